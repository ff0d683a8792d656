"""Steering law (eq. 38): feedforward against the steady-state bicycle, state feedback whose
closed-loop poles are those designed, stability with the steering lag, the slip envelope."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from eoam_sumo.control import SteeringController, SteeringGains, understeer_gradient
from eoam_sumo.control.steering import _GAIN_TABLES, place_poles, single_track_matrices
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()


def steady_state(v, radius):
    """Road-wheel angle and body sideslip of the linear single-track model in steady
    cornering (force and moment balance)."""
    m, a, b = P.mass_kg, P.cg_to_front_m, P.cg_to_rear_m
    cf, cr = P.cornering_stiffness_front_npr, P.cornering_stiffness_rear_npr
    r = v / radius
    fyf = m * v * r * b / (a + b)  # moment balance a*Fyf = b*Fyr, sum = m v r
    fyr = m * v * r * a / (a + b)
    vy = b * r - v * fyr / cr  # rear slip angle alpha_r = -(vy - b r)/v = fyr / cr
    return fyf / cf + (vy + a * r) / v, vy / v  # alpha_f = delta - (vy + a r)/v


def linear_model(v, stiffness_scale=1.0):
    """Independent linear single-track model, states (e, psi, vy, r), input delta."""
    m, iz, a, b = P.mass_kg, P.yaw_inertia_kgm2, P.cg_to_front_m, P.cg_to_rear_m
    cf = P.cornering_stiffness_front_npr * stiffness_scale
    cr = P.cornering_stiffness_rear_npr * stiffness_scale
    A = np.zeros((4, 4))
    A[0, 1], A[0, 2], A[1, 3] = v, 1.0, 1.0
    A[2, 2], A[2, 3] = -(cf + cr) / (m * v), -v - (a * cf - b * cr) / (m * v)
    A[3, 2], A[3, 3] = -(a * cf - b * cr) / (iz * v), -(a * a * cf + b * b * cr) / (iz * v)
    B = np.array([0.0, 0.0, cf / m, a * cf / iz])
    return A, B


def feedback_row(ctrl, v, mu):
    """The controller's feedback as a row on (e, psi, vy, r), read off ``command`` itself."""
    base = ctrl.command(v, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, mu).steer_rad
    unit = (1e-4, 1e-5, 1e-4, 1e-5)
    row = []
    for i, h in enumerate(unit):
        e, psi, vy, r = (h if j == i else 0.0 for j in range(4))
        row.append((ctrl.command(v, r, vy, e, psi, 0.0, 0.0, mu).steer_rad - base) / h)
    return np.array(row)


@pytest.mark.parametrize("v", [5.0, 15.0, 33.3, 45.8])
@pytest.mark.parametrize("radius", [50.0, 200.0, -400.0])
def test_feedforward_is_the_steady_state_steer_and_no_feedback_in_steady_cornering(v, radius):
    ctrl = SteeringController(P)
    delta_ss, beta = steady_state(v, radius)
    # cornering on the path: yaw rate v / R, lateral speed v beta, body heading -beta off course
    cmd = ctrl.command(v, v / radius, v * beta, 0.0, -beta, 1.0 / radius, 1.0 / radius, 1.0)
    assert cmd.feedforward_rad == pytest.approx(delta_ss, rel=1e-9)
    assert cmd.feedback_rad == pytest.approx(0.0, abs=1e-12)
    assert cmd.body_feedback_rad == pytest.approx(0.0, abs=1e-12)
    assert ctrl.steady_sideslip(v, 1.0 / radius) == pytest.approx(beta, rel=1e-9)


def test_feedforward_uses_the_preview_curvature():
    ctrl = SteeringController(P)
    v, k_now, k_ahead = 30.0, 0.002, 0.005
    cmd = ctrl.command(v, v * k_now, 0.0, 0.0, 0.0, k_now, k_ahead, 1.0)
    assert cmd.feedforward_rad == pytest.approx(steady_state(v, 1.0 / k_ahead)[0], rel=1e-9)
    # and the steady lateral acceleration of the feedforward angle is v^2 kappa
    assert ctrl.lateral_accel(v, cmd.feedforward_rad) == pytest.approx(v * v * k_ahead, rel=1e-9)


@pytest.mark.parametrize("v", [15.0, 33.3, 45.8])
def test_yaw_rate_reference_is_the_body_yaw_rate_on_a_curvature_ramp(v):
    """Entering a curve, kappa 0 -> 0.004 1/m over the 0.3 s preview: the body of a car on the
    reference yaws at v kappa less the rate of its steady sideslip (``steady_sideslip``, its
    own test above), and the yaw-rate feedback does not act on that yaw rate; without the
    preview time (the sideslip's rate left out) it would steer against it."""
    preview_s, k_now, k_ahead = 0.3, 0.0, 0.004
    beta_now = 0.0  # straight now
    beta_ahead = steady_state(v, 1.0 / k_ahead)[1]
    r_body = v * k_now - (beta_ahead - beta_now) / preview_s
    args = (v, r_body, v * beta_now, 0.0, -beta_now, k_now, k_ahead, 1.0)
    ctrl = SteeringController(P, preview_time_s=preview_s)
    assert ctrl.command(*args).body_feedback_rad == pytest.approx(0.0, abs=1e-12)
    assert abs(SteeringController(P).command(*args).body_feedback_rad) > 1e-4


def test_understeer_gradient_sign_and_value():
    # b / Cf > a / Cr for this car: mildly understeering, about 0.04 deg/(m/s^2)
    k = understeer_gradient(P)
    assert 0.0 < math.degrees(k) < 0.2


def test_feedback_opposes_the_errors():
    ctrl = SteeringController(P)
    cmd = ctrl.command(30.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0)
    assert cmd.lookahead_error_m == pytest.approx(0.5) and cmd.feedback_rad < 0.0  # steer right
    cmd = ctrl.command(30.0, 0.0, 0.0, 0.0, 0.02, 0.0, 0.0, 1.0)
    assert cmd.lookahead_error_m > 0.0 and cmd.feedback_rad < 0.0  # heading left of the path
    assert ctrl.command(30.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0).body_feedback_rad < 0.0


def test_clipped_to_the_front_slip_envelope_and_the_lock():
    ctrl = SteeringController(P)
    g = SteeringGains()
    fz = P.mass_kg * 9.81 * P.cg_to_rear_m / P.wheelbase_m
    envelope = g.front_slip_fraction * 3.0 * fz / P.cornering_stiffness_front_npr
    for mu in (1.0, 0.3):
        delta = ctrl.command(30.0, 0.0, 0.0, -50.0, 0.0, 0.0, 0.0, mu).steer_rad
        assert delta == pytest.approx(envelope * mu, rel=1e-12)  # front slip = delta here
    assert ctrl.command(0.5, 0.0, 0.0, -50.0, 0.0, 0.0, 0.0, 1.0).steer_rad == P.max_steer_rad
    assert ctrl.command(0.5, 0.0, 0.0, 50.0, 0.0, 0.0, 0.0, 1.0).steer_rad == -P.max_steer_rad


def _motion(lateral_speed_mps: float):
    """(speed, lateral speed, yaw rate, mu) of a body in motion."""
    return st.tuples(
        st.floats(5.0, 50.0),
        st.floats(-lateral_speed_mps, lateral_speed_mps),
        st.floats(-0.5, 0.5),
        st.floats(0.1, 1.2),
    )


def _peak_slip_per_mu() -> float:
    """The Fiala front tyre's peak slip per unit of mu, 3 Fz_f / C_f."""
    fz = P.mass_kg * 9.81 * P.cg_to_rear_m / P.wheelbase_m
    return 3.0 * fz / P.cornering_stiffness_front_npr


@settings(max_examples=50, deadline=None)
@given(_motion(2.0), st.sampled_from((1.0, -1.0)))
def test_envelope_edge_is_the_front_slip_limit_the_law_clips_to(motion, side):
    """The edge's front slip (delta less the front axle's course) is the envelope's, on the
    side asked for, and the law's largest error towards that side lands on it."""
    v, vy, r, mu = motion
    ctrl = SteeringController(P)
    envelope = SteeringGains().front_slip_fraction * _peak_slip_per_mu()
    edge = ctrl.envelope_edge(v, r, vy, mu, side)
    course_f = (vy + P.cg_to_front_m * r) / v
    assume(abs(course_f) + envelope * mu < P.max_steer_rad)
    assert edge - course_f == pytest.approx(side * envelope * mu, rel=1e-9)
    clipped = ctrl.command(v, r, vy, -side * 50.0, 0.0, 0.0, 0.0, mu).steer_rad
    assert clipped == pytest.approx(edge, rel=1e-9, abs=1e-12)


@settings(max_examples=50, deadline=None)
@given(_motion(4.0), st.floats(0.05, 0.95))
def test_share_edges_give_the_fiala_force_share_about_the_body_motion(motion, share):
    """At either edge the front slip about the front axle's course is the one at which a
    Fiala tyre gives ``share`` of its peak force, 1 - (1 - alpha / alpha_peak)^3, with
    alpha_peak = 3 mu Fz / C_f; at 7/8 of the peak it is the envelope's edge."""
    v, vy, r, mu = motion
    ctrl = SteeringController(P)
    alpha_peak = mu * _peak_slip_per_mu()
    course_f = (vy + P.cg_to_front_m * r) / v
    assume(abs(course_f) + alpha_peak < P.max_steer_rad)
    right, left = ctrl.share_edges(v, r, vy, mu, share)
    for edge, side in ((right, -1.0), (left, 1.0)):
        x = side * (edge - course_f) / alpha_peak
        assert 1.0 - (1.0 - x) ** 3 == pytest.approx(min(share, 0.875), rel=1e-9)
    full = ctrl.share_edges(v, r, vy, mu, 0.875)
    envelope = (ctrl.envelope_edge(v, r, vy, mu, -1.0), ctrl.envelope_edge(v, r, vy, mu, 1.0))
    assert full == pytest.approx(envelope, rel=1e-9, abs=1e-12)


GAINS = {"default": SteeringGains(), "planned": EoamSettings().planned_steering}


@pytest.mark.parametrize("gains", sorted(GAINS))
@pytest.mark.parametrize("v", [4.0, 10.0, 15.5, 25.0, 33.3, 46.0])
@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
def test_closed_loop_poles_are_the_designed_ones(v, mu, gains):
    """A - B K of an independently built linear model has the designed poles: the path pair
    at s^2 + 2 zeta omega s + omega^2 and the body pair with at least its damping (the
    default gains and the table lane change's)."""
    g = GAINS[gains]
    ctrl = SteeringController(P, g)
    A, B = linear_model(v)
    closed = A + np.outer(B, feedback_row(ctrl, v, mu))
    want = ctrl.design_poles(v, mu)
    # characteristic polynomials (repeated roots split under rounding); gains are blended
    # linearly between the 0.5 m/s grid speeds, exact on them
    on_grid = abs(2.0 * v - round(2.0 * v)) < 1e-9
    assert np.poly(closed).real == pytest.approx(np.poly(want).real, rel=1e-4 if on_grid else 3e-2)
    omega = g.natural_freq_radps * mu**g.friction_exponent
    omega *= min(1.0, v / g.full_bandwidth_speed_mps)
    assert ctrl.natural_freq(v, mu) == pytest.approx(omega, rel=1e-12)
    assert np.poly(want[:2]).real == pytest.approx(  # the path pair comes first
        [1.0, 2.0 * g.damping_ratio * omega, omega**2], rel=1e-6
    )
    damping = -want.real / abs(want)
    assert damping.min() >= min(g.damping_ratio, g.body_damping_ratio) - 1e-9


@pytest.mark.parametrize("gains", sorted(GAINS))
@pytest.mark.parametrize("v", [4.0, 10.0, 15.3, 25.0, 33.3, 45.8])
@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
@pytest.mark.parametrize("stiffness_with_mu", [False, True])
def test_closed_loop_with_the_steering_lag_is_stable_and_damped(v, mu, stiffness_with_mu, gains):
    """With the actuator's first-order lag every pole stays in the left half-plane with
    damping above 0.4; with tyres whose cornering stiffness falls with the friction (a
    robustness check: the plant's does not) the loop stays stable."""
    ctrl = SteeringController(P, GAINS[gains])
    A, B = linear_model(v, mu if stiffness_with_mu else 1.0)
    k = feedback_row(ctrl, v, mu)
    lag = P.steer_lag_s
    full = np.zeros((5, 5))
    full[:4, :4], full[:4, 4] = A, B
    full[4, :4], full[4, 4] = k / lag, -1.0 / lag
    poles = np.linalg.eigvals(full)
    if stiffness_with_mu:
        assert poles.real.max() < -0.05
    else:
        assert poles.real.max() < -0.2
        assert (-poles.real / abs(poles)).min() > 0.4


def test_gains_validate():
    with pytest.raises(ValueError, match="natural_freq"):
        SteeringGains(natural_freq_radps=0.0)
    with pytest.raises(ValueError, match="body_damping"):
        SteeringGains(body_damping_ratio=math.nan)


def test_gain_rows_are_placed_when_first_needed_and_blend_the_placed_ones():
    """A friction seen for the first time (an estimate) places the two rows around the speed
    only, and the gains are those rows' linear blend (the same as a whole table's)."""
    ctrl = SteeringController(P)
    mu, v = 0.4321, 20.2
    k = ctrl.gains_at(v, mu)
    rows = _GAIN_TABLES[(P, SteeringGains(), mu)]
    placed = [i for i, row in enumerate(rows) if row is not None]
    assert len(placed) == 2
    v0, v1 = (ctrl._speeds[i] for i in placed)
    assert v0 <= v < v1
    ends = []
    for vi in (v0, v1):
        A, B = single_track_matrices(P, vi)
        ends.append(place_poles(A, B, ctrl.design_poles(vi, mu)))
    w = (v - v0) / (v1 - v0)
    assert k == pytest.approx(tuple(ends[0] + w * (ends[1] - ends[0])), rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(mu=st.floats(0.05, 1.2), v=st.floats(0.0, 90.0))
def test_a_row_placed_from_the_kept_speed_part_is_the_pole_placement_bit_for_bit(mu, v):
    """A gain-table row placed after another friction left its speed's friction-free part
    (A's powers, the controllability matrix, the body poles) in the cache is exactly
    ``place_poles(A, B, design_poles(v, mu))`` at its grid speed."""
    ctrl = SteeringController(P)
    ctrl.gains_at(v, 0.5123)  # the rows around v placed once, at another friction
    ctrl.gains_at(v, mu)
    rows = _GAIN_TABLES[(P, SteeringGains(), mu)]
    placed = [i for i, row in enumerate(rows) if row is not None]
    assert placed
    for i in placed:
        vi = ctrl._speeds[i]
        A, B = single_track_matrices(P, vi)
        assert rows[i] == tuple(float(k) for k in place_poles(A, B, ctrl.design_poles(vi, mu)))
