"""The braking tests: a straight-line stop (``brake``, UN R13-H Annex 3 / FMVSS 135) and the
lock order in a linearly increasing brake (``brake-ramp``, UN R13-H Annex 5 Appendix 1). Clauses:
``clauses.py``."""

from __future__ import annotations

import numpy as np

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2, VehicleParams
from eoam_sumo.plant.chassis import ABS_MIN_SPEED_MPS
from eoam_sumo.vehicle_tests import clauses as c
from eoam_sumo.vehicle_tests.common import (
    VehicleTestOptions,
    VehicleTestResult,
    criterion,
    header,
    overall,
    rounded,
    vehicle_for,
)
from eoam_sumo.vehicle_tests.figures import (
    LOCK_MIN_SPEED_MPS,
    LOCK_SLIP,
    STOP_SPEED_MPS,
    distance_between_m,
    first_time_s,
    lock_order,
    locked,
    mfdd_mps2,
    path_length_m,
    stop_time_s,
    stopping_distance_limit_m,
)
from eoam_sumo.vehicle_tests.harness import Controls, Run, Sample, Vehicle, simulate

REST_S = 1.0
"""Time recorded after the stop, to see the vehicle stay at rest [s]."""

RAMP_LOCK_TARGET_S = 0.75
"""The first lock aimed at, after braking begins [s] (the middle of R13-H's 0.5-1 s)."""
RAMP_TRIES = 5
"""Brake-ramp runs at most, to bring the first lock into 0.5-1 s (ours)."""


def brake(params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None):
    """Full brake application from the test speed to a stop, engine disconnected (R13-H Type-0):
    stopping distance against ``0.1 v + 0.0060 v^2``, the mean fully developed deceleration,
    the friction utilisation (MFDD over ``mu g``; at least 0.75 with ABS, R13-H Annex 6),
    which axles locked, the lowest wheel speed and the largest speed once at rest."""
    v0_mps = options.speed_mps(c.BRAKE_SPEED_KMH)
    full_n = params.max_brake_force_n
    stopped_at: list[float] = []

    def stop(t_s: float, s: Sample) -> bool:
        if not stopped_at and s.vx_mps <= STOP_SPEED_MPS:
            stopped_at.append(t_s)
        return bool(stopped_at) and t_s >= stopped_at[0] + REST_S

    duration_s = 4.0 * v0_mps / (options.mu * G_MPS2) + 10.0
    run = simulate(
        vehicle_for(params, vehicle),
        v0_mps,
        lambda t, s: Controls(0.0, 0.0, full_n),
        duration_s,
        options.mu,
        stop=stop,
    )
    summary = header("brake", params, options, v0_mps)
    summary.update(_brake_figures(run, v0_mps, options.mu, params))
    return VehicleTestResult("brake", (run,), summary)


def resistance_mps2(params: VehicleParams, v0_mps: float) -> float:
    """The deceleration rolling resistance and drag give over the MFDD's window (``0.8 v0``
    to ``0.1 v0``): ``Crr g`` and ``rho CdA v^2 / (2 m)`` at the window's mean ``v^2`` over
    its distance, ``(vb^2 + ve^2) / 2`` under a steady deceleration."""
    vb, ve = 0.8 * v0_mps, 0.1 * v0_mps
    drag = AIR_DENSITY_KGPM3 * params.drag_area_m2 * (vb * vb + ve * ve) / (4.0 * params.mass_kg)
    return params.rolling_resistance_coeff * G_MPS2 + drag


def _brake_figures(run: Run, v0_mps: float, mu: float, params: VehicleParams) -> dict:
    time_s, vx = run["time_s"], run["vx_mps"]
    distance = path_length_m(run["x_m"], run["y_m"])
    t_stop = stop_time_s(time_s, vx, 0.0)
    stopping_m = None if t_stop is None else distance_between_m(time_s, distance, 0.0, t_stop)
    mfdd = mfdd_mps2(vx, distance, v0_mps)
    # the tyres' part of the MFDD over the road's friction: R13-H's k is measured on the car,
    # with its own drag and rolling resistance; here k is the road's mu, so they are taken out
    utilisation = None if mfdd is None else (mfdd - resistance_mps2(params, v0_mps)) / (mu * G_MPS2)
    with_abs = params.abs_fitted
    front = locked(run["wheel_speed_front_mps"], vx)
    rear = locked(run["wheel_speed_rear_mps"], vx)
    stopped = t_stop is not None
    rest = time_s >= (t_stop if stopped else np.inf)
    limit_m = stopping_distance_limit_m(v0_mps * 3.6)
    criteria = [_stopping_criterion(run, float(distance[-1]), stopping_m, limit_m)]
    if with_abs:
        criteria.append(_utilisation_criterion(utilisation, v0_mps))
    wheel_min = min(run["wheel_speed_front_mps"].min(), run["wheel_speed_rear_mps"].min())
    figures = {
        "stopped": stopped,
        "stopping_distance_m": rounded(stopping_m, 3),
        "stopping_distance_at_least_m": None if stopped else round(float(distance[-1]), 3),
        "stopping_distance_limit_m": round(limit_m, 3),
        "stop_time_s": rounded(t_stop, 3),
        "mfdd_mps2": rounded(mfdd),
        "mfdd_clause": c.CITE["mfdd"],
        "friction_utilisation": rounded(utilisation),
        "front_locked": bool(front.any()),
        "rear_locked": bool(rear.any()),
        "front_lock_time_s": rounded(first_time_s(time_s, front), 3),
        "rear_lock_time_s": rounded(first_time_s(time_s, rear), 3),
        "min_wheel_speed_mps": round(float(wheel_min), 6),
        "max_speed_at_rest_mps": round(float(np.abs(vx[rest]).max()), 6) if rest.any() else None,
    }
    return {"figures": figures, "criteria": criteria, "passed": overall(criteria)}


def _stopping_criterion(
    run: Run, travelled_m: float, stopping_m: float | None, limit_m: float
) -> dict:
    """The stopping distance against its limit. A car still moving when the run ends fails:
    its stopping distance is more than the ``travelled_m`` so far (the value given, a lower
    bound), and it did not stop in four times the friction's shortest stopping time."""
    if stopping_m is not None:
        return criterion("stopping_distance_m", stopping_m, limit_m, True, c.CITE["stop"])
    judged = criterion("stopping_distance_m", round(travelled_m, 3), limit_m, True, c.CITE["stop"])
    beyond = "beyond" if travelled_m > limit_m else "within"
    judged["value_is_lower_bound"] = True
    judged["passed"] = False
    judged["reason"] = (
        f"not stopped when the run ended {run['time_s'][-1]:.1f} s after the brake was applied, "
        f"still at {run['vx_mps'][-1]:.2f} m/s: the stopping distance is more than the "
        f"{travelled_m:.1f} m travelled ({beyond} the {limit_m:.1f} m limit)"
    )
    return judged


def brake_ramp(params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None):
    """UN R13-H Annex 5 Appendix 1, the wheel-lock sequence: engine disconnected, the brake
    force raised linearly so that the first axle locks 0.5-1 s after braking begins, from
    100 km/h (65 km/h on roads of mu 0.5 or less); the ramp rate found by up to
    ``RAMP_TRIES`` runs, each scaled by the last lock time over ``RAMP_LOCK_TARGET_S``. Which
    axle locks first and at which braking rate; passes when the front locks first (or
    together) for braking rates between 0.15 and 0.8."""
    standard_kmh = c.BRAKE_SPEED_KMH if options.mu > c.LOCK_SEQUENCE_LOW_MU else 65.0
    v0_mps = options.speed_mps(standard_kmh)
    rate_n_per_s = options.mu * params.mass_kg * G_MPS2 / RAMP_LOCK_TARGET_S
    tries = 0
    while True:
        tries += 1
        run, t_lock = _ramp_run(params, v0_mps, rate_n_per_s, options.mu, vehicle)
        early, late = c.LOCK_SEQUENCE_FIRST_LOCK_S
        if tries == RAMP_TRIES or (t_lock is not None and early <= t_lock <= late):
            break
        scale = 2.0 if t_lock is None else t_lock / RAMP_LOCK_TARGET_S
        rate_n_per_s *= min(max(scale, 0.5), 2.0)
    return _ramp_result(params, options, v0_mps, run, t_lock, rate_n_per_s, tries)


def _utilisation_criterion(utilisation: float | None, v0_mps: float) -> dict:
    """R13-H Annex 6's utilisation of adhesion, judged only where the ABS works over the
    whole MFDD window (its end, ``0.1 v0``, at or above ``ABS_MIN_SPEED_MPS``; ours)."""
    judged = criterion(
        "friction_utilisation", utilisation, c.ADHESION_UTILISATION_MIN, False, c.CITE["adhesion"]
    )
    if 0.1 * v0_mps < ABS_MIN_SPEED_MPS:
        judged["passed"] = None
        judged["reason"] = (
            f"not judged: the MFDD window ends at {0.1 * v0_mps:.2f} m/s, below the "
            f"{ABS_MIN_SPEED_MPS:g} m/s under which the ABS hands the wheels back"
        )
    return judged


def brake_ramp_at_rate(
    params: VehicleParams,
    options: VehicleTestOptions,
    rate_g_per_s: float,
    vehicle: Vehicle | None = None,
) -> VehicleTestResult:
    """The lock sequence on one ramp of ``rate_g_per_s`` (weight per second) from 100 km/h:
    a slow ramp passes each braking rate quasi-statically (the oracle comparison's)."""
    v0_mps = options.speed_mps(c.BRAKE_SPEED_KMH)
    rate_n_per_s = rate_g_per_s * params.mass_kg * G_MPS2
    run, t_lock = _ramp_run(params, v0_mps, rate_n_per_s, options.mu, vehicle)
    return _ramp_result(params, options, v0_mps, run, t_lock, rate_n_per_s, 1)


def _ramp_result(
    params: VehicleParams,
    options: VehicleTestOptions,
    v0_mps: float,
    run: Run,
    t_lock: float | None,
    rate_n_per_s: float,
    tries: int,
) -> VehicleTestResult:
    """The lock order of a brake-ramp run and its verdict (R13-H Annex 5)."""
    vx = run["vx_mps"]
    order = lock_order(
        run["time_s"],
        run["ax_mps2"],
        locked(run["wheel_speed_front_mps"], vx),
        locked(run["wheel_speed_rear_mps"], vx),
    )
    passed = order.passes(c.LOCK_ORDER_RATE_MIN, c.LOCK_ORDER_RATE_MAX)
    summary = header("brake-ramp", params, options, v0_mps)
    summary["figures"] = {
        "first_locked_axle": order.first,
        "front_lock_braking_rate": rounded(order.rate_front),
        "rear_lock_braking_rate": rounded(order.rate_rear),
        "first_lock_time_s": rounded(t_lock, 3),
        "brake_ramp_g_per_s": round(rate_n_per_s / (params.mass_kg * G_MPS2), 4),
        "ramp_runs": tries,
        "lock_sequence_clause": c.CITE["lock_sequence"],
    }
    if order.first == "none":
        summary["criteria"], summary["passed"] = [], None
        summary["figures"]["not_measured"] = summary["not_measured"] = _no_lock_reason(
            params, run, rate_n_per_s
        )
        return VehicleTestResult("brake-ramp", (run,), summary)
    summary["criteria"] = [
        {
            "name": "front_locks_first_between_braking_rates",
            "value": order.first,
            "limit": [c.LOCK_ORDER_RATE_MIN, c.LOCK_ORDER_RATE_MAX],
            "comparison": "front first or together",
            "clause": c.CITE["lock_order"],
            "passed": passed,
        }
    ]
    summary["passed"] = passed
    return VehicleTestResult("brake-ramp", (run,), summary)


def _no_lock_reason(params: VehicleParams, run: Run, rate_n_per_s: float) -> str:
    """Why a ramp without a locked axle measured no lock sequence (R13-H Annex 5 judges the
    order in which the axles lock: none locked, nothing to judge)."""
    why = (
        "the ABS kept every wheel from locking"
        if params.abs_fitted
        else "the brakes could not lock a wheel on this road"
    )
    return (
        f"no axle locked on the ramps ({why}; last ramp "
        f"{rate_n_per_s / (params.mass_kg * G_MPS2):.2f} g/s up to "
        f"{params.max_brake_force_n:.0f} N, peak braking rate "
        f"{float(np.max(-run['ax_mps2'])) / G_MPS2:.2f} g): no lock sequence to judge"
    )


def _ramp_run(
    params: VehicleParams, v0_mps: float, rate_n_per_s: float, mu: float, vehicle: Vehicle | None
) -> tuple[Run, float | None]:
    """One linear brake ramp from ``v0_mps`` until both axles lock (0.3 s more recorded) or
    the speed falls below ``LOCK_MIN_SPEED_MPS``; the run and its first lock time."""
    both_at: list[float] = []

    def stop(t_s: float, s: Sample) -> bool:
        low = (1.0 - LOCK_SLIP) * s.vx_mps
        if not both_at and s.wheel_speed_front_mps < low and s.wheel_speed_rear_mps < low:
            both_at.append(t_s)
        return s.vx_mps < LOCK_MIN_SPEED_MPS or (bool(both_at) and t_s >= both_at[0] + 0.3)

    full_n = params.max_brake_force_n
    run = simulate(
        vehicle_for(params, vehicle),
        v0_mps,
        lambda t, s: Controls(0.0, 0.0, min(rate_n_per_s * t, full_n)),
        full_n / rate_n_per_s + 2.0,
        mu,
        stop=stop,
    )
    vx = run["vx_mps"]
    either = locked(run["wheel_speed_front_mps"], vx) | locked(run["wheel_speed_rear_mps"], vx)
    return run, first_time_s(run["time_s"], either)
