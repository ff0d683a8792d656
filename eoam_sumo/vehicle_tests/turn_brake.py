"""Braking in a turn (``brake-in-turn``, ISO 7975:2019, open-loop): steady circular driving on
the initial radius at the initial lateral acceleration, then, the steering wheel held where
it was, the throttle released and the brake applied as a step to a set deceleration; a series
of decelerations in steps. Figures per run 1 s after the brake's onset: how the turn changed
(yaw-rate and lateral-acceleration ratios, the yaw rate against the one that keeps the radius,
the sideslip change, the path's deviation from the initial circle). ISO 7975 sets no pass
mark. Clauses: ``clauses.py``.
"""

from __future__ import annotations

import math

import numpy as np

from eoam_sumo.params import G_MPS2, VehicleParams
from eoam_sumo.vehicle_tests import clauses as c
from eoam_sumo.vehicle_tests.common import (
    VehicleTestOptions,
    VehicleTestResult,
    header,
    rounded,
    speed_keeper,
    vehicle_for,
)
from eoam_sumo.vehicle_tests.figures import locked
from eoam_sumo.vehicle_tests.harness import STEP_S, Controls, Run, Sample, Vehicle, simulate

CIRCLE_S = 5.0
"""Steady circular driving before the brake's onset [s] (ours: the yaw rate settles)."""
AFTER_S = 2.0
"""Recorded after the onset [s] (ours: the figures are at 1 s, ``c.TURN_BRAKE_MEASURE_S``)."""
HOLD_S = 1.0
"""The last second of the circle: the steering found is held (open loop) from its start."""
CIRCLE_GAIN_S = 0.5
"""Integral gain of the steering that finds the circle: road-wheel rad per rad of yaw-rate
error [s] (ours)."""
SPIN_SIDESLIP_DEG = 45.0
"""A run counts as a spin once the sideslip passes this (ours)."""
CIRCLE_TOLERANCE = 0.05
"""At the brake's onset the yaw rate must be within this share of the circle's ``v / R``
(ours): otherwise the car is not on the initial circle (the turn asks more than the road
gives) and the series is not measured."""


def decelerations_mps2(mu: float) -> list[float]:
    """The series: from ``TURN_BRAKE_DECEL_STEP_MPS2`` in its steps up to ``mu g``."""
    step = c.TURN_BRAKE_DECEL_STEP_MPS2
    return [step * k for k in range(1, int(mu * G_MPS2 / step + 1e-9) + 1)]


def brake_in_turn(
    params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None
) -> VehicleTestResult:
    """The series on the initial circle (``TURN_BRAKE_RADIUS_M``; the speed of
    ``TURN_BRAKE_AY_MPS2`` on it unless given): one run per deceleration (``decel_<a>``). Not
    measured (no figures, the reason in ``not_measured``) when the road is too slippery for
    the series' first step, or the car is not on the circle at the brake's onset."""
    radius_m = c.TURN_BRAKE_RADIUS_M
    ay0 = min(c.TURN_BRAKE_AY_MPS2, 0.6 * options.mu * G_MPS2)  # a steady turn on any road
    default_kmh = math.sqrt(ay0 * radius_m) * 3.6
    speed_mps = options.speed_mps(default_kmh)
    series = decelerations_mps2(options.mu)
    runs, per_run, why = _series(params, options, vehicle, speed_mps, radius_m, series)
    if not series:
        why = _no_series(options.mu, speed_mps * speed_mps / radius_m)
    cut, why = (why, None) if per_run else (None, why)  # the runs measured before it stand
    summary = header("brake-in-turn", params, options, speed_mps)
    summary["figures"] = {
        "radius_m": radius_m,
        "initial_lateral_acceleration_mps2": round(speed_mps * speed_mps / radius_m, 4),
        "brake_onset_s": CIRCLE_S,
        "measured_after_onset_s": c.TURN_BRAKE_MEASURE_S,
        "runs": per_run,
        "clause": c.CITE["turn_brake"],
    }
    if cut is not None:
        summary["figures"]["series_cut"] = cut
    summary["criteria"] = []
    summary["passed"] = None
    if why is not None:
        summary["figures"]["not_measured"] = summary["not_measured"] = why
    return VehicleTestResult("brake-in-turn", tuple(runs), summary)


def _series(
    params: VehicleParams,
    options: VehicleTestOptions,
    vehicle: Vehicle | None,
    speed_mps: float,
    radius_m: float,
    series: list[float],
) -> tuple[list[Run], list[dict], str | None]:
    """The series' runs, the figures of those measured, and why it ended short (None: every
    run measured): the car off the circle at the first brake's onset (every run drives the
    same circle: none is measured, the run that shows it kept), or a brake that stops the car
    before its figures (a harder one stops it sooner: the series ends there)."""
    runs: list[Run] = []
    per_run: list[dict] = []
    for decel in series:
        run = _run(params, speed_mps, radius_m, decel, options.mu, vehicle)
        why = _off_circle(run, speed_mps, radius_m, options.mu)
        if why is not None:
            return [*runs, run], per_run, why
        why = _stopped_early(run, decel)
        if why is not None:
            return runs, per_run, why
        runs.append(run)
        per_run.append(_figures(run, decel, radius_m))
    return runs, per_run, None


def _no_series(mu: float, ay_mps2: float) -> str:
    """Why no run brakes: the series' first step is beyond the road's friction."""
    mu_g = mu * G_MPS2
    left_mps2 = math.sqrt(max(mu_g * mu_g - ay_mps2 * ay_mps2, 0.0))
    return (
        f"no run: the series' first deceleration, {c.TURN_BRAKE_DECEL_STEP_MPS2:g} m/s^2, is "
        f"beyond the road's friction (mu g = {mu_g:.2f} m/s^2; in the turn's {ay_mps2:.2f} "
        f"m/s^2 of lateral acceleration the tyres have {left_mps2:.2f} m/s^2 left to brake)"
    )


def _off_circle(run: Run, speed_mps: float, radius_m: float, mu: float) -> str | None:
    """Why the car is not on the initial circle at the brake's onset (``CIRCLE_TOLERANCE``),
    or None when it is."""
    r0_radps = float(run["yaw_rate_radps"][_onset_index(run)])
    circle_radps = speed_mps / radius_m
    if abs(r0_radps / circle_radps - 1.0) <= CIRCLE_TOLERANCE:
        return None
    return (
        f"no run measured: the car was not on the {radius_m:g} m circle when the brake came on "
        f"(yaw rate {math.degrees(r0_radps):.1f} deg/s, the circle's "
        f"{math.degrees(circle_radps):.1f} deg/s): the turn's lateral acceleration, "
        f"{speed_mps * circle_radps:.2f} m/s^2, is more than the car holds on this road "
        f"(mu g = {mu * G_MPS2:.2f} m/s^2)"
    )


def _stopped_early(run: Run, decel_mps2: float) -> str | None:
    """Why a run has no figures at ``c.TURN_BRAKE_MEASURE_S`` after the onset (the car
    stopped before it), or None when it has."""
    end_s = float(run["time_s"][-1])
    if end_s >= CIRCLE_S + c.TURN_BRAKE_MEASURE_S - 1e-9:
        return None
    return (
        f"from {decel_mps2:g} m/s^2 on no run measured: the car stopped "
        f"{max(end_s - CIRCLE_S, 0.0):.2f} s after the brake's onset, before the figures at "
        f"{c.TURN_BRAKE_MEASURE_S:g} s (ISO 7975)"
    )


def _onset_index(run: Run) -> int:
    """The sample of the brake's onset (``CIRCLE_S``)."""
    return int(np.searchsorted(run["time_s"], CIRCLE_S - 1e-9))


def _run(
    params: VehicleParams,
    speed_mps: float,
    radius_m: float,
    decel_mps2: float,
    mu: float,
    vehicle: Vehicle | None,
) -> Run:
    """One run: the circle found by an integral steering on the yaw rate ``v / R`` (speed
    held), that steering held for ``HOLD_S``, then the brake step at ``CIRCLE_S``."""
    keep = speed_keeper(params, speed_mps)
    r_target = speed_mps / radius_m
    steer = [params.wheelbase_m / radius_m]
    brake_n = params.mass_kg * decel_mps2

    def driver(t_s: float, s: Sample) -> Controls:
        if t_s < CIRCLE_S - HOLD_S:
            steer[0] += CIRCLE_GAIN_S * (r_target - s.yaw_rate_radps) * STEP_S
            return Controls(steer[0], keep(s), 0.0)
        if t_s < CIRCLE_S:
            return Controls(steer[0], keep(s), 0.0)
        return Controls(steer[0], 0.0, brake_n)

    return simulate(
        vehicle_for(params, vehicle),
        speed_mps,
        driver,
        CIRCLE_S + AFTER_S,
        mu,
        label=f"decel_{decel_mps2:g}",
        stop=lambda t, s: t > CIRCLE_S and s.vx_mps < 1.0,
    )


def _figures(run: Run, decel_mps2: float, radius_m: float) -> dict:
    """One run's figures at the onset ``t0`` and ``c.TURN_BRAKE_MEASURE_S`` after it."""
    t = run["time_s"]
    i0 = _onset_index(run)
    i1 = int(np.searchsorted(t, CIRCLE_S + c.TURN_BRAKE_MEASURE_S - 1e-9))
    i1 = min(i1, len(t) - 1)
    vx, r, ay = run["vx_mps"], run["yaw_rate_radps"], run["ay_mps2"]
    beta = np.arctan2(run["vy_mps"], np.maximum(vx, 0.1))
    course_rad = run["yaw_rad"][i0] + beta[i0]  # the velocity's direction at the onset
    centre = (-math.sin(course_rad), math.cos(course_rad))  # unit, to the left of it
    cx = run["x_m"][i0] + radius_of(run, i0) * centre[0]
    cy = run["y_m"][i0] + radius_of(run, i0) * centre[1]
    deviation = math.hypot(run["x_m"][i1] - cx, run["y_m"][i1] - cy) - radius_of(run, i0)
    max_beta_deg = float(np.degrees(np.max(np.abs(beta[i0:]))))
    use = run["friction_use_max"][1:]  # the start row is the harness's, not the plant's
    course = r[i0] * vx[i1] / vx[i0]  # the yaw rate that keeps the initial radius
    return {
        "run": run.label,
        "target_deceleration_mps2": decel_mps2,
        "mean_deceleration_mps2": rounded(-float(np.mean(run["ax_mps2"][i0 + 1 : i1 + 1]))),
        "initial_yaw_rate_degps": rounded(math.degrees(r[i0])),
        "yaw_rate_ratio": rounded(r[i1] / r[i0]),
        "yaw_rate_over_course": rounded(r[i1] / course),
        "lateral_acceleration_ratio": rounded(ay[i1] / ay[i0]),
        "sideslip_change_deg": rounded(math.degrees(beta[i1] - beta[i0])),
        "path_deviation_m": rounded(deviation),
        "front_locked": bool(locked(run["wheel_speed_front_mps"][i0:], vx[i0:]).any()),
        "rear_locked": bool(locked(run["wheel_speed_rear_mps"][i0:], vx[i0:]).any()),
        "a_wheel_locked": bool(locked(run["wheel_speed_min_mps"][i0:], vx[i0:]).any()),
        "max_sideslip_deg": rounded(max_beta_deg),
        "max_friction_use": rounded(float(np.max(use))) if np.isfinite(use).all() else None,
        "spun": max_beta_deg >= SPIN_SIDESLIP_DEG,
        "nominal_radius_m": radius_m,
    }


def radius_of(run: Run, i: int) -> float:
    """The path's radius at sample ``i``: ``|v| / r``."""
    return float(math.hypot(run["vx_mps"][i], run["vy_mps"][i]) / run["yaw_rate_radps"][i])
