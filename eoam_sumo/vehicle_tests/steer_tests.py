"""The steering tests at constant speed: ``ramp-steer`` (ISO 4138, slowly increasing steer)
and ``step-steer`` (ISO 7401 sec. 10). Clauses: ``clauses.py``; the sine with dwell is in
``sine_with_dwell.py``."""

from __future__ import annotations

import collections
import math

import numpy as np

from eoam_sumo.params import G_MPS2, VehicleParams
from eoam_sumo.vehicle_tests import clauses as c
from eoam_sumo.vehicle_tests.common import (
    SETTLE_S,
    VehicleTestOptions,
    VehicleTestResult,
    header,
    rounded,
    speed_keeper,
    vehicle_for,
)
from eoam_sumo.vehicle_tests.harness import Controls, Run, Sample, Vehicle, simulate
from eoam_sumo.vehicle_tests.steer_figures import (
    LINEAR_AY_RANGE_G,
    LINEAR_PEAK_FRACTION,
    StepResponse,
    drift_over_window,
    linear_range_g,
    steer_angle_gradient_deg_per_g,
    step_response,
    understeer_gradient_deg_per_g,
)

RAMP_END_FRACTION = 0.9
"""A ramp steer ends once the lateral acceleration has fallen below this share of its peak
(past the limit: more steering gives no more lateral acceleration) or the speed to half."""

RAMP_STEER_RATE_DEGPS = 2.0
"""Hand-wheel rate of the ramp steer [deg/s] (ours: slow enough that the understeer gradient
is within 2 % of the one of steady turns at constant steer; at the 13.5 deg/s of the FMVSS 126
slowly increasing steer the yaw response's lag adds about 0.1 deg/g)."""

QUASI_STEADY_TOLERANCE = 0.1
"""A ramp steer also ends when the sideslip grows faster than in steady turns by more than this
share of the lateral acceleration (``RampStop``): the turn is no longer quasi-steady (a spin,
a slide, a wheel lifting), and ISO 4138 describes steady turns. The step steer's end is judged
on ``ay - vx r`` with the same share (``step_sliding``)."""

AY_RATE_WINDOW_S = 0.5
"""The lateral acceleration's rate in the ramp's quasi-steady check is its change over this
window [s] (ours: 50 samples, smooth on a ramp, short beside its many seconds)."""

RAMP_MIN_PEAK_MU = 0.2
"""... judged once the peak is above this share of ``mu g`` (any car gets there; below it,
the first wobbles of a noisy model would end the ramp)."""

STEP_RISE_S = 0.1
"""Time of the step's steering ramp [s] (ours: a steering robot's quick step)."""

STEP_HOLD_S = 4.0
"""The step steer is held this long [s]; the last second gives the steady state."""

STEP_ITERATIONS = 3
"""Runs to scale the step to the standard's steady-state lateral acceleration."""

STEP_AY_TOLERANCE = 0.05
"""The step steer is measured only when its last second's lateral acceleration is within this
share of the standard's 4 m/s^2 and changes by no more than it (ours): short of it, the road
cannot give the lateral acceleration (the step was scaled towards the lock, the tyres are at
their limit) and the response is the friction's, not the car's transient response."""


def ramp_steer(params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None):
    """ISO 4138 at constant speed: the hand wheel turned left at ``RAMP_STEER_RATE_DEGPS`` with
    the speed held, until the lateral acceleration stops growing or the turn stops being
    quasi-steady (``RampStop``; ``ramp_end`` says which). Figures over the linear range
    (``linear_range_g``: 0.1-0.4 g, at most half the peak): the understeer gradient and the
    steering angle gradient (deg of road-wheel angle per g; of hand-wheel angle: times the
    steering ratio); the peak lateral acceleration."""
    speed_mps = options.speed_mps(c.RAMP_SPEED_KMH)
    stop = RampStop(params, speed_mps, options.mu, None)
    run = slowly_increasing_steer(
        params, speed_mps, options.mu, vehicle, rate_degps=RAMP_STEER_RATE_DEGPS, stop=stop
    )
    peak_mps2 = float(np.max(np.abs(run["ay_mps2"])))
    fit_range_g = linear_range_g(peak_mps2 / G_MPS2)
    summary = header("ramp-steer", params, options, speed_mps)
    gradients = _gradients(run, params, fit_range_g)
    summary["figures"] = {
        **gradients,
        "steer_rate_degps": RAMP_STEER_RATE_DEGPS,
        "fit_range_g": None if "not_measured" in gradients else [round(g, 4) for g in fit_range_g],
        "fit_range_rule": f"{LINEAR_AY_RANGE_G[0]:g} g to the lesser of "
        f"{LINEAR_AY_RANGE_G[1]:g} g and {LINEAR_PEAK_FRACTION:g} of the peak",
        "peak_lateral_acceleration_mps2": round(peak_mps2, 4),
        "peak_lateral_acceleration_g": round(peak_mps2 / G_MPS2, 4),
        "ramp_end": stop.reason,
        "clause": c.CITE["ramp"],
    }
    summary["criteria"] = []
    summary["passed"] = None
    if "not_measured" in gradients:
        summary["figures"]["not_measured"] += f"; the ramp ended: {stop.reason}"
        summary["not_measured"] = summary["figures"]["not_measured"]
    return VehicleTestResult("ramp-steer", (run,), summary)


def _gradients(run: Run, params: VehicleParams, fit_range_g: tuple[float, float]) -> dict:
    """The ramp steer's gradients over ``fit_range_g``; ``None`` with the reason under
    ``not_measured`` when the run has no samples there (a low mu or speed: the road or the
    turn cannot give 0.1 g, or not twice that), as ISO 4138's figures are defined there only."""
    road_rad = np.radians(run["steer_wheel_deg"]) / params.steering_ratio
    try:
        steer_gradient = steer_angle_gradient_deg_per_g(run["ay_mps2"], road_rad, fit_range_g)
        gradient = understeer_gradient_deg_per_g(
            run["ay_mps2"],
            road_rad,
            run["yaw_rate_radps"],
            run["vx_mps"],
            params.wheelbase_m,
            fit_range_g,
        )
    except ValueError:
        peak_g = float(np.max(np.abs(run["ay_mps2"]))) / G_MPS2
        low_g, high_g = LINEAR_AY_RANGE_G
        return {
            "understeer_gradient_deg_per_g": None,
            "steer_angle_gradient_deg_per_g": None,
            "steering_wheel_angle_gradient_deg_per_g": None,
            "not_measured": f"no linear range to fit: the lateral acceleration (peak "
            f"{peak_g:.3f} g) never spans the fit range {low_g:g}-{high_g:g} g below "
            f"{LINEAR_PEAK_FRACTION:g} of its peak ({fit_range_g[1]:.3f} g)",
        }
    return {
        "understeer_gradient_deg_per_g": round(gradient, 4),
        "steer_angle_gradient_deg_per_g": round(steer_gradient, 4),
        "steering_wheel_angle_gradient_deg_per_g": round(steer_gradient * params.steering_ratio, 3),
    }


def slowly_increasing_steer(
    params: VehicleParams,
    speed_mps: float,
    mu: float,
    vehicle: Vehicle | None,
    *,
    rate_degps: float = c.SIS_STEER_RATE_DEGPS,
    until_ay_g: float | None = None,
    stop: RampStop | None = None,
) -> Run:
    """Hand wheel turned left at ``rate_degps`` from ``SETTLE_S`` with the speed held, until
    the lateral acceleration reaches ``until_ay_g`` (None: until it falls past its peak or the
    turn is no longer quasi-steady, ``RampStop``; pass one to read why the run ended)."""
    keep = speed_keeper(params, speed_mps)
    rate_radps = math.radians(rate_degps) / params.steering_ratio
    stop = stop or RampStop(params, speed_mps, mu, until_ay_g)

    def driver(t_s: float, s: Sample) -> Controls:
        return Controls(rate_radps * max(t_s - SETTLE_S, 0.0), keep(s), 0.0)

    duration_s = SETTLE_S + params.max_steer_rad / rate_radps + 2.0
    return simulate(vehicle_for(params, vehicle), speed_mps, driver, duration_s, mu, stop=stop)


def linear_sideslip_gain_s(params: VehicleParams, vx_mps: float) -> float:
    """``d vy / d ay`` of steady turns in the linear single-track model [s]: ``vy = vx beta``,
    ``beta = b / R - m a vx^2 / (L C_r R)`` (Gillespie ch. 6) and ``1 / R = ay / vx^2``, so
    ``b / vx - m a vx / (L C_r)``. A ramp of ``ay`` grows the sideslip at this times its rate
    (``ay - vx r = dvy / dt``): at 250 km/h the corrected sedan's -0.41 s. Beyond an
    oversteering car's critical speed (``L + K_us vx^2 <= 0``) no turn is steady: 0, so that
    any growth of the sideslip counts."""
    if params.wheelbase_m + params.understeer_gradient_rad_per_mps2 * vx_mps**2 <= 0.0:
        return 0.0
    rear_share = params.mass_kg * params.cg_to_front_m / params.wheelbase_m
    return params.cg_to_rear_m / vx_mps - rear_share * vx_mps / params.cornering_stiffness_rear_npr


class RampStop:
    """When a slowly increasing steer ends, and ``reason``: why it did. Quasi-steady means
    that the sideslip grows as steady turns of the lateral acceleration reached would have it
    (``linear_sideslip_gain_s`` times the lateral acceleration's rate), within
    ``QUASI_STEADY_TOLERANCE`` of the lateral acceleration: a slide or a spin grows it faster.
    (``ay - vx r`` alone, the sideslip's rate, tripped on a steady ramp at 250 km/h.)"""

    def __init__(
        self, params: VehicleParams, speed_mps: float, mu: float, until_ay_g: float | None
    ) -> None:
        self.params, self.speed_mps, self.until_ay_g = params, speed_mps, until_ay_g
        self.judged_from_mps2 = RAMP_MIN_PEAK_MU * mu * G_MPS2
        self.peak_mps2 = 0.0
        self.recent: collections.deque[tuple[float, float]] = collections.deque()
        self.reason = "the steering reached its largest angle"

    def __call__(self, t_s: float, s: Sample) -> bool:
        ay = abs(s.ay_mps2)
        self.peak_mps2 = max(self.peak_mps2, ay)
        self.recent.append((t_s, s.ay_mps2))
        while t_s - self.recent[0][0] > AY_RATE_WINDOW_S:
            self.recent.popleft()
        if self.until_ay_g is not None:
            return self._ends(ay >= self.until_ay_g * G_MPS2, f"{self.until_ay_g:g} g reached")
        if s.vx_mps < 0.5 * self.speed_mps:
            return self._ends(True, f"the speed fell to {s.vx_mps:.1f} m/s, below half")
        if self.peak_mps2 <= self.judged_from_mps2:
            return False
        if ay < RAMP_END_FRACTION * self.peak_mps2:
            return self._ends(
                True,
                f"the lateral acceleration fell below {RAMP_END_FRACTION:g} of its peak "
                f"({self.peak_mps2 / G_MPS2:.3f} g): the limit was passed",
            )
        return self._ends(*self._slide(s))

    def _slide(self, s: Sample) -> tuple[bool, str]:
        """Whether the sideslip grows faster than steady turns' (a slide or a spin), and why."""
        (t0, ay0), (t1, ay1) = self.recent[0], self.recent[-1]
        ay_rate = (ay1 - ay0) / (t1 - t0) if t1 > t0 else 0.0
        sideslip_rate = s.ay_mps2 - s.vx_mps * s.yaw_rate_radps
        steady_rate = linear_sideslip_gain_s(self.params, s.vx_mps) * ay_rate
        if abs(sideslip_rate - steady_rate) <= QUASI_STEADY_TOLERANCE * abs(s.ay_mps2):
            return False, ""
        return True, (
            f"the turn stopped being quasi-steady at {abs(s.ay_mps2) / G_MPS2:.3f} g (a slide "
            f"or a spin): the sideslip grew at dvy/dt = {sideslip_rate:+.3f} m/s^2 against "
            f"{steady_rate:+.3f} m/s^2 in steady turns, more than {QUASI_STEADY_TOLERANCE:g} "
            f"of the lateral acceleration"
        )

    def _ends(self, ended: bool, reason: str) -> bool:
        if ended:
            self.reason = reason
        return ended


def step_steer(params: VehicleParams, options: VehicleTestOptions, vehicle: Vehicle | None = None):
    """ISO 7401 sec. 10: a step of the hand wheel (left, ``STEP_RISE_S``) held for
    ``STEP_HOLD_S``, throttle held from the step on; the step scaled (``STEP_ITERATIONS``
    runs) to a steady-state lateral acceleration of 4 m/s^2. Figures of the yaw rate and of
    the lateral acceleration: steady-state gain, response time, peak response time, overshoot;
    not measured (``None``, the reason in ``not_measured``) when the steady state is not that
    lateral acceleration (``STEP_AY_TOLERANCE``: beyond the road's friction)."""
    speed_mps = options.speed_mps(c.STEP_SPEED_KMH)
    steer_rad = _linear_steer_rad(params, speed_mps, c.STEP_AY_MPS2)
    for _ in range(STEP_ITERATIONS):
        run = _step_run(params, speed_mps, steer_rad, options.mu, vehicle)
        steady_ay = step_response(run["time_s"], run["steer_wheel_deg"], run["ay_mps2"])
        steer_rad *= c.STEP_AY_MPS2 / max(steady_ay.steady_state, 0.1)
    yaw = step_response(run["time_s"], run["steer_wheel_deg"], run["yaw_rate_radps"])
    ay = step_response(run["time_s"], run["steer_wheel_deg"], run["ay_mps2"])
    why = _step_not_measured(ay.steady_state, drift_over_window(run["time_s"], run["ay_mps2"]))
    if ay.steady_state >= c.STEP_AY_MPS2 * (1.0 - STEP_AY_TOLERANCE):
        why = step_sliding(run) or why  # above or near the level: a slide says more
    summary = header("step-steer", params, options, speed_mps)
    summary["figures"] = {
        "steer_wheel_deg": round(float(run["steer_wheel_deg"][-1]), 3),
        "target_lateral_acceleration_mps2": c.STEP_AY_MPS2,
        "steady_lateral_acceleration_mps2": round(ay.steady_state, 4),
        **_step_figures(yaw, ay, params.steering_ratio, measured=why is None),
        "clause": c.CITE["step"],
    }
    summary["criteria"] = []
    summary["passed"] = None
    if why is not None:
        summary["figures"]["not_measured"] = summary["not_measured"] = (
            f"{why}; mu g = {options.mu * G_MPS2:.2f} m/s^2; no ISO 7401 gain, response time "
            "or overshoot"
        )
    return VehicleTestResult("step-steer", (run,), summary)


def step_sliding(run: Run) -> str | None:
    """Why the step's end is no steady turn: the lateral acceleration departs from ``vx r`` by
    more than ``QUASI_STEADY_TOLERANCE`` (the car slides or spins), or None."""
    vx, r, ay = run["vx_mps"][-1], run["yaw_rate_radps"][-1], run["ay_mps2"][-1]
    turn_mps2 = float(vx * r)
    if abs(turn_mps2 - ay) <= QUASI_STEADY_TOLERANCE * max(abs(turn_mps2), c.STEP_AY_MPS2):
        return None
    return (
        f"no steady turn: at the end the car slides or spins (vx r = {turn_mps2:.2f} m/s^2 "
        f"against a lateral acceleration of {ay:.2f} m/s^2; speed {run['vx_mps'][0]:.1f} -> "
        f"{vx:.1f} m/s)"
    )


def _step_not_measured(steady_mps2: float, drift_mps2: float) -> str | None:
    """Why a step steer's steady state is not ISO 7401's 4 m/s^2 (``STEP_AY_TOLERANCE``), or
    None when it is."""
    target, allowed = c.STEP_AY_MPS2, STEP_AY_TOLERANCE * c.STEP_AY_MPS2
    if abs(steady_mps2 - target) > allowed:
        where = "short of" if steady_mps2 < target else "above"
        return (
            f"the steady-state lateral acceleration reached, {steady_mps2:.2f} m/s^2, is "
            f"{abs(steady_mps2 - target) / target:.0%} {where} the standard's {target:g} m/s^2 "
            f"(more than {STEP_AY_TOLERANCE:.0%})"
            + (": the road cannot give it" if steady_mps2 < target else "")
        )
    if abs(drift_mps2) > allowed:
        return (
            f"no steady state: the lateral acceleration still changes by {drift_mps2:+.2f} "
            f"m/s^2 over the last second (more than {STEP_AY_TOLERANCE:.0%} of {target:g} m/s^2)"
        )
    return None


def _step_figures(
    yaw: StepResponse, ay: StepResponse, steering_ratio: float, measured: bool
) -> dict:
    """ISO 7401's figures of the yaw rate and the lateral acceleration (``None`` unless
    ``measured``)."""
    figures = {
        "yaw_rate_gain_per_s": round(yaw.gain * 180.0 / math.pi * steering_ratio, 5),
        "yaw_rate_gain_degps_per_deg": round(math.degrees(yaw.gain), 5),
        "yaw_rate_response_time_s": rounded(yaw.response_time_s),
        "yaw_rate_peak_response_time_s": rounded(yaw.peak_response_time_s),
        "yaw_rate_overshoot": round(yaw.overshoot, 4),
        "lateral_acceleration_response_time_s": rounded(ay.response_time_s),
        "lateral_acceleration_peak_response_time_s": rounded(ay.peak_response_time_s),
        "lateral_acceleration_overshoot": round(ay.overshoot, 4),
    }
    return figures if measured else dict.fromkeys(figures)


def _linear_steer_rad(params: VehicleParams, speed_mps: float, ay_mps2: float) -> float:
    """Road-wheel angle of a steady turn at ``ay_mps2`` in the linear single-track model."""
    a, b, L = params.cg_to_front_m, params.cg_to_rear_m, params.wheelbase_m
    k_us = (
        params.mass_kg
        / L
        * (b / params.front_axle_stiffness_npr - a / params.cornering_stiffness_rear_npr)
    )
    return (L / (speed_mps * speed_mps) + k_us) * ay_mps2


def _step_run(
    params: VehicleParams, speed_mps: float, steer_rad: float, mu: float, vehicle: Vehicle | None
) -> Run:
    keep = speed_keeper(params, speed_mps)
    held_n: list[float] = []

    def driver(t_s: float, s: Sample) -> Controls:
        if t_s < SETTLE_S:
            return Controls(0.0, keep(s), 0.0)
        if not held_n:
            held_n.append(keep(s))
        return Controls(steer_rad * min((t_s - SETTLE_S) / STEP_RISE_S, 1.0), held_n[0], 0.0)

    duration_s = SETTLE_S + STEP_HOLD_S
    return simulate(vehicle_for(params, vehicle), speed_mps, driver, duration_s, mu)
