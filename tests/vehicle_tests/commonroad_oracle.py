"""The oracle of the vehicle tests: commonroad-vehicle-models' multibody model (29 states,
Pacejka 2002 tyres, published BMW 320i parameters, ``parameters_vehicle2``) behind the same
``Vehicle`` interface as our plant, and our ``VehicleParams`` made from the same parameters.

Independent of our plant: its own equations (Althoff & Wuersching, "CommonRoad: Vehicle
Models"), integrated here with scipy's LSODA over each 10 ms step with the inputs held. The
model takes a steering velocity and an acceleration: the steering follows our command through a
rate-limited lag (``STEER_TAU_S``, its own rate limit), the acceleration is (drive - brake) / m,
which the model turns into engine torque on the rear wheels or brake torque split ``T_sb``
front / rear, as our plant does with ``brake_front_share``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.integrate import solve_ivp
from vehiclemodels.init_mb import init_mb
from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
from vehiclemodels.utils.tire_model import formula_lateral, formula_longitudinal
from vehiclemodels.vehicle_dynamics_mb import vehicle_dynamics_mb

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.magic_formula import PAC2002_235_60R16
from eoam_sumo.vehicle_tests.harness import STEP_S, Controls, Sample, rolling_start

STEER_TAU_S = 0.02
"""Time constant of the steering follower of both models (our ``steer_lag_s`` the same)."""

CR_G_MPS2 = 9.81  # commonroad's gravity, the same as ours

NO_RELAXATION_M = 0.05
"""Our tyres' relaxation lengths in the comparison: their model's slips are algebraic (no
relaxation); ours carry the shortest length the plant's 1 ms midpoint rule integrates with a
margin at the tests' speeds (time constant sigma / v >= 1.8 ms up to 100 km/h; the rule is
stable down to 0.5 ms)."""


def commonroad_params():
    """commonroad's BMW 320i (``parameters_vehicle2``)."""
    return parameters_vehicle2()


def static_axle_loads_n(p) -> tuple[float, float]:
    """The axle loads of ``init_mb`` at rest: the sprung mass split by a, b plus the unsprung."""
    wheelbase = p.a + p.b
    front = p.m_s * CR_G_MPS2 * p.b / wheelbase + p.m_uf * CR_G_MPS2
    rear = p.m_s * CR_G_MPS2 * p.a / wheelbase + p.m_ur * CR_G_MPS2
    return front, rear


def peak_friction(p) -> tuple[float, float]:
    """The tyre's peak friction coefficients (longitudinal, lateral) at zero camber, at the
    static front tyre load: the largest force of a slip sweep over the load."""
    fz = static_axle_loads_n(p)[0] / 2.0
    slips = np.linspace(0.0, 1.0, 2001)
    fx = max(abs(formula_longitudinal(s, 0.0, fz, p.tire)) for s in slips)
    angles = np.linspace(0.0, 0.5, 2001)
    fy = max(abs(formula_lateral(a, 0.0, fz, p.tire)[0]) for a in angles)
    return fx / fz, fy / fz


def sliding_friction_ratio(p) -> float:
    """The locked tyre's force (slip 1) over its peak, at the static front tyre load."""
    fz = static_axle_loads_n(p)[0] / 2.0
    peak = peak_friction(p)[0] * fz
    return abs(formula_longitudinal(1.0, 0.0, fz, p.tire)) / peak


def roll_stiffness_front_share(p) -> float:
    """The front axle's share of their roll stiffness: per axle the springs ``K_s T^2 / 2``
    and the auxiliary torsion stiffness ``|K_ts|`` (negative in their sets: it adds,
    ``vehicle_dynamics_mb``'s suspension forces); their roll centres are at the ground."""
    front = p.K_sf * p.T_f**2 / 2.0 + abs(p.K_tsf)
    rear = p.K_sr * p.T_r**2 / 2.0 + abs(p.K_tsr)
    return float(front / (front + rear))


def first_lock_tyre_load_n(p, ours: VehicleParams) -> float:
    """The load on each tyre of the axle that locks first in a slow brake ramp, at its lock,
    by the closed form of a load-independent friction (theirs: ``peak_friction``):
    ``z = mu b / (phi L - mu h)`` front, ``mu a / ((1 - phi) L + mu h)`` rear."""
    mu = peak_friction(p)[0]
    a, b, h = ours.cg_to_front_m, ours.cg_to_rear_m, ours.cg_height_m
    wheelbase, phi = a + b, ours.brake_front_share
    z_front = mu * b / (phi * wheelbase - mu * h)
    z_rear = mu * a / ((1.0 - phi) * wheelbase + mu * h)
    weight_n = ours.mass_kg * CR_G_MPS2
    if z_front <= z_rear:
        return 0.5 * weight_n * (b + z_front * h) / wheelbase
    return 0.5 * weight_n * (a - z_rear * h) / wheelbase


def brake_ramp_mu(p, ours: VehicleParams) -> float:
    """Our road friction for the brake ramp: their tyre's friction (``p_dx1`` at every load:
    commonroad's ``formula_longitudinal`` has no ``PDX2``) at the load of the tyres that lock
    first (``first_lock_tyre_load_n``). Our road mu is the friction at the tyre's nominal
    load (LMUX = mu / PDX1), and it rises at lighter loads by PDX2 (docs/chassis.md)."""
    c = PAC2002_235_60R16
    dfz = (first_lock_tyre_load_n(p, ours) - c.fz0) / c.fz0
    return peak_friction(p)[0] * c.pdx1 / (c.pdx1 + c.pdx2 * dfz)


def ours_from_commonroad(p) -> VehicleParams:
    """Our ``VehicleParams`` with commonroad's BMW 320i values: the same mass, yaw inertia,
    static axle loads (so the CG distances), CG height, track and size, cornering stiffness per
    axle (``-p_ky1 Fz`` of their tyre at the static load), brake split, locked-tyre friction,
    steering rate limit and the drive limits of their acceleration constraint (force
    ``m a_max``, power ``m a_max v_switch``), wheel radius and the front share of the roll
    stiffness. Theirs has no drag, no rolling resistance and no tyre relaxation: 0 (the
    relaxation lengths ``NO_RELAXATION_M``). Their model has no steering ratio: ours (16) is
    kept, for the hand-wheel columns only."""
    front_n, rear_n = static_axle_loads_n(p)
    weight_n = p.m * CR_G_MPS2
    wheelbase = p.a + p.b
    lon = p.longitudinal
    return dataclasses.replace(
        VehicleParams(),
        name="BMW 320i (commonroad parameters_vehicle2)",
        mass_kg=float(p.m),
        yaw_inertia_kgm2=float(p.I_z),
        cg_to_front_m=wheelbase * rear_n / weight_n,
        cg_to_rear_m=wheelbase * front_n / weight_n,
        cg_height_m=float(p.h_cg),
        track_m=float(p.T_f),
        length_m=float(p.l),
        width_m=float(p.w),
        front_overhang_m=0.5 * (float(p.l) - wheelbase),
        max_steer_rad=float(p.steering.max),
        max_steer_rate_radps=float(p.steering.v_max),
        cornering_stiffness_front_npr=-float(p.tire.p_ky1) * front_n,
        cornering_stiffness_rear_npr=-float(p.tire.p_ky1) * rear_n,
        front_steer_compliance=1.0,
        roll_stiffness_front_share=roll_stiffness_front_share(p),
        wheel_radius_m=float(p.R_w),
        relaxation_length_long_m=NO_RELAXATION_M,
        relaxation_length_lat_m=NO_RELAXATION_M,
        sliding_friction_ratio=sliding_friction_ratio(p),
        max_drive_force_n=float(p.m * lon.a_max),
        max_drive_power_w=float(p.m * lon.a_max * lon.v_switch),
        max_brake_force_n=float(p.m * lon.a_max),
        brake_front_share=float(p.T_sb),
        rolling_resistance_coeff=0.0,
        drag_area_m2=0.0,
        steer_lag_s=STEER_TAU_S,
        drive_lag_s=0.01,
        brake_lag_s=0.01,
    )


class CommonRoadVehicle:
    """commonroad's multibody model as a ``Vehicle`` (the road's mu is their tyre's own)."""

    def __init__(self, p, ours: VehicleParams):
        self.params = ours
        self._p = p
        self._x = np.zeros(29)

    def start(self, speed_mps: float) -> Sample:
        self._x = np.array(init_mb([0.0, 0.0, 0.0, speed_mps, 0.0, 0.0, 0.0], self._p))
        return rolling_start(speed_mps)

    def advance(self, controls: Controls, mu: float) -> Sample:
        p = self._p
        steer_rate = (controls.steer_cmd_rad - self._x[2]) / STEER_TAU_S
        steer_rate = float(np.clip(steer_rate, -p.steering.v_max, p.steering.v_max))
        accel = (controls.drive_force_cmd_n - controls.brake_force_cmd_n) / p.m
        u = [steer_rate, accel]
        solution = solve_ivp(
            lambda _t, y: vehicle_dynamics_mb(list(y), u, p),
            (0.0, STEP_S),
            self._x,
            method="LSODA",
            rtol=1e-6,
            atol=1e-8,
        )
        self._x = solution.y[:, -1]
        return self._sample(u, controls)

    def _sample(self, u: list[float], controls: Controls) -> Sample:
        x, p = self._x, self._p
        f = vehicle_dynamics_mb(list(x), u, p)
        vx, vy, r = x[3], x[10], x[5]
        return Sample(
            vx_mps=float(vx),
            vy_mps=float(vy),
            x_m=float(x[0]),
            y_m=float(x[1]),
            yaw_rad=float(x[4]),
            yaw_rate_radps=float(r),
            steer_road_rad=float(x[2]),
            ax_mps2=float(f[3] - r * vy),
            ay_mps2=float(f[10] + r * vx),  # the sprung mass's, body frame
            wheel_speed_front_mps=float(p.R_w * 0.5 * (x[23] + x[24])),
            wheel_speed_rear_mps=float(p.R_w * 0.5 * (x[25] + x[26])),
            drive_force_n=max(controls.drive_force_cmd_n - controls.brake_force_cmd_n, 0.0),
            brake_force_n=max(controls.brake_force_cmd_n - controls.drive_force_cmd_n, 0.0),
        )
