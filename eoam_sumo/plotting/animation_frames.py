"""The frames of ``eoam-sumo animate``, read from a run folder: the time-series rows shown,
the road users' boxes of each, the contact and each frame's view (``plotting/view.py``).

Frames are taken every 1/fps seconds of run time; the last frame is the run's last row, and
for a run that ended in a contact the row of the contact (``contact_time_s``), none after it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.errors import InputError
from eoam_sumo.plotting.run_plots import load_run
from eoam_sumo.plotting.view import FrameScene, Views, box_corners, plan_views
from eoam_sumo.sim.runlog import written_as
from eoam_sumo.sim.trafficlog import TRAFFIC_FILE, read_traffic

ROLE_RANK = {"ego": 0, "aro": 1, "oncoming": 2, "parked": 3, "other": 4}
MIN_DRAWN_M = 1.0  # road users are drawn at least this long and wide [m]
DEFAULT_RADAR_RANGE_M = 100.0
DEFAULT_RADAR_FOV_DEG = 18.0
SAME_TIME_S = 5e-7  # traffic.csv and timeseries.csv rows this close are the same step [s]


@dataclass(frozen=True)
class Contact:
    """The first contact: its time [s], its point [m] and the traffic row of the road user
    hit in the contact frame (None when it is not in traffic.csv)."""

    time_s: float
    x_m: float
    y_m: float
    hit_row: int | None


@dataclass(frozen=True)
class RunFrames:
    """What the animation of one run shows. Per frame (``rows``: its time-series row) the
    slice ``user_start:user_end`` of the traffic arrays (sorted by time), the ego's box
    centre, heading and radar place, and the view; per traffic row its drawn box, id and
    role rank (the most telling role the road user had)."""

    summary: dict
    series: pd.DataFrame
    rows: np.ndarray
    time_s: np.ndarray
    user_start: np.ndarray
    user_end: np.ndarray
    box: np.ndarray
    user_id: np.ndarray
    rank: np.ndarray
    is_ego: np.ndarray
    ego_xy: np.ndarray
    ego_yaw_rad: np.ndarray
    radar_xy: np.ndarray
    radar_range_m: float
    radar_fov_rad: float
    contact: Contact | None
    views: Views


def frame_rows(time_s: np.ndarray, fps: float, contact_time_s: float | None = None):
    """Indices of the time-series rows shown: one every 1/fps s of run time, and last the
    row of the contact (the first at or after ``contact_time_s``), else the run's last row."""
    last = len(time_s) - 1
    if contact_time_s is not None:
        last = min(int(np.searchsorted(time_s, contact_time_s - 1e-9)), last)
    wanted = np.arange(time_s[0], time_s[last] + 1e-9, 1.0 / fps)
    rows = np.clip(np.searchsorted(time_s, wanted - 1e-9), 0, last)
    return np.unique(np.append(rows, last))


def _read(run_dir: Path):
    """The run's summary, time series and traffic log; InputError naming what is wrong."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: no such run folder")
    if not (run_dir / "summary.json").is_file():
        raise InputError(f"{run_dir}: not a run folder (no summary.json)")
    summary, ts = load_run(run_dir)
    traffic_path = written_as(run_dir / TRAFFIC_FILE)
    if not traffic_path.is_file():
        raise InputError(
            f"{run_dir}: has no {TRAFFIC_FILE} (a run with --timeseries none, or of an older "
            "eoam-sumo; run it again)"
        )
    traffic = read_traffic(traffic_path).sort_values("time_s", kind="stable")
    return summary, ts, traffic.reset_index(drop=True)


def _ego_pose(ts: pd.DataFrame, traffic: pd.DataFrame, rows: np.ndarray):
    """Per frame the ego's box centre (its centre of gravity when traffic.csv lacks the
    row), heading and box size."""
    t = ts["time_s"].to_numpy()[rows]
    cg = ts[["x_m", "y_m"]].to_numpy()[rows]
    yaw = ts["yaw_rad"].to_numpy()[rows]
    ego = traffic[traffic["role"] == "ego"]
    if ego.empty:
        return cg, yaw, 4.9, 1.85
    at = np.searchsorted(ego["time_s"].to_numpy(), t - SAME_TIME_S).clip(0, len(ego) - 1)
    found = np.abs(ego["time_s"].to_numpy()[at] - t) < SAME_TIME_S
    centre = np.where(found[:, None], ego[["x_m", "y_m"]].to_numpy()[at], cg)
    return centre, yaw, float(ego["length_m"].iloc[0]), float(ego["width_m"].iloc[0])


def _road_heading(ts: pd.DataFrame, rows: np.ndarray) -> np.ndarray:
    """Per frame the road's heading under the ego (its yaw less its heading error), the
    ego's yaw where the run has none."""
    yaw = ts["yaw_rad"].to_numpy()[rows]
    road = yaw - ts["heading_error_rad"].to_numpy()[rows]
    return np.where(np.isfinite(road), road, yaw)


def _contact(summary: dict, traffic: pd.DataFrame, start: int, end: int, ego_xy) -> Contact:
    """The contact of summary.json in the frame whose traffic rows are ``start:end``: the hit
    road user by id, else (a run of an older eoam-sumo) the one nearest to the ego, and its
    point, else the midpoint between the two."""
    rows = traffic.iloc[start:end]
    others = rows[rows["role"] != "ego"]
    hit_id = summary.get("collision_with_id")
    hit = others[others["id"] == hit_id] if hit_id is not None else others.iloc[:0]
    if hit.empty and not others.empty:
        gap = np.hypot(others["x_m"] - ego_xy[0], others["y_m"] - ego_xy[1])
        hit = others.iloc[[int(np.argmin(gap.to_numpy()))]]
    hit_row = start + int(np.flatnonzero(rows.index == hit.index[0])[0]) if len(hit) else None
    x, y = summary.get("contact_x_m"), summary.get("contact_y_m")
    if x is None or y is None:
        other = hit[["x_m", "y_m"]].to_numpy()[0] if len(hit) else ego_xy
        x, y = 0.5 * (ego_xy[0] + other[0]), 0.5 * (ego_xy[1] + other[1])
    return Contact(float(summary["contact_time_s"]), float(x), float(y), hit_row)


def _traffic_columns(traffic: pd.DataFrame):
    """Per traffic row its drawn box (small road users at least ``MIN_DRAWN_M`` across), id,
    role rank (the most telling role its road user had) and whether it is the ego."""
    x, y, heading, length, width = (
        traffic[c].to_numpy() for c in ("x_m", "y_m", "heading_rad", "length_m", "width_m")
    )
    box = box_corners(
        x, y, heading, np.maximum(length, MIN_DRAWN_M), np.maximum(width, MIN_DRAWN_M)
    ).reshape(-1, 4, 2)
    rank = traffic["role"].map(ROLE_RANK).fillna(4)
    best = rank.groupby(traffic["id"]).transform("min").astype(int).to_numpy()
    is_ego = (traffic["role"] == "ego").to_numpy()
    return box, traffic["id"].to_numpy(dtype=str), best, is_ego


def _frame_scene(ts, traffic, rows, start, end, box, is_ego) -> FrameScene:
    """What the frames of ``rows`` must show (``plotting/view.py``): the ego's box, heading
    and radar place, and the other road users' boxes, traffic rows ``start:end`` a frame."""
    ego_xy, yaw, length_m, width_m = _ego_pose(ts, traffic, rows)
    front = 0.5 * length_m * np.stack((np.cos(yaw), np.sin(yaw)), axis=-1)
    user = np.concatenate([np.arange(a, b) for a, b in zip(start, end)]).astype(int)
    frame_of = np.repeat(np.arange(len(rows)), end - start)
    others = ~is_ego[user]
    return FrameScene(
        time_s=ts["time_s"].to_numpy()[rows],
        heading_rad=_road_heading(ts, rows),
        ego_box=box_corners(ego_xy[:, 0], ego_xy[:, 1], yaw, length_m, width_m),
        ego_yaw_rad=yaw,
        radar_xy=ego_xy + front,
        user_box=box[user[others]].reshape(-1, 4, 2),
        user_frame=frame_of[others],
    )


def load_frames(run_dir: Path, fps: float, aspect: float) -> RunFrames:
    """The frames of the run in ``run_dir`` at ``fps``, their views for a picture of
    height / width ``aspect``; InputError naming a missing or damaged file."""
    if fps < 1:
        raise InputError(f"--fps {fps} must be a whole number >= 1")
    summary, ts, traffic = _read(run_dir)
    contact_t = summary.get("contact_time_s")
    rows = frame_rows(ts["time_s"].to_numpy(), fps, contact_t)
    t = ts["time_s"].to_numpy()[rows]
    times = traffic["time_s"].to_numpy()
    start = np.searchsorted(times, t - SAME_TIME_S)
    end = np.searchsorted(times, t + SAME_TIME_S)
    box, ids, rank, is_ego = _traffic_columns(traffic)
    scene = _frame_scene(ts, traffic, rows, start, end, box, is_ego)
    ego_xy = scene.ego_box.mean(axis=1)
    radar_m = float(summary.get("radar_range_m") or DEFAULT_RADAR_RANGE_M)
    fov_rad = math.radians(float(summary.get("radar_fov_deg") or DEFAULT_RADAR_FOV_DEG))
    contact = None
    if contact_t is not None:
        contact = _contact(summary, traffic, int(start[-1]), int(end[-1]), ego_xy[-1])
    return RunFrames(
        summary=summary,
        series=ts,
        rows=rows,
        time_s=t,
        user_start=start,
        user_end=end,
        box=box,
        user_id=ids,
        rank=rank,
        is_ego=is_ego,
        ego_xy=ego_xy,
        ego_yaw_rad=scene.ego_yaw_rad,
        radar_xy=scene.radar_xy,
        radar_range_m=radar_m,
        radar_fov_rad=fov_rad,
        contact=contact,
        views=plan_views(scene, radar_m, fov_rad, aspect),
    )
