"""The sine with dwell (FMVSS 126 S7.9 / UN R140 Annex 3): the slowly increasing steer finds
A, then one 0.7 Hz sine cycle with a 500 ms dwell at its second peak, at amplitudes from 1.5 A
in steps of 0.5 A up to the greater of 6.5 A and 270 deg. Each run is judged on the yaw-rate
ratios (S5.2.1, S5.2.2) and, from 5 A, the lateral displacement (S5.2.3). Clauses:
``clauses.py``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from eoam_sumo.params import G_MPS2, VehicleParams
from eoam_sumo.vehicle_tests import clauses as c
from eoam_sumo.vehicle_tests.common import (
    SETTLE_S,
    VehicleTestOptions,
    VehicleTestResult,
    criterion,
    header,
    overall,
    speed_keeper,
    vehicle_for,
)
from eoam_sumo.vehicle_tests.figures import crossing_value
from eoam_sumo.vehicle_tests.harness import Controls, Run, Sample, Vehicle, simulate
from eoam_sumo.vehicle_tests.steer_figures import (
    lateral_displacement_m,
    steer_sign_change_s,
    yaw_rate_ratios,
)
from eoam_sumo.vehicle_tests.steer_tests import slowly_increasing_steer

PERIOD_S = 1.0 / c.SWD_FREQUENCY_HZ
SECOND_REVERSAL_S = 0.75 * PERIOD_S
"""The steering's second reversal, where the dwell begins (after the beginning of steer)."""
COMPLETION_S = PERIOD_S + c.SWD_DWELL_S
"""Completion of steer, after the beginning of steer."""
SPIN_YAW_DEG = 90.0
"""A run counts as a spin once the heading has turned this far from the start (ours)."""
ROBOT_RATE_DEGPS = 1500.0
"""The steering robot's hand-wheel rate limit [deg/s] (ours: above the 1188 deg/s the 270 deg
sine of 0.7 Hz needs, 2 pi 0.7 x 270; FMVSS 126 S7.9 has the input made by a robot)."""
ROBOT_LAG_S = 0.01
"""The steering robot's lag [s] (ours: 0.1 % of the amplitude lost at 0.7 Hz)."""


def steering_robot(params: VehicleParams) -> VehicleParams:
    """``params`` steered by the test's robot (FMVSS 126 S7.9) in place of the vehicle's own
    steering actuator (the EOAM's, rate limited): ``ROBOT_RATE_DEGPS``, ``ROBOT_LAG_S``."""
    rate = math.radians(ROBOT_RATE_DEGPS) / params.steering_ratio
    return dataclasses.replace(params, max_steer_rate_radps=rate, steer_lag_s=ROBOT_LAG_S)


def sine_with_dwell_steer(t_s: float, amplitude: float) -> float:
    """The steering input ``t_s`` after the beginning of steer: a sine of ``SWD_FREQUENCY_HZ``
    held at its second peak (``-amplitude``) for ``SWD_DWELL_S``, then its last quarter."""
    omega = 2.0 * math.pi * c.SWD_FREQUENCY_HZ
    if t_s <= 0.0 or t_s >= COMPLETION_S:
        return 0.0
    if t_s < SECOND_REVERSAL_S:
        return amplitude * math.sin(omega * t_s)
    if t_s < SECOND_REVERSAL_S + c.SWD_DWELL_S:
        return -amplitude
    return amplitude * math.sin(omega * (t_s - c.SWD_DWELL_S))


def amplitudes_deg(a_deg: float) -> list[float]:
    """The series' hand-wheel amplitudes: 1.5 A, 2 A, ... up to the greater of 6.5 A and
    270 deg (the last one exactly that), or 300 deg where 6.5 A is more (S7.9.4); an amplitude
    within ``SWD_SAME_AMPLITUDE_DEG`` of the last is the last."""
    last_deg = min(
        max(c.SWD_LAST_AMPLITUDE_A * a_deg, c.SWD_LAST_AMPLITUDE_DEG), c.SWD_MAX_AMPLITUDE_DEG
    )
    series, k = [], 0
    while (
        amp := (c.SWD_FIRST_AMPLITUDE_A + k * c.SWD_AMPLITUDE_STEP_A) * a_deg
    ) < last_deg - c.SWD_SAME_AMPLITUDE_DEG:
        series.append(amp)
        k += 1
    return [*series, last_deg]


def displacement_min_m(mass_kg: float) -> float:
    """FMVSS 126 S5.2.3's least lateral displacement for a vehicle of ``mass_kg`` (the vehicle
    file's mass taken as the gross mass): 1.83 m up to 3 500 kg, 1.52 m above."""
    if mass_kg > c.DISPLACEMENT_HEAVY_ABOVE_KG:
        return c.DISPLACEMENT_MIN_HEAVY_M
    return c.DISPLACEMENT_MIN_M


def run_label(amplitude_a: float) -> str:
    """``amp_1.5A``, ``amp_2A``, ``amp_16.17A``: a run's label from its amplitude in A."""
    return f"amp_{f'{amplitude_a:.2f}'.rstrip('0').rstrip('.')}A"


def sine_with_dwell(
    params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None
):
    """The whole series: the slowly increasing steer (run ``sis``), then one run per amplitude
    (``amp_<k>A``, the first half-wave to the left); figures per run and pass/fail."""
    speed_mps = options.speed_mps(c.SWD_SPEED_KMH)
    sis = slowly_increasing_steer(params, speed_mps, options.mu, vehicle, until_ay_g=0.35)
    sis = Run("sis", sis.columns)
    a_deg = crossing_value(
        sis["steer_wheel_deg"], np.abs(sis["ay_mps2"]), c.SIS_TARGET_AY_G * G_MPS2
    )
    summary = header("sine-with-dwell", params, options, speed_mps)
    if a_deg is None:
        summary.update(figures={"A_deg": None}, criteria=[], passed=None)
        summary["figures"]["not_measured"] = summary["not_measured"] = (
            f"no A: the slowly increasing steer never reached {c.SIS_TARGET_AY_G} g "
            f"(mu g = {options.mu * G_MPS2:.2f} m/s^2), so no sine with dwell was run"
        )
        return VehicleTestResult("sine-with-dwell", (sis,), summary)
    runs, per_run, criteria = [sis], [], []
    for amp_deg in amplitudes_deg(a_deg):
        label = run_label(amp_deg / a_deg)
        run = _swd_run(params, speed_mps, amp_deg, options.mu, vehicle, label)
        figures, judged = _judge(run, amp_deg, a_deg, params.mass_kg)
        runs.append(run)
        per_run.append(figures)
        criteria.extend(judged)
    summary["figures"] = {"A_deg": round(a_deg, 3), "runs": per_run, "clause": c.CITE["swd"]}
    summary["criteria"] = criteria
    summary["passed"] = overall(criteria)
    if params.mass_kg > c.SWD_MAX_MASS_KG:
        outside_scope(summary, params.mass_kg)
    return VehicleTestResult("sine-with-dwell", tuple(runs), summary)


def outside_scope(summary: dict, mass_kg: float) -> None:
    """No verdict for a vehicle heavier than FMVSS 126 covers (S3): its criteria kept as
    figures, unjudged."""
    for criterion_ in summary["criteria"]:
        criterion_["passed"] = None
    summary["passed"] = None
    summary["note"] = (
        f"{mass_kg:.0f} kg is above the {c.SWD_MAX_MASS_KG:.0f} kg the standard "
        "applies to (FMVSS 126 S3; the vehicle file's mass taken as the gross mass)"
    )


def _swd_run(
    params: VehicleParams,
    speed_mps: float,
    amp_deg: float,
    mu: float,
    vehicle: Vehicle | None,
    label: str,
) -> Run:
    """One sine-with-dwell run: speed held, then from the beginning of steer (``SETTLE_S``) the
    throttle released and the hand wheel through ``sine_with_dwell_steer`` by the steering
    robot (``steering_robot``)."""
    params = steering_robot(params)
    keep = speed_keeper(params, speed_mps)
    amp_rad = math.radians(amp_deg) / params.steering_ratio

    def driver(t_s: float, s: Sample) -> Controls:
        if t_s < SETTLE_S:
            return Controls(0.0, keep(s), 0.0)
        return Controls(sine_with_dwell_steer(t_s - SETTLE_S, amp_rad), 0.0, 0.0)

    duration_s = SETTLE_S + COMPLETION_S + 1.75 + 0.25
    return simulate(vehicle_for(params, vehicle), speed_mps, driver, duration_s, mu, label=label)


def _judge(run: Run, amp_deg: float, a_deg: float, mass_kg: float) -> tuple[dict, list[dict]]:
    """One run's figures and its criteria (the displacement from 5 A only, its limit by the
    vehicle's mass: ``displacement_min_m``). The yaw-rate peak is searched from the steering's
    sign change between its first and second peaks, measured on the run's hand-wheel angle
    (FMVSS 126 S5.2.1; about ``SETTLE_S + PERIOD_S / 2``, the robot's lag later)."""
    time_s = run["time_s"]
    sign_change_s = steer_sign_change_s(time_s, run["steer_wheel_deg"])
    ratios = yaw_rate_ratios(
        time_s, run["yaw_rate_radps"], sign_change_s, SETTLE_S + COMPLETION_S, -1.0
    )
    displacement = lateral_displacement_m(
        time_s, run["x_m"], run["y_m"], run["yaw_rad"], SETTLE_S, c.DISPLACEMENT_TIME_S
    )
    max_yaw_deg = float(np.degrees(np.max(np.abs(run["yaw_rad"]))))
    label = run.label
    judged = [
        criterion(
            f"{label}.yaw_ratio_1s", ratios.ratio_1s, c.YAW_RATIO_1S_MAX, True, c.CITE["yaw_1s"]
        ),
        criterion(
            f"{label}.yaw_ratio_1.75s",
            ratios.ratio_175s,
            c.YAW_RATIO_175S_MAX,
            True,
            c.CITE["yaw_175s"],
        ),
    ]
    if amp_deg >= c.DISPLACEMENT_FROM_A * a_deg - 1e-9:
        judged.append(
            criterion(
                f"{label}.lateral_displacement_m",
                displacement,
                displacement_min_m(mass_kg),
                False,
                c.CITE["displacement"],
            )
        )
    figures = {
        "run": label,
        "amplitude_deg": round(amp_deg, 3),
        "amplitude_A": round(amp_deg / a_deg, 3),
        "peak_steer_wheel_deg": round(float(np.max(np.abs(run["steer_wheel_deg"]))), 3),
        "steer_sign_change_s": round(sign_change_s, 4),
        "peak_yaw_rate_degps": round(math.degrees(ratios.peak_radps), 3),
        "peak_yaw_rate_time_s": round(ratios.peak_time_s, 3),
        "yaw_ratio_1s": round(ratios.ratio_1s, 4),
        "yaw_ratio_1.75s": round(ratios.ratio_175s, 4),
        "lateral_displacement_m": round(displacement, 4),
        "max_heading_change_deg": round(max_yaw_deg, 2),
        "spun": max_yaw_deg >= SPIN_YAW_DEG,
    }
    return figures, judged
