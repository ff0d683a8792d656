"""Combined-slip Magic Formula tyre (MF 5.2 / PAC2002, Pacejka 2012 ch. 4), zero camber.

Pure slip (Pacejka 2012 sec. 4.3.2, eqs. 4.E9-4.E30) with the load sensitivity of the
normalised load increment ``dfz = (Fz - Fz0) / Fz0``, and combined slip by the weighting
functions G_x(alpha), G_y(kappa) (sec. 4.3.2, eqs. 4.E50-4.E67). The road's friction scales
the peak through LMUX, LMUY (``lmux``, ``lmuy``); the cornering stiffness through LKY (``lky``).

Sign convention (ISO, as the PAC2002 coefficients are written): ``kappa > 0`` drives, the force
``Fx`` then positive; ``alpha = atan(v_lat / |v_long|)`` of the contact patch, and with
``PKY1 < 0`` the lateral force opposes it. Every function takes an ``ops`` (``ops.py``) and
runs on floats and on CasADi alike.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from eoam_sumo.params import PLANT_TYRE_FNOMIN_N
from eoam_sumo.plant.ops import FLOAT_OPS

FZ_MIN_N = 10.0
"""Floor of the load in the formulas (a lifted wheel): keeps B = K / (C D) finite."""


@dataclass(frozen=True)
class MfCoefficients:
    """MF 5.2 coefficients used here (names as in the .tir file, lower case)."""

    fz0: float = PLANT_TYRE_FNOMIN_N
    pcx1: float = 1.6411
    pdx1: float = 1.1739
    pdx2: float = -0.16395
    pex1: float = 0.46403
    pex2: float = 0.25022
    pex3: float = 0.067842
    pex4: float = -3.7604e-5
    pkx1: float = 22.303
    pkx2: float = 0.48896
    pkx3: float = 0.21253
    phx1: float = 0.0012297
    phx2: float = 0.0004318
    pvx1: float = -8.8098e-6
    pvx2: float = 1.862e-5
    rbx1: float = 13.276
    rbx2: float = -13.778
    rcx1: float = 1.2568
    rex1: float = 0.65225
    rex2: float = -0.24948
    rhx1: float = 0.0050722
    pcy1: float = 1.3507
    pdy1: float = 1.0489
    pdy2: float = -0.18033
    pey1: float = -0.0074722
    pey2: float = -0.0063208
    pey3: float = -9.9935
    pky1: float = -21.92
    pky2: float = 2.0012
    phy1: float = 0.0026747
    phy2: float = 8.9094e-5
    pvy1: float = 0.037318
    pvy2: float = -0.010049
    rby1: float = 7.1433
    rby2: float = 9.1916
    rby3: float = -0.027856
    rcy1: float = 1.0719
    rey1: float = -0.27572
    rey2: float = 0.32802
    rhy1: float = 5.7448e-6
    rhy2: float = -3.1368e-5
    rvy1: float = -0.027825
    rvy2: float = 0.053604
    rvy4: float = 12.12
    rvy5: float = 1.9
    rvy6: float = -10.704

    def symmetric(self) -> MfCoefficients:
        """The set without its left/right asymmetries (conicity and ply-steer shifts, the
        sign-dependent curvature PEY3, the kappa-induced side force): a car's mirrored left
        and right tyres cancel them, and the single-track evaluates both with one slip."""
        zero = ("phx1", "phx2", "pvx1", "pvx2", "rhx1", "pey3", "phy1", "phy2", "pvy1", "pvy2")
        more = ("rby3", "rhy1", "rhy2", "rvy1", "rvy2")
        return dataclasses.replace(self, **dict.fromkeys((*zero, *more), 0.0))


PAC2002_235_60R16 = MfCoefficients()
"""MSC Adams PAC2002 sample tyre 235/60R16 (FNOMIN 4850 N, R0 0.344 m): the coefficients
CommonRoad's vehicle models ship (Althoff & Wuersching 2020, Tab. 7) with the load-variation
terms of the same file."""


class PureSlip(NamedTuple):
    """A pure-slip force and the quantities the combined-slip and ABS parts reuse."""

    force_n: Any
    mu: Any  # peak friction coefficient at this load and road
    stiffness_b: Any  # the formula's B


def _shape(b, c, e, x, ops):
    """``sin(C atan(B x - E (B x - atan(B x))))``, the Magic Formula's shape."""
    bx = b * x
    return ops.sin(c * ops.atan(bx - e * (bx - ops.atan(bx))))


def _weight(b, c, e, x, shift, ops):
    """Combined-slip weighting ``cos(C atan(B x - E(...))) / cos(C atan(B s - E(...)))``."""
    bx, bs = b * x, b * shift
    num = ops.cos(c * ops.atan(bx - e * (bx - ops.atan(bx))))
    den = ops.cos(c * ops.atan(bs - e * (bs - ops.atan(bs))))
    return num / den


def pure_fx(kappa, fz_n, lmux, c: MfCoefficients, ops) -> PureSlip:
    """Pure longitudinal force Fx0 [N] (Pacejka 2012 eqs. 4.E9-4.E18, zero camber)."""
    fz = ops.fmax(fz_n, FZ_MIN_N)
    dfz = (fz - c.fz0) / c.fz0
    kx = kappa + c.phx1 + c.phx2 * dfz
    mux = (c.pdx1 + c.pdx2 * dfz) * lmux
    dx = mux * fz
    ex = ops.fmin((c.pex1 + c.pex2 * dfz + c.pex3 * dfz * dfz) * (1.0 - c.pex4 * ops.sign(kx)), 1.0)
    kxk = fz * (c.pkx1 + c.pkx2 * dfz) * ops.exp(c.pkx3 * dfz)
    bx = kxk / (c.pcx1 * dx)
    svx = fz * (c.pvx1 + c.pvx2 * dfz) * lmux
    return PureSlip(dx * _shape(bx, c.pcx1, ex, kx, ops) + svx, mux, bx)


def cornering_stiffness_npr(fz_n, c: MfCoefficients, ops):
    """|K_y alpha| = |PKY1| Fz0 sin(2 atan(Fz / (PKY2 Fz0))) [N/rad] (eq. 4.E25), with
    sin(2 atan x) written as 2 x / (1 + x^2)."""
    x = ops.fmax(fz_n, FZ_MIN_N) / (c.pky2 * c.fz0)
    return math.fabs(c.pky1) * c.fz0 * 2.0 * x / (1.0 + x * x)


def pure_fy(alpha, fz_n, lmuy, lky, c: MfCoefficients, ops, kya=None) -> PureSlip:
    """Pure lateral force Fy0 [N] (Pacejka 2012 eqs. 4.E19-4.E30, zero camber); ``kya`` the
    cornering stiffness when given (signed as PKY1), else eq. 4.E25 times ``lky``."""
    fz = ops.fmax(fz_n, FZ_MIN_N)
    dfz = (fz - c.fz0) / c.fz0
    ay = alpha + c.phy1 + c.phy2 * dfz
    muy = (c.pdy1 + c.pdy2 * dfz) * lmuy
    dy = muy * fz
    ey = ops.fmin((c.pey1 + c.pey2 * dfz) * (1.0 - c.pey3 * ops.sign(ay)), 1.0)
    if kya is None:
        kya = math.copysign(1.0, c.pky1) * cornering_stiffness_npr(fz, c, ops) * lky
    by = kya / (c.pcy1 * dy)
    svy = fz * (c.pvy1 + c.pvy2 * dfz) * lmuy
    return PureSlip(dy * _shape(by, c.pcy1, ey, ay, ops) + svy, muy, by)


def weight_x(kappa, alpha, fz_n, c: MfCoefficients, ops):
    """G_x(alpha), the combined-slip weight of Fx (Pacejka 2012 eqs. 4.E50-4.E57)."""
    dfz = (ops.fmax(fz_n, FZ_MIN_N) - c.fz0) / c.fz0
    bxa = c.rbx1 / ops.sqrt(1.0 + (c.rbx2 * kappa) * (c.rbx2 * kappa))  # cos(atan(.))
    exa = ops.fmin(c.rex1 + c.rex2 * dfz, 1.0)
    return _weight(bxa, c.rcx1, exa, alpha + c.rhx1, c.rhx1, ops)


def weight_y(kappa, alpha, fz_n, c: MfCoefficients, ops):
    """G_y(kappa), the combined-slip weight of Fy (Pacejka 2012 eqs. 4.E58-4.E64)."""
    dfz = (ops.fmax(fz_n, FZ_MIN_N) - c.fz0) / c.fz0
    u = c.rby2 * (alpha - c.rby3)
    byk = c.rby1 / ops.sqrt(1.0 + u * u)
    eyk = ops.fmin(c.rey1 + c.rey2 * dfz, 1.0)
    shyk = c.rhy1 + c.rhy2 * dfz
    return _weight(byk, c.rcy1, eyk, kappa + shyk, shyk, ops)


def combined_fx(kappa, alpha, fz_n, fx0, c: MfCoefficients, ops):
    """Fx = G_x(alpha) Fx0 (Pacejka 2012 eq. 4.E50)."""
    return weight_x(kappa, alpha, fz_n, c, ops) * fx0


def combined_fy(kappa, alpha, fz_n, fy0: PureSlip, c: MfCoefficients, ops):
    """Fy = G_y(kappa) Fy0 + S_Vy(kappa) (Pacejka 2012 eqs. 4.E58-4.E67)."""
    fz = ops.fmax(fz_n, FZ_MIN_N)
    dfz = (fz - c.fz0) / c.fz0
    g = weight_y(kappa, alpha, fz, c, ops)
    if c.rvy1 == 0.0 and c.rvy2 == 0.0:
        return g * fy0.force_n
    w = c.rvy4 * alpha
    dvyk = fy0.mu * fz * (c.rvy1 + c.rvy2 * dfz) / ops.sqrt(1.0 + w * w)
    return g * fy0.force_n + dvyk * ops.sin(c.rvy5 * ops.atan(c.rvy6 * kappa))


def tyre_forces(kappa, alpha, fz_n, lmux, lmuy, lky, c: MfCoefficients, ops):
    """Combined-slip ``(Fx, Fy, Fx0)`` of one tyre [N] at slip ``kappa``, slip angle ``alpha``
    [rad] and load ``fz_n``; ``Fx0`` (the pure-slip part) carries ``mu`` and ``B`` for ABS."""
    fx0 = pure_fx(kappa, fz_n, lmux, c, ops)
    fy0 = pure_fy(alpha, fz_n, lmuy, lky, c, ops)
    fx = combined_fx(kappa, alpha, fz_n, fx0.force_n, c, ops)
    fy = combined_fy(kappa, alpha, fz_n, fy0, c, ops)
    return fx, fy, fx0


class TyreForce(NamedTuple):
    """One tyre's wheel-frame forces [N] and its pure-slip peaks ``Dx``, ``Dy`` [N] (the axes
    of its friction ellipse at this load and road)."""

    fx_n: Any
    fy_n: Any
    dx_n: Any
    dy_n: Any


def axle_forces(kappas, alpha, loads, mu, lky, c: MfCoefficients, ops):
    """``(left, right)`` ``TyreForce`` of an axle's two tyres, each at its own longitudinal
    slip ``kappas[i]`` and load ``loads[i]``, sharing the slip angle (``alpha`` is its
    tangent), on a road of friction ``mu`` (LMUX = mu / PDX1, LMUY = mu / PDY1); ``c``
    symmetric. Two adaptations for the plant (docs/chassis.md): the combined-slip weights
    take the slips over ``mu`` (the peak slips scale with the friction, B = K / (C D)) at the
    axle's mean load (they depend on it only through REX2, REY2); each tyre's force is kept
    inside the ellipse of its pure-slip peaks, ``(Fx / Dx)^2 + (Fy / Dy)^2 <= 1``."""
    mean = 0.5 * (loads[0] + loads[1])
    out = []
    for kappa, fz in zip(kappas, loads):
        gx = weight_x(kappa / mu, alpha / mu, mean, c, ops)
        gy = weight_y(kappa / mu, alpha / mu, mean, c, ops)
        fx0 = pure_fx(kappa, fz, mu / c.pdx1, c, ops)
        fy0 = pure_fy(alpha, fz, mu / c.pdy1, lky, c, ops)
        fx, fy = gx * fx0.force_n, gy * fy0.force_n
        load = ops.fmax(fz, FZ_MIN_N)
        dx, dy = fx0.mu * load, fy0.mu * load
        ex, ey = fx / dx, fy / dy
        scale = 1.0 / ops.fmax(ops.sqrt(ex * ex + ey * ey), 1.0)
        out.append(TyreForce(fx * scale, fy * scale, dx, dy))
    return out[0], out[1]


def peak_slip(c: MfCoefficients) -> float:
    """Braking slip |kappa| of the pure longitudinal peak at nominal load and LMUX = 1, by a
    scan in steps of 0.001 (it scales with 1 / LMUX, since B = K / (C D))."""
    sym = c.symmetric()
    forces = [-pure_fx(-i * 1e-3, sym.fz0, 1.0, sym, FLOAT_OPS).force_n for i in range(1, 1000)]
    return (forces.index(max(forces)) + 1) * 1e-3
