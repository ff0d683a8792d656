"""The steering tests' figures from time series: pure functions of arrays (``clauses.py``)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from eoam_sumo.params import G_MPS2

LINEAR_AY_RANGE_G = (0.1, 0.4)
"""Lateral accelerations over which the understeer gradient is fitted on a dry road (ours: the
linear range of a passenger car's tyres, below the 0.5 g the slowly increasing steer reaches);
``linear_range_g`` narrows it to the car's limit on the road of the test."""

LINEAR_PEAK_FRACTION = 0.5
"""The fit ends at most at this share of the peak lateral acceleration the run reached (ours:
below about half its peak a tyre's force is close to proportional to its slip, and the
gradients are figures of that linear range; above it the road's friction sets the steer)."""


def linear_range_g(peak_g: float) -> tuple[float, float]:
    """The fit range [g] of a run that peaked at ``peak_g``: ``LINEAR_AY_RANGE_G``, its upper
    end at most ``LINEAR_PEAK_FRACTION`` of the peak (empty, low > high, below 0.2 g)."""
    low_g, high_g = LINEAR_AY_RANGE_G
    return low_g, min(high_g, LINEAR_PEAK_FRACTION * peak_g)


def understeer_gradient_deg_per_g(
    ay_mps2: np.ndarray,
    steer_road_rad: np.ndarray,
    yaw_rate_radps: np.ndarray,
    vx_mps: np.ndarray,
    wheelbase_m: float,
    ay_range_g: tuple[float, float] = LINEAR_AY_RANGE_G,
) -> float:
    """Understeer gradient (ISO 4138): the slope over the lateral acceleration of the
    road-wheel angle less the Ackermann angle ``L / R``, the path curvature ``1 / R = r / vx``
    taken per sample (so a speed that drifts does not bias it), fitted by least squares over
    ``ay_range_g``; in deg of road-wheel angle per g."""
    ay_g = np.abs(ay_mps2) / G_MPS2
    window = (ay_g >= ay_range_g[0]) & (ay_g <= ay_range_g[1])
    if np.count_nonzero(window) < 2:
        raise ValueError(f"no lateral acceleration within {ay_range_g} g to fit")
    sign = np.sign(np.mean(ay_mps2[window]))
    ackermann_rad = wheelbase_m * yaw_rate_radps[window] / vx_mps[window]
    excess_rad = sign * (steer_road_rad[window] - ackermann_rad)
    slope = np.polyfit(sign * ay_mps2[window], excess_rad, 1)[0]
    return math.degrees(slope) * G_MPS2


def steer_angle_gradient_deg_per_g(
    ay_mps2: np.ndarray,
    steer_road_rad: np.ndarray,
    ay_range_g: tuple[float, float] = LINEAR_AY_RANGE_G,
) -> float:
    """Steering angle gradient (ISO 4138): the slope of the road-wheel angle over the lateral
    acceleration, least squares over ``ay_range_g``; deg per g (times the steering ratio: the
    steering-wheel angle gradient)."""
    window = (np.abs(ay_mps2) >= ay_range_g[0] * G_MPS2) & (
        np.abs(ay_mps2) <= ay_range_g[1] * G_MPS2
    )
    if np.count_nonzero(window) < 2:
        raise ValueError(f"no lateral acceleration within {ay_range_g} g to fit")
    slope = np.polyfit(np.abs(ay_mps2[window]), np.abs(steer_road_rad[window]), 1)[0]
    return math.degrees(slope) * G_MPS2


class StepResponse(NamedTuple):
    """ISO 7401 sec. 10 figures of a step steer's response (yaw rate or lateral acceleration)."""

    steady_state: float
    gain: float  # steady-state response per unit of the steering input's final value
    response_time_s: float | None  # 50 % of the steering input -> 90 % of the steady state
    peak_response_time_s: float | None  # 50 % of the steering input -> the response's peak
    overshoot: float  # (peak - steady) / steady


def step_response(
    time_s: np.ndarray,
    steer: np.ndarray,
    response: np.ndarray,
    steady_window_s: float = 1.0,
) -> StepResponse:
    """The step response's figures; the steady state is the mean over the last
    ``steady_window_s`` of the series, the input's final value its mean over the same window."""
    tail = time_s >= time_s[-1] - steady_window_s
    steer_final = float(np.mean(steer[tail]))
    steady = float(np.mean(response[tail]))
    sign_in, sign_out = math.copysign(1.0, steer_final), math.copysign(1.0, steady)
    t_half = _first_crossing_time(time_s, sign_in * steer, 0.5 * abs(steer_final))
    t_90 = _first_crossing_time(time_s, sign_out * response, 0.9 * abs(steady))
    k_peak = int(np.argmax(sign_out * response))
    peak = float(response[k_peak])
    return StepResponse(
        steady_state=steady,
        gain=steady / steer_final,
        response_time_s=None if t_half is None or t_90 is None else t_90 - t_half,
        peak_response_time_s=None if t_half is None else float(time_s[k_peak]) - t_half,
        overshoot=(peak - steady) / steady,
    )


def drift_over_window(time_s: np.ndarray, response: np.ndarray, window_s: float = 1.0) -> float:
    """How much ``response`` still changes over the last ``window_s`` of the series: its
    least-squares slope there times ``window_s`` (0 for a steady state)."""
    tail = time_s >= time_s[-1] - window_s
    if np.count_nonzero(tail) < 2:
        return 0.0
    return float(np.polyfit(time_s[tail], response[tail], 1)[0]) * window_s


def _first_crossing_time(time_s: np.ndarray, y: np.ndarray, level: float) -> float | None:
    idx = np.flatnonzero(y >= level)
    if idx.size == 0:
        return None
    k = int(idx[0])
    if k == 0:
        return float(time_s[0])
    frac = (level - y[k - 1]) / (y[k] - y[k - 1])
    return float(time_s[k - 1] + frac * (time_s[k] - time_s[k - 1]))


class YawRatios(NamedTuple):
    """FMVSS 126 S5.2.1 / S5.2.2: the yaw rate 1.0 s and 1.75 s after the completion of steer
    over the first peak value of yaw rate recorded after the steering wheel angle changes sign
    (signed: a yaw rate that keeps the peak's sign is positive; above 1 the vehicle is still
    yawing harder)."""

    peak_radps: float
    peak_time_s: float
    ratio_1s: float
    ratio_175s: float


def steer_sign_change_s(time_s: np.ndarray, steer: np.ndarray) -> float:
    """When the steering changes sign between its first and second peaks (FMVSS 126 S5.2.1):
    the first zero crossing after the first peak, interpolated between the samples. The first
    half-wave's side is that of the first sample beyond half the largest angle."""
    large = np.flatnonzero(np.abs(steer) > 0.5 * np.max(np.abs(steer)))
    signed = math.copysign(1.0, float(steer[int(large[0])])) * steer
    k_peak = int(np.argmax(signed))
    k = k_peak + int(np.flatnonzero(signed[k_peak:] < 0.0)[0])
    frac = signed[k - 1] / (signed[k - 1] - signed[k])
    return float(time_s[k - 1] + frac * (time_s[k] - time_s[k - 1]))


def first_peak_index(signed: np.ndarray) -> int:
    """The first local peak of ``signed`` (positive, not below the sample before it in the
    window, above the one after it); its first sample counts. With none (a yaw rate still
    growing at the end: a spin) the largest sample."""
    inner = signed[:-1]
    before = np.concatenate(([-np.inf], signed[:-2]))
    peaks = np.flatnonzero((inner > 0.0) & (inner >= before) & (inner > signed[1:]))
    return int(peaks[0]) if peaks.size else int(np.argmax(signed))


def yaw_rate_ratios(
    time_s: np.ndarray,
    yaw_rate_radps: np.ndarray,
    sign_change_s: float,
    completion_s: float,
    peak_sign: float,
) -> YawRatios:
    """The yaw-rate ratios of one sine-with-dwell run. The peak is "the first peak value of yaw
    rate recorded after the steering wheel angle changes sign (between first and second
    peaks)" (FMVSS 126 S5.2.1, S5.2.2): the first local peak of ``peak_sign * yaw rate`` from
    ``sign_change_s`` on (``first_peak_index``: the window's first sample included)."""
    signed = peak_sign * yaw_rate_radps
    k0 = int(np.flatnonzero(time_s >= sign_change_s)[0])
    k_peak = k0 + first_peak_index(signed[k0:])
    peak = float(signed[k_peak])
    at_1s = float(np.interp(completion_s + 1.0, time_s, signed))
    at_175s = float(np.interp(completion_s + 1.75, time_s, signed))
    return YawRatios(peak_sign * peak, float(time_s[k_peak]), at_1s / peak, at_175s / peak)


def lateral_displacement_m(
    time_s: np.ndarray,
    x_m: np.ndarray,
    y_m: np.ndarray,
    yaw_rad: np.ndarray,
    begin_s: float,
    after_s: float,
) -> float:
    """FMVSS 126 S5.2.3: the centre of gravity's displacement to the left of its straight path
    at the beginning of steer (``begin_s``), ``after_s`` later."""
    x0, y0 = np.interp(begin_s, time_s, x_m), np.interp(begin_s, time_s, y_m)
    heading = float(np.interp(begin_s, time_s, yaw_rad))
    t = begin_s + after_s
    dx, dy = np.interp(t, time_s, x_m) - x0, np.interp(t, time_s, y_m) - y0
    return float(-math.sin(heading) * dx + math.cos(heading) * dy)
