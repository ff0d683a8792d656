"""Track persistence of the ideal radar: an in-path road user lost from view at close range
is reported as a coasted (predicted) object until it is predicted out of the path or behind
the ego, seen again, or missing where it was predicted to be."""

from __future__ import annotations

import math

import pytest

from eoam_sumo.sensing.radar import Radar, RadarSettings
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body

LANE_M = 3.5
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])  # ego lane centre line, eastbound
WALKER = (0.30, 0.55)  # a person's footprint [m]
WALKER_D_M = -1.13  # off the lane centre towards the right marker (SUMO's walker here)
WALK_MPS = 1.4
HALF_FOV = math.radians(9.0)


def walker_at(
    t_s: float, x0_m: float = 60.0, d_m: float = WALKER_D_M, speed_mps: float = WALK_MPS
) -> Body:
    """A person walking along the lane (eastbound), centre at x0 + speed t."""
    return Body("walker", "pedestrian", x0_m + speed_mps * t_s, d_m, 0.0, speed_mps, *WALKER)


def true_range_m(front_x_m: float, body: Body) -> float:
    """Distance from the radar at (front_x, 0) to the nearest point of a body whose centre is
    ahead of it and whose near side is right of the boresight (closed form, straight road)."""
    rear = body.x_m - 0.5 * body.length_m
    near_side = body.y_m + 0.5 * body.width_m
    return math.hypot(max(rear - front_x_m, 0.0), near_side)


def drive(radar: Radar, ego_mps: float, t_end_s: float, walker=walker_at, dt_s: float = 0.01):
    """Scan every ``dt_s`` with the ego's front at x = ego t (yaw 0); yields (t, front x,
    walker body or None, report)."""
    n = round(t_end_s / dt_s)
    for k in range(n + 1):
        t = k * dt_s
        front = ego_mps * t
        body = walker(t)
        targets = [] if body is None else [body]
        yield t, front, body, radar.scan((front, 0.0), 0.0, ego_mps, ROAD, targets, LANE_M, t)


def test_a_person_off_centre_leaves_the_beam_and_is_coasted_until_the_ego_reaches_it():
    """Closing at 8.6 m/s on a person 1.13 m right of the lane centre: the 18 deg beam loses
    them about 5.2 m ahead (the beam's half-width at their far face equals their near side's
    offset, 0.855 m); from then on the coasted object follows them exactly (constant
    velocity) until their centre is behind the radar."""
    radar = Radar()
    lost_at = None
    coasted_until = None
    for t, front, body, report in drive(radar, 10.0, 9.0):
        truth = true_range_m(front, body)
        if report.in_path is not None:
            assert report.coasted is None
            assert report.in_path_range_m >= truth - 1e-9  # the part in the beam
            continue
        if body.x_m <= front:  # centre behind the radar: no longer in the path ahead
            assert report.coasted is None
            continue
        if lost_at is None:
            lost_at = truth
        det = report.coasted
        assert det is not None, f"not coasted at t={t}"
        coasted_until = t
        assert det.category == "in_path"
        assert det.range_m == pytest.approx(truth, abs=1e-9)
        assert det.range_rate_mps <= 0.0  # closing (0 once beside the radar)
        assert det.road_speed_mps == pytest.approx(WALK_MPS)
    # the last part in the beam is the far corner of the near side: lost when the person's
    # far face is 0.855 / tan(9 deg) = 5.40 m ahead (closing 0.086 m per scan)
    far_face_m = 0.855 / math.tan(HALF_FOV)
    assert lost_at == pytest.approx(math.hypot(far_face_m - WALKER[0], 0.855), abs=0.1)
    assert coasted_until is not None


def test_lost_at_the_far_edge_of_the_range_is_not_coasted():
    """A car pulling away on the lane centre leaves through the far edge: no prediction."""
    radar = Radar()

    def car(t):  # rear 97 m ahead of the ego's front, opening at 5 m/s
        return Body("car", "passenger", 97.0 + 2.55 + 25.0 * t, 0.0, 0.0, 25.0, 5.1, 2.0)

    reports = [r for *_, r in drive(radar, 20.0, 1.0, walker=car)]
    assert reports[0].in_path is not None and reports[-1].in_path is None
    assert all(r.coasted is None for r in reports)


def test_a_road_user_leaving_the_path_while_seen_is_not_coasted():
    """A car still detected, but no longer in the lane band, is not an in-path object."""
    radar = Radar()

    def car(t):
        return Body("car", "passenger", 40.0, 2.5 * min(t, 1.0), 0.0, 0.0, 4.6, 1.8)

    reports = [r for *_, r in drive(radar, 0.0, 1.0, walker=car, dt_s=0.05)]
    assert reports[0].in_path is not None and reports[-1].in_path is None
    assert reports[-1].detections and all(r.coasted is None for r in reports)


def braking_phases(person) -> list[tuple[bool, bool]]:
    """(in path measured, coasted) as it changes while the ego brakes from 10 m/s to a stop
    with its front at x = 5 m (t = 1 s) behind ``person(t)`` (a body or None)."""
    radar = Radar()
    states = []
    for k in range(500):
        t = 0.01 * k
        front = 5.0 if t >= 1.0 else 10.0 * t - 5.0 * t * t
        body = person(t)
        rep = radar.scan(
            (front, 0.0),
            0.0,
            max(10.0 - 10.0 * t, 0.0),
            ROAD,
            [] if body is None else [body],
            LANE_M,
            t,
        )
        states.append((rep.in_path is not None, rep.coasted is not None))
    return [s for i, s in enumerate(states) if i == 0 or s != states[i - 1]]


def test_seen_again_ends_the_coasting_and_the_measurement_takes_over():
    """The person (rear 7.85 m ahead at the start) is lost when the ego comes within 5.4 m,
    coasted while the ego stops, and measured in path again once they have walked more than
    5.4 m ahead of its front (t = 1.8 s)."""
    phases = braking_phases(lambda t: walker_at(t, x0_m=8.0))
    assert phases == [(True, False), (False, True), (True, False)]


def test_a_prediction_in_the_beam_with_nothing_seen_there_ends_the_coasting():
    """The same, but the person vanishes at 0.6 s (as SUMO removes a person at their
    arrival): the prediction re-enters the beam where nothing is seen, and the coasting
    ends (the object was not where it was predicted to be)."""
    phases = braking_phases(lambda t: walker_at(t, x0_m=8.0) if t < 0.6 else None)
    assert phases == [(True, False), (False, True), (False, False)]


def test_without_a_time_nothing_is_coasted():
    radar = Radar(RadarSettings())
    for t in (0.0, 0.5, 1.0):
        body = walker_at(t, x0_m=8.0)
        rep = radar.scan((10.0 * t, 0.0), 0.0, 10.0, ROAD, [body], LANE_M)
        assert rep.coasted is None


def test_a_wrong_way_car_leaving_the_beam_beside_the_lane_centre_is_coasted_head_on():
    """A wrong-way car (50 km/h against the ego's 80), its centre 2.0 m left of the lane
    centre (inside the lane band): in path while seen, then coasted, still head-on and
    oncoming, at the range of its predicted box (closed form), until its centre passes the
    radar."""
    ego_mps, tgt_mps, d_m, dims = 80 / 3.6, 50 / 3.6, 2.0, (4.70, 1.82)

    def car(t):  # front face 30 m ahead of the ego's front at t = 0, driving west
        return Body(
            "car", "passenger", 30.0 + 0.5 * dims[0] - tgt_mps * t, d_m, math.pi, tgt_mps, *dims
        )

    phases, coasted = [], 0
    for _t, front, body, rep in drive(Radar(), ego_mps, 1.0, walker=car):
        phases.append("seen" if rep.in_path is not None else "coasted" if rep.coasted else "-")
        if rep.in_path is not None:
            assert rep.in_path.head_on and rep.oncoming_detected
        if rep.coasted is not None:
            coasted += 1
            det = rep.coasted
            assert det.head_on and det.category == "oncoming"
            front_face = body.x_m - 0.5 * dims[0]
            near_side = d_m - 0.5 * dims[1]
            assert det.range_m == pytest.approx(
                math.hypot(max(front_face - front, 0.0), near_side), abs=1e-9
            )
            assert det.range_rate_mps <= 1e-9  # closing (0 once beside the radar)
    runs = [p for i, p in enumerate(phases) if i == 0 or p != phases[i - 1]]
    assert runs == ["seen", "coasted", "-"] and coasted >= 3
