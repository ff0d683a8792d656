"""The standards' figures against closed-form answers on hand-made time series."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.params import G_MPS2
from eoam_sumo.vehicle_tests.figures import (
    LockOrder,
    crossing_value,
    lock_order,
    locked,
    mfdd_mps2,
    path_length_m,
    stop_time_s,
    stopping_distance_limit_m,
)
from eoam_sumo.vehicle_tests.harness import Run
from eoam_sumo.vehicle_tests.sine_with_dwell import (
    COMPLETION_S,
    PERIOD_S,
    SECOND_REVERSAL_S,
    amplitudes_deg,
    displacement_min_m,
    run_label,
    sine_with_dwell_steer,
)
from eoam_sumo.vehicle_tests.steer_figures import (
    lateral_displacement_m,
    steer_angle_gradient_deg_per_g,
    steer_sign_change_s,
    step_response,
    understeer_gradient_deg_per_g,
    yaw_rate_ratios,
)

DT = 0.001


def test_the_stopping_distance_limit_is_70_m_from_100_kmh():
    assert stopping_distance_limit_m(100.0) == pytest.approx(70.0)
    assert stopping_distance_limit_m(50.0) == pytest.approx(20.0)


def _constant_deceleration(v0_mps: float, decel_mps2: float):
    t = np.arange(0.0, v0_mps / decel_mps2 + 1.0, DT)
    speed = np.maximum(v0_mps - decel_mps2 * t, 0.0)
    t_stop = v0_mps / decel_mps2
    travelled = np.where(
        t < t_stop, v0_mps * t - 0.5 * decel_mps2 * t * t, v0_mps**2 / 2 / decel_mps2
    )
    return t, speed, travelled


def test_a_constant_deceleration_gives_the_closed_form_stop_and_mfdd():
    v0, decel = 27.0, 8.0
    t, speed, travelled = _constant_deceleration(v0, decel)
    t_stop = stop_time_s(t, speed, 0.0)
    assert t_stop == pytest.approx((v0 - 0.01) / decel, abs=2 * DT)
    assert np.interp(t_stop, t, travelled) == pytest.approx(v0 * v0 / 2 / decel, abs=0.01)
    assert mfdd_mps2(speed, travelled, v0) == pytest.approx(decel, rel=1e-4)


def test_the_mfdd_is_the_regulations_km_h_formula():
    """R13-H: dm = (vb^2 - ve^2) / (25.92 (se - sb)) with speeds in km/h."""
    v0, decel = 25.0, 6.0
    _t, speed, travelled = _constant_deceleration(v0, decel)
    vb_kmh, ve_kmh = 0.8 * v0 * 3.6, 0.1 * v0 * 3.6
    sb = (v0**2 - (0.8 * v0) ** 2) / (2 * decel)
    se = (v0**2 - (0.1 * v0) ** 2) / (2 * decel)
    assert mfdd_mps2(speed, travelled, v0) == pytest.approx(
        (vb_kmh**2 - ve_kmh**2) / (25.92 * (se - sb)), rel=1e-4
    )


def test_no_stop_and_no_mfdd_when_the_speed_never_falls():
    t = np.arange(0.0, 2.0, 0.01)
    speed = np.full_like(t, 10.0)
    assert stop_time_s(t, speed, 0.0) is None
    assert mfdd_mps2(speed, 10.0 * t, 10.0) is None


def test_the_path_length_of_a_circle_is_its_arc():
    angle = np.linspace(0.0, math.pi / 2, 2001)
    assert path_length_m(20.0 * np.sin(angle), 20.0 * (1 - np.cos(angle)))[-1] == pytest.approx(
        10.0 * math.pi, rel=1e-6
    )


def test_an_axle_is_locked_when_its_wheels_turn_far_slower_than_the_body():
    vx = np.array([20.0, 20.0, 20.0, 0.5])
    wheels = np.array([20.0, 2.5, 0.0, 0.0])
    assert locked(wheels, vx).tolist() == [False, False, True, False]


@pytest.mark.parametrize(
    ("order", "passes"),
    [
        (LockOrder("front", 0.6, 0.7), True),
        (LockOrder("both", 0.5, 0.5), True),
        (LockOrder("none", None, None), True),
        (LockOrder("rear", 0.7, 0.5), False),  # rear locked alone from 0.5 to 0.7
        (LockOrder("rear", None, 0.65), False),
        (LockOrder("rear", None, 0.83), True),  # above the band
        (LockOrder("rear", 0.12, 0.10), True),  # both below the band
    ],
)
def test_the_lock_order_criterion_of_r13h_annex_5(order, passes):
    assert order.passes(0.15, 0.8) is passes


def test_the_lock_order_and_the_braking_rates_from_a_hand_made_ramp():
    t = np.arange(0.0, 5.0, 0.01)
    ax = -0.2 * G_MPS2 * t
    rear = t >= 3.0  # rear locks at z = 0.6
    front = t >= 4.0
    order = lock_order(t, ax, front, rear)
    assert order.first == "rear"
    assert order.rate_rear == pytest.approx(0.598, abs=0.003)
    assert order.rate_front == pytest.approx(0.798, abs=0.003)


def test_a_crossing_is_interpolated():
    x = np.array([0.0, 1.0, 2.0, 3.0])
    y = np.array([0.0, 0.2, 0.4, 0.6])
    assert crossing_value(x, y, 0.3) == pytest.approx(1.5)
    assert crossing_value(x, y, 0.7) is None


def test_the_understeer_gradient_of_a_linear_car():
    """delta = L r / v + K ay: the gradient is K, whatever the speed does."""
    wheelbase, k_rad = 2.7, math.radians(2.0) / G_MPS2  # 2 deg/g
    ay = np.linspace(0.0, 0.6 * G_MPS2, 300)
    vx = np.linspace(22.0, 20.0, 300)
    r = ay / vx
    steer = wheelbase * r / vx + k_rad * ay
    assert understeer_gradient_deg_per_g(ay, steer, r, vx, wheelbase) == pytest.approx(2.0)
    assert understeer_gradient_deg_per_g(-ay, -steer, -r, vx, wheelbase) == pytest.approx(2.0)
    steady = steer_angle_gradient_deg_per_g(ay, wheelbase * ay / 22.0**2 + k_rad * ay)
    assert steady == pytest.approx(2.0 + math.degrees(wheelbase / 22.0**2) * G_MPS2)


def test_a_first_order_yaw_response_has_its_closed_form_response_time():
    """An ideal step at t0 (50 % of the input at t0) and r = r_ss (1 - exp(-(t - t0) / tau)):
    90 % after tau ln 10, no overshoot, the gain r_ss / input."""
    tau, t0, r_ss = 0.25, 1.0, 0.2
    t = np.arange(0.0, 6.0, DT)
    steer = np.where(t >= t0, 30.0, 0.0)
    yaw = np.where(t >= t0, r_ss * (1 - np.exp(-(t - t0) / tau)), 0.0)
    response = step_response(t, steer, yaw)
    assert response.response_time_s == pytest.approx(tau * math.log(10.0), abs=2 * DT)
    assert response.gain == pytest.approx(r_ss / 30.0, rel=1e-4)
    assert response.overshoot == pytest.approx(0.0, abs=1e-4)


def test_a_second_order_yaw_response_has_its_closed_form_overshoot_and_peak_time():
    zeta, omega_n, t0 = 0.5, 8.0, 0.5
    omega_d = omega_n * math.sqrt(1 - zeta * zeta)
    t = np.arange(0.0, 5.0, DT)
    s = np.maximum(t - t0, 0.0)
    phase = math.acos(zeta)
    yaw = 1 - np.exp(-zeta * omega_n * s) * np.sin(omega_d * s + phase) / math.sqrt(1 - zeta**2)
    response = step_response(t, np.where(t >= t0, 1.0, 0.0), yaw)
    assert response.overshoot == pytest.approx(
        math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2)), abs=1e-3
    )
    assert response.peak_response_time_s == pytest.approx(math.pi / omega_d, abs=2 * DT)


def test_the_sine_with_dwell_input():
    amp = 100.0
    quarter = SECOND_REVERSAL_S / 3
    assert sine_with_dwell_steer(0.0, amp) == 0.0
    assert sine_with_dwell_steer(quarter, amp) == pytest.approx(amp)
    assert sine_with_dwell_steer(SECOND_REVERSAL_S + 0.25, amp) == -amp
    assert sine_with_dwell_steer(SECOND_REVERSAL_S + 0.5 + 1e-9, amp) == pytest.approx(-amp)
    assert sine_with_dwell_steer(COMPLETION_S - 1e-9, amp) == pytest.approx(0.0, abs=1e-6)
    assert pytest.approx(1 / 0.7 + 0.5) == COMPLETION_S


def test_the_amplitude_series_goes_to_the_greater_of_6_5_a_and_270_deg():
    assert amplitudes_deg(20.0) == [30.0 + 10.0 * k for k in range(24)] + [270.0]
    assert amplitudes_deg(44.0)[-2:] == [264.0, 286.0]  # 6.5 A = 286 deg
    assert run_label(1.5) == "amp_1.5A"
    assert run_label(2.0) == "amp_2A"


def test_no_amplitude_of_the_series_is_above_300_deg():
    """FMVSS 126 S7.9.4: where 6.5 A is above 300 deg the last run is 300 deg."""
    big = amplitudes_deg(50.0)
    assert big == [75.0 + 25.0 * k for k in range(9)] + [300.0]
    assert max(amplitudes_deg(62.6)) == 300.0


@given(st.floats(min_value=5.0, max_value=120.0))
def test_the_series_has_one_run_per_amplitude_and_label(a_deg):
    """An amplitude a hair below the last (7 A of 38.563 deg = 269.94 deg) is that run: every
    run has its own amplitude and its own label."""
    series = amplitudes_deg(a_deg)
    assert all(b - a >= 1.0 - 1e-9 for a, b in itertools.pairwise(series))
    assert len({run_label(amp / a_deg) for amp in series}) == len(series)
    assert series[-1] in (270.0, 300.0) or series[-1] == pytest.approx(6.5 * a_deg)


def test_the_displacement_limit_follows_the_vehicles_mass():
    """FMVSS 126 S5.2.3: 1.83 m up to 3 500 kg gross, 1.52 m above."""
    assert displacement_min_m(1800.0) == 1.83
    assert displacement_min_m(3500.0) == 1.83
    assert displacement_min_m(3600.0) == 1.52


def test_the_yaw_rate_ratios_of_a_decaying_yaw_rate():
    """Peak -P at t_p after the second reversal, then r = -P exp(-(t - t_p) / tau)."""
    tau, peak, t_rev, t_peak, t_done = 0.8, 0.5, 1.0, 1.3, 1.9
    t = np.arange(0.0, 5.0, DT)
    rise = -peak * np.sin(0.5 * math.pi * np.clip((t - t_rev) / (t_peak - t_rev), 0.0, 1.0))
    yaw = np.where(t < t_peak, rise, -peak * np.exp(-(t - t_peak) / tau))
    ratios = yaw_rate_ratios(t, yaw, t_rev, t_done, -1.0)
    assert ratios.peak_radps == pytest.approx(-peak, rel=1e-6)
    assert ratios.peak_time_s == pytest.approx(t_peak, abs=DT)
    assert ratios.ratio_1s == pytest.approx(math.exp(-(t_done + 1.0 - t_peak) / tau), rel=1e-3)
    assert ratios.ratio_175s == pytest.approx(math.exp(-(t_done + 1.75 - t_peak) / tau), rel=1e-3)


def test_the_lateral_displacement_on_a_circle():
    """From the beginning of steer at (5, 0) heading +x, a left circle of radius R at speed v:
    after T the displacement is R (1 - cos(v T / R))."""
    radius, speed, begin = 40.0, 20.0, 0.5
    t = np.arange(0.0, 3.0, DT)
    arc = np.maximum(t - begin, 0.0) * speed / radius
    x = 5.0 + np.where(t < begin, (t - begin) * speed, radius * np.sin(arc))
    y = radius * (1 - np.cos(arc))
    displacement = lateral_displacement_m(t, x, y, arc, begin, 1.07)
    assert displacement == pytest.approx(radius * (1 - math.cos(speed * 1.07 / radius)), rel=1e-4)


# FMVSS 126 S5.2.1: the peak is "the first peak value of yaw rate recorded after the steering
# wheel angle changes sign (between first and second peaks)". A 0.7 Hz sine with dwell from
# the beginning of steer at BOS changes sign at BOS + T / 2; its dwell begins at BOS + 3 T / 4.
BOS_S = 1.0
SIGN_CHANGE_S = BOS_S + 0.5 * PERIOD_S
DWELL_S = BOS_S + SECOND_REVERSAL_S
END_S = BOS_S + COMPLETION_S


def _swd_steer_deg(t: np.ndarray, amplitude_deg: float) -> np.ndarray:
    return np.array([sine_with_dwell_steer(x - BOS_S, amplitude_deg) for x in t])


def _yaw_peaked_before_the_dwell(t: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Yaw rate [rad/s]: the first half-wave's +0.3, then negative, a true peak of -1.2 at
    1.96 s (on the 10 ms grid, before the dwell at 2.071 s), decaying, with a small late wiggle
    that peaks at -0.02 near ``DWELL_S + 0.6``; the peak and its time."""
    t_peak, peak = 1.96, 1.2
    first = 0.3 * np.sin(math.pi * np.clip((t - BOS_S) / (SIGN_CHANGE_S - BOS_S), 0.0, 1.0))
    rise = np.sin(0.5 * math.pi * np.clip((t - SIGN_CHANGE_S) / (t_peak - SIGN_CHANGE_S), 0, 1))
    decay = np.exp(-np.maximum(t - t_peak, 0.0) / 0.3)
    wiggle = 0.02 * np.exp(-(((t - DWELL_S - 0.6) / 0.1) ** 2))
    second = np.where(t < t_peak, -peak * rise, -peak * decay - wiggle)
    return np.where(t < SIGN_CHANGE_S, first, second), -peak, t_peak


def test_the_steering_changes_sign_half_a_period_after_the_beginning_of_steer():
    t = np.arange(0.0, 5.0, 0.01)
    assert steer_sign_change_s(t, _swd_steer_deg(t, 100.0)) == pytest.approx(
        SIGN_CHANGE_S, abs=1e-4
    )
    # the dwell holds the full amplitude, the first peak a hair less: still the first half-wave
    steer = _swd_steer_deg(t, 100.0)
    steer[steer > 0.0] *= 0.99
    assert steer_sign_change_s(t, steer) == pytest.approx(SIGN_CHANGE_S, abs=1e-4)


def test_a_yaw_rate_peak_before_the_dwell_is_the_first_peak_after_the_sign_change():
    """The yaw rate peaks before the dwell begins and decays; the peak is the true one, not a
    late wiggle (the search from the dwell's start took -0.02 rad/s and ratios above 1)."""
    t = np.round(np.arange(0.0, 6.0, 0.01), 6)
    yaw, peak, t_peak = _yaw_peaked_before_the_dwell(t)
    assert t_peak < DWELL_S
    ratios = yaw_rate_ratios(t, yaw, SIGN_CHANGE_S, END_S, -1.0)
    assert ratios.peak_radps == pytest.approx(peak)
    assert ratios.peak_time_s == pytest.approx(t_peak, abs=0.005)
    expected_1s = float(np.interp(END_S + 1.0, t, yaw)) / peak
    assert ratios.ratio_1s == pytest.approx(expected_1s, rel=1e-9)
    assert ratios.ratio_1s < 0.35


def test_the_windows_first_sample_can_be_the_peak():
    """A yaw rate whose peak (-1.2 rad/s) is the first sample at or after the sign change, the
    next ones decaying: that sample is the peak, not a later local one (-0.05 rad/s)."""
    t = np.round(np.arange(0.0, 6.0, 0.01), 6)
    k0 = int(np.flatnonzero(t >= SIGN_CHANGE_S)[0])
    decay = -1.2 * np.exp(-np.maximum(t - t[k0], 0.0) / 0.3)
    later = -0.05 * np.exp(-(((t - 3.5) / 0.1) ** 2))
    yaw = np.where(t < t[k0], 0.2, decay + later)
    ratios = yaw_rate_ratios(t, yaw, SIGN_CHANGE_S, END_S, -1.0)
    assert ratios.peak_radps == pytest.approx(-1.2)
    assert ratios.peak_time_s == pytest.approx(t[k0])


def test_the_judged_run_searches_the_peak_from_the_steerings_sign_change():
    """``sine_with_dwell._judge`` on a hand-made run whose yaw rate peaks before the dwell:
    the figures' peak is the true first peak after the sign change, and the run passes."""
    from eoam_sumo.vehicle_tests.sine_with_dwell import _judge

    t = np.round(np.arange(0.0, END_S + 2.0, 0.01), 6)
    yaw, peak, t_peak = _yaw_peaked_before_the_dwell(t)
    straight = np.zeros_like(t)
    columns = {
        "time_s": t,
        "steer_wheel_deg": _swd_steer_deg(t, 100.0),
        "yaw_rate_radps": yaw,
        "x_m": 22.0 * t,
        "y_m": straight,
        "yaw_rad": straight,
    }
    figures, judged = _judge(Run("amp_5A", columns), 100.0, 20.0, 1500.0)
    assert figures["peak_yaw_rate_degps"] == pytest.approx(math.degrees(peak), abs=1e-3)
    assert figures["peak_yaw_rate_time_s"] == pytest.approx(t_peak, abs=0.005)
    assert figures["steer_sign_change_s"] == pytest.approx(SIGN_CHANGE_S, abs=1e-4)
    ratios = {c["name"]: c["passed"] for c in judged}
    assert ratios["amp_5A.yaw_ratio_1s"] and ratios["amp_5A.yaw_ratio_1.75s"]
