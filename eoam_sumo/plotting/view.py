"""Where each frame of ``eoam-sumo animate`` looks: its centre, its turn and its size.

Pure numpy, no drawing. The view is turned so that the heading it follows (the road's, else
the ego's) points to the right of the picture, whichever way the road runs; that heading is
low-pass filtered (a zero-phase Gaussian over the run, so a curve is followed without lag and
the picture does not jitter at the chords of a polyline road). In the turned frame
(``u`` along the view heading, ``v`` to its left) each frame must show the ego's box, its
radar cone (from the front bumper along the ego's heading, ``radar_range_m`` long,
``radar_fov_rad`` wide), the road ``BEHIND_M`` behind the ego and every road user whose
centre lies within the radar's range of the ego (ahead, beside or behind it). The view is
centred on the middle of what must be shown, smoothed relative to the ego (a road user
coming into range moves it gently); its width is the largest any frame within
``SCALE_HOLD_S`` either side needs about that centre, smoothed, so the scale changes gently
and never leaves out anything that must be shown.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

HEADING_SMOOTH_S = 0.5  # standard deviation of the Gaussian low-pass on the view heading [s]
SCALE_HOLD_S = 1.5  # the view's width covers what frames this close in time need [s]
MARGIN_M = 5.0  # free space around what must be shown [m]
MIN_WIDTH_M = 150.0  # the view is never narrower [m]
BEHIND_M = 40.0  # road shown behind the ego's centre [m]


class Views(NamedTuple):
    """One view per frame: centre in network coordinates [m], turn (the direction, counter-
    clockwise from +x, drawn pointing right) [rad], width along it and height across [m]."""

    centre_x_m: np.ndarray
    centre_y_m: np.ndarray
    rotation_rad: np.ndarray
    width_m: np.ndarray
    height_m: np.ndarray


class FrameScene(NamedTuple):
    """What the frames must show, in network coordinates: per frame the heading the view
    follows, the ego's box corners and heading and the radar's place (the front bumper); per
    road user box (``user_box``, corners) the frame it belongs to (``user_frame``)."""

    time_s: np.ndarray  # (n,)
    heading_rad: np.ndarray  # (n,) the road's heading, else the ego's
    ego_box: np.ndarray  # (n, 4, 2)
    ego_yaw_rad: np.ndarray  # (n,)
    radar_xy: np.ndarray  # (n, 2)
    user_box: np.ndarray  # (m, 4, 2)
    user_frame: np.ndarray  # (m,) int


def box_corners(x, y, yaw, length, width) -> np.ndarray:
    """(n, 4, 2) corners of footprint rectangles centred at (x, y), ``length`` along ``yaw``."""
    x, y, yaw, length, width = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (x, y, yaw, length, width))
    )
    c, s = np.cos(yaw), np.sin(yaw)
    hl, hw = 0.5 * length, 0.5 * width
    corners = [
        np.stack((x + fl * hl * c - fw * hw * s, y + fl * hl * s + fw * hw * c), axis=-1)
        for fl, fw in ((1, 1), (1, -1), (-1, -1), (-1, 1))
    ]
    return np.stack(corners, axis=-2)


def to_view(x, y, rotation_rad):
    """(u, v): the vector (x, y) in a frame turned by ``rotation_rad`` (u along it)."""
    c, s = np.cos(rotation_rad), np.sin(rotation_rad)
    return x * c + y * s, -x * s + y * c


def from_view(u, v, rotation_rad):
    """(x, y): the vector (u, v) of a frame turned by ``rotation_rad`` in network axes."""
    c, s = np.cos(rotation_rad), np.sin(rotation_rad)
    return u * c - v * s, u * s + v * c


def _gaussian(values: np.ndarray, half_width: int, sigma: float) -> np.ndarray:
    """``values`` smoothed by a Gaussian of ``sigma`` samples cut at ``half_width`` samples,
    the ends extended by their own value (zero phase: no lag)."""
    if half_width < 1 or len(values) < 2:
        return values.astype(float)
    offsets = np.arange(-half_width, half_width + 1)
    kernel = np.exp(-0.5 * (offsets / sigma) ** 2)
    kernel /= kernel.sum()
    return np.convolve(np.pad(values, half_width, mode="edge"), kernel, mode="valid")


def _step_s(time_s: np.ndarray) -> float:
    steps = np.diff(time_s)
    steps = steps[steps > 0]
    return float(np.median(steps)) if len(steps) else 1.0


def smooth_heading(time_s: np.ndarray, heading_rad: np.ndarray, sigma_s: float = HEADING_SMOOTH_S):
    """The heading, unwrapped and low-pass filtered: a zero-phase Gaussian of ``sigma_s``."""
    sigma = sigma_s / _step_s(time_s)
    return _gaussian(np.unwrap(heading_rad), int(3.0 * sigma), max(sigma, 1e-9))


def _held_width(need_m: np.ndarray, hold: int) -> np.ndarray:
    """Per frame a width no smaller than ``need_m`` of any frame within ``hold`` frames: the
    running maximum over that window, smoothed by a Gaussian cut at the same window (a
    weighted mean of values each at least the frame's own need)."""
    if hold < 1 or len(need_m) < 2:
        return need_m
    padded = np.pad(need_m, hold, mode="edge")
    held = np.lib.stride_tricks.sliding_window_view(padded, 2 * hold + 1).max(axis=1)
    return np.maximum(_gaussian(held, hold, 0.5 * hold), need_m)


def radar_cone(apex_xy: np.ndarray, yaw_rad: np.ndarray, range_m: float, fov_rad: float):
    """(n, 4, 2): the radar's apex, its two far corners and the middle of its far arc."""
    apex = np.asarray(apex_xy, float)
    points = [apex]
    for angle in (-0.5 * fov_rad, 0.0, 0.5 * fov_rad):
        ray = np.stack((np.cos(yaw_rad + angle), np.sin(yaw_rad + angle)), axis=-1)
        points.append(apex + range_m * ray)
    return np.stack(points, axis=-2)


def users_in_range(scene: FrameScene, range_m: float) -> np.ndarray:
    """Which road user boxes have their centre within ``range_m`` of the ego's centre or
    of the radar."""
    frame = scene.user_frame
    centre = scene.user_box.mean(axis=1)
    ego = scene.ego_box.mean(axis=1)[frame]
    radar = scene.radar_xy[frame]
    near = np.hypot(*(centre - ego).T) <= range_m
    return near | (np.hypot(*(centre - radar).T) <= range_m)


def _must_show(scene: FrameScene, range_m: float, fov_rad: float, rotation: np.ndarray):
    """(frame of each point, x, y): every point the frames must show."""
    n = len(scene.time_s)
    centre = scene.ego_box.mean(axis=1)
    du, dv = from_view(-BEHIND_M, 0.0, rotation)
    behind = np.stack((centre[:, 0] + du, centre[:, 1] + dv), axis=-1)[:, None, :]
    cone = radar_cone(scene.radar_xy, scene.ego_yaw_rad, range_m, fov_rad)
    own = np.concatenate((scene.ego_box, cone, behind), axis=1)  # (n, 9, 2)
    frames = [np.repeat(np.arange(n), own.shape[1])]
    points = [own.reshape(-1, 2)]
    near = users_in_range(scene, range_m)
    frames.append(np.repeat(scene.user_frame[near].astype(int), 4))
    points.append(scene.user_box[near].reshape(-1, 2))
    xy = np.concatenate(points)
    return np.concatenate(frames), xy[:, 0], xy[:, 1]


def _bounds(frame: np.ndarray, x, y, rotation: np.ndarray):
    """Per frame the box (u_lo, u_hi, v_lo, v_hi) of its points in its turned frame."""
    n = len(rotation)
    u, v = to_view(x, y, rotation[frame])
    lo_u, hi_u = np.full(n, np.inf), np.full(n, -np.inf)
    lo_v, hi_v = np.full(n, np.inf), np.full(n, -np.inf)
    np.minimum.at(lo_u, frame, u)
    np.maximum.at(hi_u, frame, u)
    np.minimum.at(lo_v, frame, v)
    np.maximum.at(hi_v, frame, v)
    return lo_u, hi_u, lo_v, hi_v


def _centre_offsets(scene: FrameScene, bounds, rotation: np.ndarray, hold: int):
    """Per frame the view's centre relative to the ego's, in the turned frame: the middle of
    what must be shown, smoothed (a road user coming into range moves it gently)."""
    lo_u, hi_u, lo_v, hi_v = bounds
    ego = scene.ego_box.mean(axis=1)
    ego_u, ego_v = to_view(ego[:, 0], ego[:, 1], rotation)
    sigma = max(0.5 * hold, 1e-9)
    off_u = _gaussian(0.5 * (lo_u + hi_u) - ego_u, hold, sigma)
    off_v = _gaussian(0.5 * (lo_v + hi_v) - ego_v, hold, sigma)
    return ego_u + off_u, ego_v + off_v


def plan_views(
    scene: FrameScene,
    radar_range_m: float,
    radar_fov_rad: float,
    aspect: float,
    min_width_m: float = MIN_WIDTH_M,
) -> Views:
    """The view of each frame of ``scene``; ``aspect`` is the picture's height / width."""
    rotation = smooth_heading(scene.time_s, scene.heading_rad)
    frame, x, y = _must_show(scene, radar_range_m, radar_fov_rad, rotation)
    lo_u, hi_u, lo_v, hi_v = bounds = _bounds(frame, x, y, rotation)
    hold = round(SCALE_HOLD_S / _step_s(scene.time_s))
    cu, cv = _centre_offsets(scene, bounds, rotation, hold)
    half_u = np.maximum(hi_u - cu, cu - lo_u) + MARGIN_M
    half_v = np.maximum(hi_v - cv, cv - lo_v) + MARGIN_M
    need = np.maximum(2.0 * half_u, 2.0 * half_v / aspect)
    width = _held_width(np.maximum(need, min_width_m), hold)
    cx, cy = from_view(cu, cv, rotation)
    return Views(cx, cy, np.arctan2(np.sin(rotation), np.cos(rotation)), width, aspect * width)
