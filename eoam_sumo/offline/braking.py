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
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import replace

from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.params import VehicleParams
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
    tyres_only = replace(params, drag_area_m2=0.0, rolling_resistance_coeff=0.0)
    plant = Plant(tyres_only, dt_s=_STEP_S / _SUBSTEPS, substeps=_SUBSTEPS)
    v0 = ABS_TEST_SPEED_MPS
    state = [float(v) for v in initial_state(0.0, 0.0, 0.0, v0, params=params)]
    controls = [0.0, 0.0, params.max_brake_force_n]
    samples = [(state[_VX], state[_X])]
    limit_steps = int(20.0 * v0 / (mu * 9.81 * _STEP_S)) + 1000
    for _ in range(limit_steps):
        state, _outputs = plant.advance(state, controls, mu)
        samples.append((state[_VX], state[_X]))
        if state[_VX] <= MFDD_TO * v0:
            break
    else:
        raise ValueError(f"the plant did not brake to {MFDD_TO * v0:.2f} m/s at mu={mu:g}")
    s_b = _distance_at(samples, MFDD_FROM * v0)
    s_e = _distance_at(samples, MFDD_TO * v0)
    v_b, v_e = MFDD_FROM * v0, MFDD_TO * v0
    return (v_b * v_b - v_e * v_e) / (2.0 * (s_e - s_b))


def _distance_at(samples: list[tuple[float, float]], speed_mps: float) -> float:
    """Distance at which the (falling) speed first reaches ``speed_mps``, interpolated."""
    for (v_a, s_a), (v_b, s_b) in itertools.pairwise(samples):
        if v_b <= speed_mps <= v_a and v_b < v_a:
            return s_a + (v_a - speed_mps) / (v_a - v_b) * (s_b - s_a)
    raise ValueError(f"the speed never fell to {speed_mps:.2f} m/s")
