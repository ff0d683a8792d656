"""The brake force that locks no wheel, from the vehicle's fixed brake split (eq. 33 on the
chassis the plant has).

Eq. 33's no-lock deceleration (``offline.boundaries.max_decel_no_lock_mps2``) is a straight
road's axle balance on a constant-friction tyre. On the plant a braked wheel also carries its
rolling resistance (a Coulomb torque at the wheel, ``plant.integrator.resist``), its tyre's
peak friction falls with load (PDX2, Pacejka 2012 eq. 4.E13), both wheels of an axle get the
same line pressure while the lateral load transfer unloads the inner one, and cornering takes
its share of the friction ellipse. Without ABS the EOAM's brake command must lock neither
axle's inner wheel, or the front wheels it steers with slide straight on. For a
wheel of axle share ``phi`` (front ``brake_front_share``, rear ``1 - phi``) and load

    Fz = m (g l_o +/- h a) / (2 L) - dFz_lat,   a = (F + R) / m_eq,

its brake force ``phi F / 2`` plus its rolling resistance ``c_rr Fz`` stays within its peak
``mu_x(Fz) Fz sqrt(1 - q^2)``, ``q`` the share of the friction cornering takes; linear in the
command ``F`` once ``mu_x`` is taken at the load (two fixed-point passes).
"""

from __future__ import annotations

import math

from eoam_sumo.params import G_MPS2, PLANT_TYRE_PEAK_LOAD_SENSITIVITY, VehicleParams

_PASSES = 2  # fixed-point passes for the load-sensitive peak (converged to < 0.1 %)


def peak_friction(mu: float, load_n: float, nominal_load_n: float) -> float:
    """The plant tyre's longitudinal peak friction at this load (Pacejka 2012 eq. 4.E13), its
    curves scaled to the vehicle's own tyre's nominal load (LFZO, as the plant's)."""
    dfz = (load_n - nominal_load_n) / nominal_load_n
    return mu * (1.0 + PLANT_TYRE_PEAK_LOAD_SENSITIVITY * dfz)


class BrakeSplit:
    """A vehicle's fixed brake split and what loads its inner wheels: the parameters
    ``limit_n`` reads at every control step, kept as plain floats."""

    def __init__(self, params: VehicleParams) -> None:
        p = params
        self.front_share = p.brake_front_share
        self.mass_kg, self.cg_height_m, self.track_m = p.mass_kg, p.cg_height_m, p.track_m
        self.roll_front_share = p.roll_stiffness_front_share
        self.cg_to_front_m, self.cg_to_rear_m = p.cg_to_front_m, p.cg_to_rear_m
        self.wheelbase_m = p.wheelbase_m
        self.nominal_load_n = p.tyre_nominal_load_n
        self.rolling_resistance_coeff = p.rolling_resistance_coeff

    def limit_n(
        self,
        mu: float,
        lateral_accel_mps2: float,
        resistance_n: float,
        lateral_share: float,
        equivalent_mass_kg: float,
    ) -> float:
        """The largest brake command [N] (the split's total at the road) that locks neither
        axle's inner wheel while the car takes ``lateral_accel_mps2`` and its resistances
        (drag, rolling) ``resistance_n``; ``lateral_share`` is q, the share of each tyre's
        friction ellipse cornering takes (clipped to [0, 1]). ``math.inf`` when no wheel can
        lock."""
        phi = self.front_share
        q = min(max(lateral_share, 0.0), 1.0)
        ellipse = math.sqrt(1.0 - q * q)
        lateral_n = self.mass_kg * abs(lateral_accel_mps2) * self.cg_height_m / self.track_m
        d_front = lateral_n * self.roll_front_share
        m_eq = equivalent_mass_kg
        front = self._inner_wheel_limit_n(
            mu, ellipse, 0.5 * phi, self.cg_to_rear_m, 1.0, d_front, resistance_n, m_eq
        )
        rear = self._inner_wheel_limit_n(
            mu,
            ellipse,
            0.5 * (1.0 - phi),
            self.cg_to_front_m,
            -1.0,
            lateral_n - d_front,
            resistance_n,
            m_eq,
        )
        return min(front, rear)

    def _inner_wheel_limit_n(
        self,
        mu: float,
        ellipse: float,
        share: float,
        lever_m: float,
        sign: float,
        d_lat_n: float,
        resistance_n: float,
        m_eq: float,
    ) -> float:
        """One axle's limit: ``share F <= k Fz(F)``, k = mu_x(Fz) sqrt(1 - q^2) - c_rr, Fz(F) =
        m (g lever + sign h (F + R) / m_eq) / (2 L) - dFz_lat (sign +1 front, -1 rear)."""
        m, h, wb = self.mass_kg, self.cg_height_m, self.wheelbase_m
        nominal_load_n, c_rr = self.nominal_load_n, self.rolling_resistance_coeff
        static = m * G_MPS2 * lever_m / (2.0 * wb) - d_lat_n
        per_force = sign * m * h / (2.0 * wb * m_eq)  # load per N of deceleration force
        load = static + per_force * resistance_n
        limit = math.inf
        for _ in range(_PASSES):
            k = peak_friction(mu, max(load, 0.0), nominal_load_n) * ellipse - c_rr
            if k <= 0.0:
                return 0.0
            slope = share - k * per_force
            if slope <= 0.0:
                return math.inf  # the load grows faster with braking than the brake force
            limit = max(k * (static + per_force * resistance_n) / slope, 0.0)
            load = static + per_force * (limit + resistance_n)
        return limit
