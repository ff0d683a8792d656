"""The animation's view on roads running every way (no SUMO): each frame shows the ego, its
radar cone, the obstacle and every road user within the radar's range, and turns with the
road. The scenes are built here from straight-line and circular motion, and what is inside a
view is worked out here with complex numbers (turn by multiplying with exp(-i rotation)),
independently of the module's own frame maths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.plotting.view import (
    MIN_WIDTH_M,
    FrameScene,
    Views,
    plan_views,
    smooth_heading,
)

FPS = 10.0
RADAR_M = 100.0
FOV_RAD = math.radians(18.0)
ASPECT = 0.31  # a wide picture, as the animation's
EGO_L, EGO_W = 4.9, 1.85


def corners(cx, cy, heading, length, width) -> np.ndarray:
    """(n, 4) complex corners of boxes centred at cx + i cy."""
    centre = (np.asarray(cx) + 1j * np.asarray(cy))[..., None]
    along = np.exp(1j * np.asarray(heading, float))[..., None]
    signs = np.array([1 + 1j, 1 - 1j, -1 - 1j, -1 + 1j])
    half_l = 0.5 * np.asarray(length, float)[..., None]
    half_w = 0.5 * np.asarray(width, float)[..., None]
    return centre + along * (half_l * signs.real + 1j * half_w * signs.imag)


def as_xy(z: np.ndarray) -> np.ndarray:
    return np.stack((z.real, z.imag), axis=-1)


def inside(views: Views, k: int, z: np.ndarray, slack_m: float = 1e-6) -> bool:
    local = (np.asarray(z) - (views.centre_x_m[k] + 1j * views.centre_y_m[k])) * np.exp(
        -1j * views.rotation_rad[k]
    )
    return bool(
        np.all(np.abs(local.real) <= 0.5 * views.width_m[k] + slack_m)
        and np.all(np.abs(local.imag) <= 0.5 * views.height_m[k] + slack_m)
    )


def scene_of(t, ego_z, ego_heading, road_heading, users) -> FrameScene:
    """A FrameScene from per-frame ego centres (complex) and headings and road users given as
    (per-frame complex centres, per-frame headings, length, width)."""
    ego = corners(ego_z.real, ego_z.imag, ego_heading, np.full(len(t), EGO_L), EGO_W)
    radar = ego_z + 0.5 * EGO_L * np.exp(1j * ego_heading)
    boxes, frames = [], []
    for z, heading, length, width in users:
        boxes.append(corners(z.real, z.imag, heading, np.full(len(t), length), width))
        frames.append(np.arange(len(t)))
    return FrameScene(
        time_s=t,
        heading_rad=road_heading,
        ego_box=as_xy(ego),
        ego_yaw_rad=ego_heading,
        radar_xy=as_xy(radar),
        user_box=as_xy(np.concatenate(boxes)) if boxes else np.zeros((0, 4, 2)),
        user_frame=np.concatenate(frames) if frames else np.zeros(0, int),
    )


def straight_road_run(heading_rad: float, start=(120.0, -40.0), speed_mps=25.0, seconds=6.0):
    """The ego driving straight along ``heading_rad`` towards a car stopped 95 m ahead of it
    at the start (and stopping behind it), followed 30 m behind by a car, an oncoming car in
    the next lane passing it, a parked car beside the road: (the scene, the obstacle's
    corners per frame, the ego's centre per frame)."""
    t = np.arange(0.0, seconds + 1e-9, 1.0 / FPS)
    along = np.exp(1j * heading_rad)
    left = 1j * along
    s = np.minimum(speed_mps * t, 88.0)  # stopping 2 m short of the obstacle's tail
    origin = start[0] + 1j * start[1]
    ego = origin + s * along
    h = np.full(len(t), heading_rad)
    users = [
        (origin + 95.0 * along + 0 * t, h, 4.6, 1.8),  # the obstacle, stopped
        (origin + (s - 30.0) * along, h, 4.6, 1.8),  # the follower
        (origin + (150.0 - 20.0 * t) * along + 3.5 * left, h + math.pi, 4.7, 1.8),  # oncoming
        (origin + 40.0 * along - 6.0 * left + 0 * t, h, 4.3, 1.8),  # parked beside the road
    ]
    scene = scene_of(t, ego, h, h, users)
    z, hh, ln, w = users[0]
    return scene, corners(z.real, z.imag, hh, np.full(len(t), ln), w), ego


def assert_frames_show(views: Views, scene: FrameScene, must: list[np.ndarray]) -> None:
    """Every frame shows the ego's box, its radar cone, each of ``must`` (per-frame corners)
    and every road user whose centre is within the radar's range of the ego."""
    ego_z = scene.ego_box[..., 0] + 1j * scene.ego_box[..., 1]
    radar = scene.radar_xy[:, 0] + 1j * scene.radar_xy[:, 1]
    user_z = scene.user_box[..., 0] + 1j * scene.user_box[..., 1]
    for k in range(len(scene.time_s)):
        cone = radar[k] + RADAR_M * np.exp(
            1j * (scene.ego_yaw_rad[k] + np.array([-0.5, 0.0, 0.5]) * FOV_RAD)
        )
        assert inside(views, k, ego_z[k]), k
        assert inside(views, k, np.append(cone, radar[k])), k
        for z in must:
            assert inside(views, k, z[k]), k
        mine = user_z[scene.user_frame == k]
        near = np.abs(mine.mean(axis=1) - ego_z[k].mean()) <= RADAR_M
        assert inside(views, k, mine[near]), k


HEADINGS_DEG = [0.0, 90.0, 180.0, -90.0, 45.0, 135.0, -135.0, -45.0, 30.0, 200.0]


@pytest.mark.parametrize("heading_deg", HEADINGS_DEG)
def test_a_straight_road_any_way_is_turned_to_point_right_and_keeps_all_in_view(heading_deg):
    heading = math.radians(heading_deg)
    scene, obstacle, ego = straight_road_run(heading)
    views = plan_views(scene, RADAR_M, FOV_RAD, ASPECT)
    assert_frames_show(views, scene, [obstacle])
    # the road runs left to right: the view's turn is the road's heading
    np.testing.assert_allclose(np.angle(np.exp(1j * (views.rotation_rad - heading))), 0, atol=1e-9)
    # and looks ahead: the ego left of the picture's middle, the view at least 150 m wide
    centre = views.centre_x_m + 1j * views.centre_y_m
    ahead = ((ego - centre) * np.exp(-1j * heading)).real
    assert (ahead < 0.0).all() and ahead[0] < -25.0
    assert (views.width_m >= MIN_WIDTH_M - 1e-9).all()
    np.testing.assert_allclose(views.height_m, ASPECT * views.width_m)


@settings(max_examples=40, deadline=None)
@given(
    heading=st.floats(-math.pi, math.pi),
    x0=st.floats(-5000.0, 5000.0),
    y0=st.floats(-5000.0, 5000.0),
    speed=st.floats(0.0, 45.0),
)
def test_any_heading_and_place_keeps_the_ego_the_obstacle_and_the_traffic_in_view(
    heading, x0, y0, speed
):
    scene, obstacle, _ = straight_road_run(heading, (x0, y0), speed)
    views = plan_views(scene, RADAR_M, FOV_RAD, ASPECT)
    assert_frames_show(views, scene, [obstacle])
    assert np.all(np.abs(np.angle(np.exp(1j * (views.rotation_rad - heading)))) < 1e-9)


def circle_run(radius_m: float, turn_deg: float, left: bool, speed_mps: float = 20.0):
    """The ego on a circular road from heading 30 deg, turning ``turn_deg`` (left or
    right), with a car stopped on the arc 60 m beyond where the ego ends."""
    sign = 1.0 if left else -1.0
    arc_m = radius_m * math.radians(turn_deg)
    t = np.arange(0.0, arc_m / speed_mps + 1e-9, 1.0 / FPS)
    start_heading = math.radians(30.0)
    centre = 200.0 + 300j + radius_m * 1j * sign * np.exp(1j * start_heading)

    def on_arc(s):
        angle = start_heading - sign * math.pi / 2 + sign * np.asarray(s) / radius_m
        return centre + radius_m * np.exp(1j * angle), start_heading + sign * np.asarray(
            s
        ) / radius_m

    ego, heading = on_arc(speed_mps * t)
    # the ego's yaw wobbles about the road's by +-3 deg at 1.5 Hz (a lane change, say)
    yaw = heading + math.radians(3.0) * np.sin(2 * math.pi * 1.5 * t)
    stop_z, stop_h = on_arc(arc_m + 60.0)
    obstacle = (np.full(len(t), stop_z), np.full(len(t), float(stop_h)), 4.6, 1.8)
    scene = scene_of(t, ego, yaw, heading, [obstacle])
    return (
        scene,
        corners(obstacle[0].real, obstacle[0].imag, obstacle[1], np.full(len(t), 4.6), 1.8),
        heading,
    )


@pytest.mark.parametrize("radius_m", [40.0, 150.0, 600.0])
@pytest.mark.parametrize("left", [True, False])
def test_a_curve_turning_the_road_round_keeps_the_ego_and_the_obstacle_in_view(radius_m, left):
    """The obstacle is in view whenever it is within the radar's range (on the 40 m circle,
    whose diameter is less than the range, always; on the others from 60 m before)."""
    scene, obstacle, heading = circle_run(radius_m, 200.0, left)
    views = plan_views(scene, RADAR_M, FOV_RAD, ASPECT)
    always = [obstacle] if 2 * radius_m < RADAR_M - 5.0 else []
    assert_frames_show(views, scene, always)
    ego = scene.ego_box.mean(axis=1)
    near = np.abs(obstacle.mean(axis=1) - (ego[:, 0] + 1j * ego[:, 1])) < RADAR_M
    assert near[-1] and near.sum() >= 2.0 * FPS
    # the view turns with the road: the whole 200 deg, within a few degrees of it away
    # from the ends (a zero-phase low-pass does not lag on a steady curve)
    turn = np.unwrap(views.rotation_rad)
    assert abs(abs(turn[-1] - turn[0]) - math.radians(200.0)) < math.radians(25.0)
    middle = slice(20, len(turn) - 20)
    assert np.abs(np.angle(np.exp(1j * (turn - heading))))[middle].max() < math.radians(1.0)


def test_the_heading_is_smoothed_without_lag_and_across_the_wrap():
    t = np.arange(0.0, 20.0, 0.01)
    rate = 0.3  # rad/s, through +-pi several times
    truth = math.pi - 0.5 + rate * t
    jitter = np.radians(2.0) * np.where(np.arange(len(t)) % 2, 1.0, -1.0)
    measured = np.angle(np.exp(1j * (truth + jitter)))  # wrapped into (-pi, pi]
    smooth = smooth_heading(t, measured)
    middle = slice(200, len(t) - 200)
    np.testing.assert_allclose(smooth[middle], truth[middle], atol=math.radians(0.05))
    assert np.abs(np.diff(smooth)).max() < 2 * rate * 0.01


def test_a_road_user_coming_into_range_behind_widens_the_view_gently():
    """A car closing from 160 m behind at 25 m/s comes within the radar's range of the ego
    (stopped behind the obstacle) after 5.9 s: the view widens to take it in, frame by
    frame, beginning before it is needed."""
    scene, obstacle, _ = straight_road_run(0.0, speed_mps=20.0, seconds=9.0)
    t = scene.time_s
    chaser = (120.0 - 40j) + (-160.0 + 25.0 * t)
    box = corners(chaser.real, chaser.imag, np.zeros(len(t)), np.full(len(t), 4.6), 1.8)
    scene = scene._replace(
        user_box=np.concatenate((scene.user_box, as_xy(box))),
        user_frame=np.concatenate((scene.user_frame, np.arange(len(t)))),
    )
    views = plan_views(scene, RADAR_M, FOV_RAD, ASPECT)
    assert_frames_show(views, scene, [obstacle])
    assert views.width_m.max() > 200.0 and views.width_m[0] < 160.0
    assert np.abs(np.diff(views.width_m)).max() < 12.0  # metres a frame at 10 fps
    centre = views.centre_x_m + 1j * views.centre_y_m
    assert np.abs(np.diff(centre)).max() < 20.0 * 0.1 + 8.0
