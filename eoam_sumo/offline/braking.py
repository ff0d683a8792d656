"""The braking deceleration of eq. 33 for a given vehicle: the no-lock limit, or what its ABS
achieves.

Without ABS the ego must not lock an axle, and eq. 33's deceleration is the closed-form
no-lock limit of the fixed brake split (``boundaries.max_decel_no_lock_mps2``). With ABS
(``VehicleParams.abs_fitted``) every axle is held near its peak slip, and the limit is what the
plant's ABS achieves: the mean fully developed deceleration of a full brake application on a
straight road (UN R13-H Annex 3, Type-0 test at 100 km/h, the deceleration between 0.8 v0 and
0.1 v0), simulated once per vehicle and friction without aerodynamic drag and rolling
resistance (as eq. 33, the tyres' deceleration alone; cached, and written by the build into
metadata.json for the run).

With ABS the stopping distance B0 is, per speed and friction, what the plant needs to stop
under the EOAM's limit braking command (``limit_braking_stop_m``): ABS cycling depends on
the speed (the onset's first dump weighs more in a short stop), which one 100 km/h figure
misses.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import replace

from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2, stop_distance_m
from eoam_sumo.params import VehicleParams, equivalent_mass_kg
from eoam_sumo.plant import STATE_NAMES, Plant, initial_state

ABS_TEST_SPEED_MPS = 100.0 / 3.6  # UN R13-H Annex 3, Type-0 test speed
MFDD_FROM, MFDD_TO = 0.8, 0.1  # UN R13-H Annex 3: the fully developed part, share of v0
_STEP_S = 0.01
_SUBSTEPS = 10
_X, _VX = STATE_NAMES.index("x_m"), STATE_NAMES.index("vx_mps")


def braking_decel_mps2(params: VehicleParams, mu: float) -> float:
    """Eq. 33's straight-line braking deceleration: ABS's (``abs_decel_mps2``) if the vehicle
    has ABS, else the no-lock limit."""
    if params.abs_fitted:
        return abs_decel_mps2(params, mu)
    return max_decel_no_lock_mps2(params, mu)


def braking_stop_m(params: VehicleParams, mu: float, speed_mps: float, share: float) -> float:
    """B0 (eq. 33) at limit braking, ``share`` of ``braking_decel_mps2``: the closed form
    v^2 / (2 a) without ABS, ``limit_braking_stop_m`` with it."""
    if params.abs_fitted:
        return limit_braking_stop_m(params, mu, speed_mps, share)
    return stop_distance_m(speed_mps, share * braking_decel_mps2(params, mu))


def braking_model(params: VehicleParams) -> str:
    """How ``braking_decel_mps2`` obtains the deceleration (for metadata.json)."""
    if params.abs_fitted:
        return "abs: mean fully developed deceleration of the plant's full brake application"
    return "no-lock: largest deceleration of the fixed brake split without locking an axle"


@functools.lru_cache(maxsize=64)
def abs_decel_mps2(params: VehicleParams, mu: float) -> float:
    """Mean fully developed deceleration (v_b^2 - v_e^2) / (2 (s_e - s_b)) of the plant braking
    with its full brake force from ``ABS_TEST_SPEED_MPS``, v_b = 0.8 v0, v_e = 0.1 v0, with
    neither drag nor rolling resistance."""
    if not mu > 0.0:
        raise ValueError(f"mu={mu!r} must be > 0")
    v0 = ABS_TEST_SPEED_MPS
    samples = _brake_run(params, mu, v0, params.max_brake_force_n, MFDD_TO * v0)
    s_b = _distance_at(samples, MFDD_FROM * v0)
    s_e = _distance_at(samples, MFDD_TO * v0)
    v_b, v_e = MFDD_FROM * v0, MFDD_TO * v0
    return (v_b * v_b - v_e * v_e) / (2.0 * (s_e - s_b))


#: Where a stop counts as ended [m/s] (creeping at the end adds nothing measurable).
_STOPPED_MPS = 0.05


@functools.lru_cache(maxsize=2048)
def limit_braking_stop_m(params: VehicleParams, mu: float, speed_mps: float, share: float) -> float:
    """B0 with ABS (eq. 33's stopping distance, per speed and friction): the distance the plant
    (tyres only, as ``abs_decel_mps2``) needs from ``speed_mps`` to a standstill under the
    EOAM's limit braking command, ``m_eq`` times ``share`` of ``abs_decel_mps2``, less the
    brake's build-up ``brake_lag_s`` v (the braking buffer's t_b carries it); never below
    the closed form v^2 / (2 share a)."""
    closed = stop_distance_m(speed_mps, share * abs_decel_mps2(params, mu))
    if speed_mps <= 1.0:
        return closed
    force = equivalent_mass_kg(params) * share * abs_decel_mps2(params, mu)
    samples = _brake_run(params, mu, speed_mps, force, _STOPPED_MPS)
    return max(samples[-1][1] - samples[0][1] - params.brake_lag_s * speed_mps, closed)


def _brake_run(
    params: VehicleParams, mu: float, v0: float, force_n: float, until_mps: float
) -> list[tuple[float, float]]:
    """(speed, distance) samples of the plant braking straight with a constant brake command
    from ``v0`` until its speed falls to ``until_mps``, without drag or rolling resistance."""
    tyres_only = replace(params, drag_area_m2=0.0, rolling_resistance_coeff=0.0)
    plant = Plant(tyres_only, dt_s=_STEP_S / _SUBSTEPS, substeps=_SUBSTEPS)
    state = [float(v) for v in initial_state(0.0, 0.0, 0.0, v0, params=params)]
    controls = [0.0, 0.0, force_n]
    samples = [(state[_VX], state[_X])]
    limit_steps = int(20.0 * v0 / (mu * 9.81 * _STEP_S)) + 1000
    for _ in range(limit_steps):
        state, _outputs = plant.advance(state, controls, mu)
        samples.append((state[_VX], state[_X]))
        if state[_VX] <= until_mps:
            return samples
    raise ValueError(f"the plant did not brake to {until_mps:.2f} m/s at mu={mu:g}")


def _distance_at(samples: list[tuple[float, float]], speed_mps: float) -> float:
    """Distance at which the (falling) speed first reaches ``speed_mps``, interpolated."""
    for (v_a, s_a), (v_b, s_b) in itertools.pairwise(samples):
        if v_b <= speed_mps <= v_a and v_b < v_a:
            return s_a + (v_a - speed_mps) / (v_a - v_b) * (s_b - s_a)
    raise ValueError(f"the speed never fell to {speed_mps:.2f} m/s")
