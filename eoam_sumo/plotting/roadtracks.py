"""Every road user of a run in the ego's road frame, and the events the traffic plot marks.

The road frame is the one the run measured the ego in (paper sec. 4.2-4.3: station ``s``
along the centre line of the ego's original lane, lateral offset ``d``, left positive): the
run writes that centre line as ``road.csv`` (``sim.runlog.ROAD_FILE``), and every road user's
footprint centre of ``traffic.csv`` is projected onto it with the run's own ``RoadFrame``,
so curved roads and roads in any direction come out as the run saw them. A run folder
without ``road.csv`` (written before it existed) gets the centre line back from the ego's own
samples (:func:`centreline_from_ego`): exact along the stretch the ego drove, extended
straight beyond it.

Events: the smallest box-to-box gaps to the obstacle and to oncoming traffic
(:func:`closest_approach`, over the rows of that role, as the run's ``min_gap_aro_m`` and
``min_gap_oncoming_m`` are), and the road users braking harder than
``HARD_BRAKING_MPS2`` (:func:`hard_braking`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from eoam_sumo.errors import InputError
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.runlog import ROAD_FILE, read_road
from eoam_sumo.world.geometry import OrientedBox, box_distance

#: A road user braking harder than this is marked as forced to brake [m/s^2]: the
#: deceleration of AASHTO's stopping sight distance (A Policy on Geometric Design of
#: Highways and Streets, 2011, sec. 3.2.2.2: 3.4 m/s^2, comfortable for most drivers, and
#: exceeded by about 90 % of drivers stopping for an unexpected object). SUMO's default
#: passenger car brakes at up to ``decel`` 4.5 m/s^2 in normal driving and up to
#: ``emergencyDecel`` 9 m/s^2 to avoid a collision; both lie above this threshold.
HARD_BRAKING_MPS2 = 3.4
#: Decelerations are speed drops over this time [s]: ten 10 ms steps, so that one step's
#: rounding of SUMO's speed does not read as braking.
BRAKING_WINDOW_S = 0.1
#: The ego's samples are kept this far apart along the road for its centre line [m].
EGO_LINE_SPACING_M = 1.0
#: Classes whose speed changes are not braking (SUMO's persons start and stop at once).
NOT_BRAKING_CLASSES = ("pedestrian",)
#: Roles ranked from the most telling: a road user is drawn in the first role it ever had.
ROLE_RANK = ("ego", "aro", "oncoming", "parked", "other")


@dataclass
class EgoRoad:
    """The road frame of the ego's original lane: ``project`` gives (s, d) of a network point
    in the run's stations. ``source`` says where the centre line came from; ``covered_m`` is
    the stretch of stations it is known on (None: the whole route, from road.csv)."""

    frame: RoadFrame
    s0_m: float
    source: str
    covered_m: tuple[float, float] | None = None

    def project(self, x_m: float, y_m: float) -> tuple[float, float]:
        s_m, d_m, _ = self.frame.project(x_m, y_m)
        return s_m + self.s0_m, d_m

    def project_path(self, xy: np.ndarray) -> np.ndarray:
        """(n, 2) stations and offsets of the points of a path (n, 2), walked in order."""
        out = np.empty((len(xy), 2))
        if len(xy):
            self.frame.locate(float(xy[0, 0]), float(xy[0, 1]))
        for k, (x, y) in enumerate(xy):
            out[k] = self.project(float(x), float(y))
        return out


def ego_road(run_dir: Path, ts: pd.DataFrame) -> EgoRoad:
    """The run's road frame: road.csv's centre line, else the ego's samples'."""
    path = Path(run_dir) / ROAD_FILE
    if path.is_file():
        return EgoRoad(RoadFrame(read_road(path)), 0.0, f"{ROAD_FILE} (the run's centre line)")
    try:
        points, s0 = centreline_from_ego(ts)
    except ValueError as exc:
        raise InputError(f"{Path(run_dir) / 'timeseries.csv'}: {exc}") from exc
    covered = (float(np.nanmin(ts["s_m"])), float(np.nanmax(ts["s_m"])))
    return EgoRoad(
        RoadFrame(points), s0, "the ego's samples (no road.csv): straight beyond them", covered
    )


def centreline_from_ego(ts: pd.DataFrame) -> tuple[np.ndarray, float]:
    """(points (n, 2), station of the first) of the centre line the ego was measured from:
    each sample's centre of gravity moved back across the road by its lateral offset d, at
    the road heading (yaw - heading error), kept every ``EGO_LINE_SPACING_M`` of station.
    An ego that hardly moved gives a metre of line along the road heading."""
    cols = ["x_m", "y_m", "yaw_rad", "heading_error_rad", "s_m", "lateral_offset_m"]
    x, y, yaw, e_yaw, s, d = (ts[c].to_numpy(dtype=float) for c in cols)
    ok = np.isfinite(x) & np.isfinite(y) & np.isfinite(yaw) & np.isfinite(e_yaw)
    ok &= np.isfinite(s) & np.isfinite(d)
    if not ok.any():
        raise ValueError("no finite sample of the ego to draw its road from")
    road_yaw = yaw[ok] - e_yaw[ok]
    cx = x[ok] + d[ok] * np.sin(road_yaw)
    cy = y[ok] - d[ok] * np.cos(road_yaw)
    s = s[ok]
    keep = [0]
    for k in range(1, len(s)):
        if s[k] - s[keep[-1]] >= EGO_LINE_SPACING_M:
            keep.append(k)
    if len(keep) < 2:
        c, r = keep[0], road_yaw[keep[0]]
        return np.array([[cx[c], cy[c]], [cx[c] + math.cos(r), cy[c] + math.sin(r)]]), s[c]
    return np.column_stack((cx[keep], cy[keep])), float(s[keep[0]])


def project_traffic(traffic: pd.DataFrame, road: EgoRoad) -> pd.DataFrame:
    """traffic.csv's rows with ``s_m`` and ``d_m`` of each footprint centre, each road user's
    rows projected in time order from where its first one lies (the traffic log's walk)."""
    out = traffic.copy()
    s = np.full(len(out), np.nan)
    d = np.full(len(out), np.nan)
    xy = out[["x_m", "y_m"]].to_numpy(dtype=float)
    order = np.lexsort((out["time_s"].to_numpy(), out["id"].to_numpy()))
    ids = out["id"].to_numpy()[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    for a, b in zip(starts, [*starts[1:], len(order)]):
        rows = order[a:b]
        sd = road.project_path(xy[rows])
        s[rows], d[rows] = sd[:, 0], sd[:, 1]
    out["s_m"], out["d_m"] = s, d
    return out


def telling_roles(traffic: pd.DataFrame) -> dict[str, str]:
    """Each road user's most telling role over the run (``ROLE_RANK``)."""
    rank = traffic["role"].map({r: k for k, r in enumerate(ROLE_RANK)}).fillna(len(ROLE_RANK))
    best = rank.groupby(traffic["id"]).min().astype(int)
    return {vid: ROLE_RANK[min(k, len(ROLE_RANK) - 1)] for vid, k in best.items()}


class Closest(NamedTuple):
    """The smallest box-to-box gap between the ego and a road user of a role: the gap, when,
    who, and the rows of the road user and of the ego then (indices of the traffic frame)."""

    gap_m: float
    time_s: float
    vid: str
    row: int
    ego_row: int


def _box(row: pd.Series) -> OrientedBox:
    return OrientedBox(
        float(row["x_m"]),
        float(row["y_m"]),
        float(row["heading_rad"]),
        float(row["length_m"]),
        float(row["width_m"]),
    )


def closest_approach(traffic: pd.DataFrame, role: str) -> Closest | None:
    """The smallest gap between the ego's box and the box of any road user in the rows where
    it has ``role`` at the same time (None when no row has it). Exact gaps are worked out
    in order of the bounding circles' gap, a lower bound, until that bound passes the least
    gap found."""
    ego = traffic[traffic["role"] == "ego"]
    ego_at = pd.Series(ego.index, index=ego["time_s"].to_numpy())
    ego_at = ego_at[~ego_at.index.duplicated()]
    rows = traffic[(traffic["role"] == role) & traffic["time_s"].isin(ego_at.index)]
    if rows.empty:
        return None
    ego_rows = ego_at.loc[rows["time_s"].to_numpy()].to_numpy()
    e = traffic.loc[ego_rows]
    centres = np.hypot(
        rows["x_m"].to_numpy() - e["x_m"].to_numpy(), rows["y_m"].to_numpy() - e["y_m"].to_numpy()
    )
    radii = 0.5 * (
        np.hypot(rows["length_m"].to_numpy(), rows["width_m"].to_numpy())
        + np.hypot(e["length_m"].to_numpy(), e["width_m"].to_numpy())
    )
    lower = centres - radii
    best: Closest | None = None
    for k in np.argsort(lower, kind="stable"):
        if best is not None and lower[k] >= best.gap_m:
            break  # no row further on can come closer
        row, ego_row = rows.index[k], int(ego_rows[k])
        gap = box_distance(_box(traffic.loc[ego_row]), _box(traffic.loc[row]))
        if best is None or gap < best.gap_m:
            t = float(rows.at[row, "time_s"])
            best = Closest(gap, t, str(rows.at[row, "id"]), int(row), ego_row)
    return best


class Braking(NamedTuple):
    """A road user braking harder than the threshold: who, from when to when, the hardest
    deceleration and the speeds before and after (rows: indices of the traffic frame)."""

    vid: str
    t_start_s: float
    t_end_s: float
    peak_mps2: float
    speed_from_mps: float
    speed_to_mps: float
    rows: tuple[int, ...]


def hard_braking(
    traffic: pd.DataFrame,
    threshold_mps2: float = HARD_BRAKING_MPS2,
    window_s: float = BRAKING_WINDOW_S,
) -> list[Braking]:
    """Every spell in which a road user (not the ego, not parked, not a person) lost speed
    faster than ``threshold_mps2`` over ``window_s``, in order of time."""
    moving = traffic[
        (traffic["role"] != "ego")
        & (traffic["role"] != "parked")
        & ~traffic["vclass"].isin(NOT_BRAKING_CLASSES)
    ]
    spells: list[Braking] = []
    for vid, rows in moving.sort_values("time_s", kind="stable").groupby("id", sort=True):
        spells += _braking_spells(str(vid), rows, threshold_mps2, window_s)
    return sorted(spells, key=lambda b: (b.t_start_s, b.vid))


def _braking_spells(
    vid: str, rows: pd.DataFrame, threshold_mps2: float, window_s: float
) -> list[Braking]:
    """The spells of one road user's rows (in time order): the deceleration at a row is the
    speed lost from it to the row ``window_s`` later (none across a gap in its rows)."""
    t = rows["time_s"].to_numpy(dtype=float)
    v = rows["speed_mps"].to_numpy(dtype=float)
    later = np.searchsorted(t, t + window_s - 1e-9)
    ok = later < len(t)
    span = np.where(ok, t[np.minimum(later, len(t) - 1)] - t, np.nan)
    ok &= span <= 1.5 * window_s
    decel = np.full(len(t), np.nan)
    decel[ok] = (v[ok] - v[later[ok]]) / span[ok]
    hard = np.nan_to_num(decel) > threshold_mps2
    edges = np.flatnonzero(np.diff(np.r_[0, hard.astype(int), 0]))
    spells = []
    for a, b in zip(edges[::2], edges[1::2]):
        end = int(min(later[b - 1], len(t) - 1))
        spells.append(
            Braking(
                vid,
                float(t[a]),
                float(t[end]),
                float(np.nanmax(decel[a:b])),
                float(v[a]),
                float(v[end]),
                tuple(int(i) for i in rows.index[a : end + 1]),
            )
        )
    return spells


def box_outline(road: EgoRoad, row: pd.Series) -> np.ndarray:
    """(5, 2) stations and offsets of a footprint's corners (closed), in the road frame."""
    box = _box(row)
    corners = []
    for fl, fw in ((1, 1), (1, -1), (-1, -1), (-1, 1), (1, 1)):
        corners.append(
            (
                box.x_m
                + fl * box.half_length_m * box.cos_yaw
                - fw * box.half_width_m * box.sin_yaw,
                box.y_m
                + fl * box.half_length_m * box.sin_yaw
                + fw * box.half_width_m * box.cos_yaw,
            )
        )
    return road.project_path(np.array(corners))
