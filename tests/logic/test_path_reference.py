"""Manoeuvre reference sampled from a table trajectory: scaling and the planned speed."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.manoeuvre import PathReference, QuinticShift, TrajectoryPoint

H_TABLE = 3.5  # lane change of the tables [m]
LENGTH = 60.0  # [m]
AX = -3.0  # constant deceleration of the synthetic profile [m/s^2]


class QuinticTrajectory:
    """Closed-form trajectory in the tables' format: (y, ax, yaw, curvature, steer) at dx."""

    length_m = LENGTH

    def at(self, dx):
        u = min(max(dx / LENGTH, 0.0), 1.0)
        y = H_TABLE * (10 * u**3 - 15 * u**4 + 6 * u**5)
        dy = H_TABLE * (30 * u**2 - 60 * u**3 + 30 * u**4) / LENGTH
        ddy = H_TABLE * (60 * u - 180 * u**2 + 120 * u**3) / LENGTH**2
        return TrajectoryPoint(y, AX, math.atan(dy), ddy / (1 + dy * dy) ** 1.5, 0.0)


@pytest.mark.parametrize(("start", "height"), [(0.0, 3.5), (0.1, 3.0), (3.4, -3.4)])
def test_scaled_path_and_planned_speed(start, height):
    ref = PathReference(
        QuinticTrajectory(), start_offset_m=start, height_m=height, speed_mps=25.0, step_m=0.25
    )
    k = height / H_TABLE
    assert ref.length_m == LENGTH and ref.start_offset_m == start
    for dx in (0.0, 7.3, 30.0, 44.4, 59.9):
        y, yaw, curv, ax, v, steer, beta = ref.at(dx)
        y_t, _, yaw_t, curv_t, _, _ = QuinticTrajectory().at(dx)
        assert steer == beta == 0.0 and not ref.planned_steering  # none in the trajectory
        assert y == pytest.approx(start + k * y_t, abs=2e-4)
        assert yaw == pytest.approx(k * yaw_t, abs=1e-5)
        assert curv == pytest.approx(k * curv_t, abs=1e-5)
        assert ax == AX
        # v^2 = v0^2 + 2 a dx for a constant acceleration (exact at the samples, linear between)
        assert v == pytest.approx(math.sqrt(25.0**2 + 2 * AX * dx), rel=1e-6)
    # held at both ends
    assert ref.at(-5.0)[0] == pytest.approx(start)
    assert ref.at(LENGTH + 50.0)[0] == pytest.approx(start + height, abs=1e-12)
    assert ref.at(LENGTH + 50.0)[4] == pytest.approx(math.sqrt(25.0**2 + 2 * AX * LENGTH))


class PlannedTrajectory(QuinticTrajectory):
    """The same with planned steering and sideslip, as the lookup tables give them."""

    def at(self, dx):
        p = super().at(dx)
        return p._replace(steer_rad=0.5 * p.curvature_1pm, sideslip_rad=-0.2 * p.yaw_rad)


def test_planned_steering_and_sideslip_scale_with_the_path():
    ref = PathReference(
        PlannedTrajectory(), start_offset_m=0.2, height_m=3.0, speed_mps=25.0, step_m=0.25
    )
    k = 3.0 / H_TABLE
    assert ref.planned_steering
    for dx in (0.0, 12.5, 33.3):
        _, yaw, _, _, _, steer, beta = ref.at(dx)
        assert beta == pytest.approx(-0.2 * yaw, abs=1e-6)
        assert steer == pytest.approx(k * PlannedTrajectory().at(dx).steer_rad, abs=1e-6)
    assert ref.at(LENGTH + 5.0)[5:] == pytest.approx((0.0, 0.0), abs=1e-9)


@pytest.mark.parametrize("dx", [0.0, 6.0, 12.5, 30.0, 47.1, LENGTH])
def test_planned_curvature_is_the_body_yaw_per_metre(dx):
    """With a planned sideslip beta (course less body yaw), the reference's curvature is the
    body's yaw per metre, d(theta - beta)/dx: here beta = -0.2 theta, so 1.2 theta'(x), with
    theta = atan(y') and theta' = y'' / (1 + y'^2). The steering law's yaw-rate reference
    v kappa is then the plan's body yaw rate."""
    ref = PathReference(
        PlannedTrajectory(), start_offset_m=0.2, height_m=3.0, speed_mps=25.0, step_m=0.25
    )
    u = dx / LENGTH
    dy = H_TABLE * (30 * u**2 - 60 * u**3 + 30 * u**4) / LENGTH
    ddy = H_TABLE * (60 * u - 180 * u**2 + 120 * u**3) / LENGTH**2
    body = 3.0 / H_TABLE * 1.2 * ddy / (1.0 + dy * dy)
    assert ref.at(dx).curvature_1pm == pytest.approx(body, abs=5e-5)


def test_speed_profile_stops_at_zero():
    ref = PathReference(
        QuinticTrajectory(), start_offset_m=0.0, height_m=3.5, speed_mps=10.0, step_m=0.5
    )
    # 10^2 / (2 * 3) = 16.7 m to standstill: the planned speed stays 0 afterwards
    assert ref.at(16.0)[4] > 0.0 and ref.at(20.0)[4] == 0.0


def test_rejects_unusable_trajectories():
    class Flat(QuinticTrajectory):
        def at(self, dx):
            return TrajectoryPoint(0.0, 0.0, 0.0, 0.0, 0.0)

    with pytest.raises(ValueError, match="lateral travel"):
        PathReference(Flat(), start_offset_m=0.0, height_m=3.5, speed_mps=20.0, step_m=0.5)
    with pytest.raises(ValueError, match="step_m"):
        PathReference(
            QuinticTrajectory(), start_offset_m=0.0, height_m=3.5, speed_mps=20.0, step_m=0.0
        )


@pytest.mark.parametrize(("height", "speed", "accel"), [(3.5, 33.3, 2.94), (-2.0, 15.0, 0.9)])
def test_quintic_shift_from_rest_is_the_papers_lane_change(height, speed, accel):
    """slope0 = 0: the textbook quintic, peak 5.77 h v^2 / X^2 at the asked value: its
    length found by root-finding (to 1 um), not on the scan's 2 % grid."""
    traj = QuinticShift.for_lateral_accel(0.5, 0.0, 0.5 + height, speed, accel, min_length_m=1.0)
    ref = PathReference(traj, start_offset_m=0.0, height_m=None, speed_mps=speed, step_m=0.1)
    n = 400
    peak = max(abs(ref.at(traj.length_m * i / n)[2]) for i in range(n + 1)) * speed**2
    assert accel * 0.99 <= peak <= accel * (1.0 + 1e-9)  # the reference samples every 0.1 m
    closed_form = speed * math.sqrt(10.0 * math.sqrt(3.0) / 3.0 * abs(height) / accel)
    assert traj.length_m == pytest.approx(closed_form, abs=2e-6)
    assert ref.at(traj.length_m)[0] == pytest.approx(0.5 + height, abs=1e-12)
    assert ref.at(traj.length_m / 2)[0] == pytest.approx(0.5 + height / 2, abs=1e-12)
    assert ref.start_offset_m == 0.5
    assert ref.at(traj.length_m)[4] == speed  # constant speed
    # never shorter than asked
    assert QuinticShift.for_lateral_accel(0.0, 0.0, 0.01, 5.0, 9.0, 12.0).length_m == 12.0


def _fine(traj, n=4000):
    """(y, slope, y'') of a shift on a fine grid of its length, from its ``at``."""
    out = []
    for k in range(n + 1):
        pt = traj.at(traj.length_m * k / n)
        slope = math.tan(pt.yaw_rad)
        out.append((pt.y_m, slope, pt.curvature_1pm * (1.0 + slope * slope) ** 1.5))
    return out


def _past_target(traj, y0, y1, n=4000):
    side = 1.0 if y1 >= y0 else -1.0
    return max(side * (y - y1) for y, _, _ in _fine(traj, n))


@given(
    y0=st.floats(-4.0, 4.0),
    slope0=st.floats(-0.15, 0.15),
    kappa0=st.floats(-0.01, 0.01),
    y1=st.floats(-4.0, 4.0),
    speed=st.floats(5.0, 45.0),
    accel=st.floats(0.5, 9.0),
)
@settings(max_examples=80, deadline=None)
def test_quintic_shift_starts_from_the_state_and_never_passes_its_target(
    y0, slope0, kappa0, y1, speed, accel
):
    """Starts at the ego's (offset, course slope, path curvature), ends at y1 level and
    straight, and never passes y1 (no overshoot beyond the planned offset), whatever the
    start; from rest its peak lateral acceleration is within the asked value."""
    traj = QuinticShift.for_lateral_accel(y0, slope0, y1, speed, accel, 5.0, kappa0)
    y, _, yaw, kappa, *_ = traj.at(0.0)
    assert y == pytest.approx(y0, abs=1e-9)
    assert math.tan(yaw) == pytest.approx(slope0, abs=1e-9)
    assert kappa * (1.0 + slope0 * slope0) ** 1.5 == pytest.approx(kappa0, abs=1e-9)
    y, _, yaw, kappa, *_ = traj.at(traj.length_m)
    assert y == pytest.approx(y1, abs=1e-9)
    assert yaw == pytest.approx(0.0, abs=1e-9) and kappa == pytest.approx(0.0, abs=1e-9)
    if abs(y1 - y0) > 0.05:  # (at the target already, any excursion would count)
        assert _past_target(traj, y0, y1) <= 2e-3
    if slope0 == 0.0 and kappa0 == 0.0:
        peak = max(abs(k) for _, _, k in _fine(traj)) * speed**2
        assert peak <= accel * 1.01


@given(
    slope0=st.floats(-0.15, 0.15),
    kappa0=st.floats(-0.01, 0.01),
    dy=st.floats(0.2, 4.0),
    speed=st.floats(10.0, 45.0),
    accel=st.floats(0.5, 9.0),
)
@settings(max_examples=60, deadline=None)
def test_quintic_shift_is_the_shortest_within_the_budget(slope0, kappa0, dy, speed, accel):
    """Time-optimal within the budget (for a quintic): the shift keeps to the budget, or no
    other length (half to twice) keeps to it without passing the target either."""
    traj = QuinticShift.for_lateral_accel(0.0, slope0, dy, speed, accel, 5.0, kappa0)
    if traj.within(speed, accel * 1.001):
        for f in (0.8, 0.9):  # 2 % grid: a markedly shorter length breaks a constraint
            other = QuinticShift(0.0, slope0, dy, traj.length_m * f, kappa0)
            if other.length_m >= 5.0:
                assert not other.within(speed, accel * 0.999)
        return
    for f in (0.5, 0.7, 1.3, 2.0):  # (not below the shortest length allowed)
        other = QuinticShift(0.0, slope0, dy, max(traj.length_m * f, 5.0), kappa0)
        assert not other.within(speed, accel * 0.95)


@given(
    y0=st.floats(-1.0, 4.0),
    slope0=st.floats(-0.12, 0.12),
    kappa0=st.floats(-0.005, 0.005),
    speed=st.floats(10.0, 45.0),
    mu=st.sampled_from([1.0, 0.7, 0.3, 0.1]),
    reaction=st.sampled_from([0.0, 0.3]),
)
@settings(max_examples=60, deadline=None)
def test_lateral_stop_is_no_shorter_than_physics_allows_and_does_not_pass_its_end(
    y0, slope0, kappa0, speed, mu, reaction
):
    """The arrest path ends where the lateral motion stops: at least the constant-deceleration
    stop v_lat^2 / (2 a) ahead of the motion (nothing stops sooner within the budget), not
    passing that end, level and straight there."""
    accel = 0.9 * mu * 9.81
    traj = QuinticShift.stopping(y0, slope0, speed, accel, 5.0, kappa0, reaction)
    v_lat = slope0 * speed
    travel = traj.y1_m - y0
    assert abs(travel) >= v_lat * v_lat / (2.0 * accel) * 0.999
    heading = v_lat + kappa0 * speed * speed * max(reaction, 0.1)  # lateral speed after the lag
    if abs(heading) > 0.3 and v_lat * heading > 0.0:
        assert math.copysign(1.0, travel) == math.copysign(1.0, v_lat)
    assert _past_target(traj, y0, traj.y1_m) <= 2e-3
    pt = traj.at(traj.length_m)
    assert pt.yaw_rad == pytest.approx(0.0, abs=1e-9)
