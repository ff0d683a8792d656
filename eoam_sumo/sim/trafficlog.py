"""traffic.csv: every road user near the ego at each logged step (ground truth beside the
ego's timeseries.csv, and what ``eoam-sumo animate`` draws).

One row per road user per logged step: ``time_s, id, vclass, role, x_m, y_m, heading_rad,
speed_mps, length_m, width_m``. The time base is timeseries.csv's: the row at ``time_s`` t
holds the world at SUMO time t, where the timeseries row at t holds the ego state the
decision of that step started from. Pose is the centre of the body's footprint rectangle
(for the ego: the centre of its box, not its centre of gravity), heading counter-clockwise
from +x in (-pi, pi], speed along the heading (the ego's: its forward speed vx, signed).

Logged: the ego and every road user whose footprint centre lies within ``radius_m``
(``TRAFFIC_RADIUS_M``, 250 m) of the ego's centre of gravity, parked ones included.

Roles (per row, worked out when the log is written, relative to the ego's original lane as
the radar's classes are, with the radar's thresholds):

* ``ego``;
* ``parked``: SUMO reports the road user parked;
* ``oncoming``: moving against the road direction faster than 2 m/s, not right of the
  ego's lane (any lane to its left, the other carriageway too: the traffic as it is; the
  radar's ``oncoming`` class, which the EOAM decides on, stops at the next lane's band);
* ``aro``: its centre in the ego lane's band (half the lane width + 0.5 m), ahead of the
  ego (station beyond the ego's centre) or first met in the band ahead of it: the obstacle
  in the ego's lane, whatever it is (a stopped car, a person walking on the road), which
  keeps that role once passed (as ``min_gap_aro_m`` counts it); one first met in the band
  behind the ego is a follower (``other``), and so is one crossing the lane (``crosses_lane``:
  more than 45 deg off the road's direction, faster than 2 m/s: cross traffic at a junction)
  that was not the obstacle before it crossed;
* ``other``: the rest (traffic in other lanes, behind the ego, people on the pavement).

Cost in the step loop: one tuple kept per step (the ``Body`` tuples the loop already has are
shared, not copied); the radius test, the rows, the roles and the columns are worked out
once, when the log is written.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from eoam_sumo.fileio import write_atomic
from eoam_sumo.sim.observers import RunView, StepObserver
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.lanes import ONCOMING_SPEED_MPS, crosses_lane, lane_band_m

TRAFFIC_FILE = "traffic.csv"
#: traffic.csv columns, SI units in the names.
TRAFFIC_COLUMNS = (
    "time_s",
    "id",
    "vclass",
    "role",
    "x_m",
    "y_m",
    "heading_rad",
    "speed_mps",
    "length_m",
    "width_m",
)
ROLES = ("ego", "aro", "oncoming", "parked", "other")
#: Road users whose centre is within this distance of the ego's centre of gravity are logged:
#: twice the view of ``eoam-sumo animate`` and beyond any radar range used here, so a car
#: closing at 60 m/s is in the log 4 s before it reaches the ego [m].
TRAFFIC_RADIUS_M = 250.0
_DECIMALS = {
    "time_s": 6,
    "x_m": 4,
    "y_m": 4,
    "heading_rad": 6,
    "speed_mps": 4,
    "length_m": 4,
    "width_m": 4,
}


class TrafficLog(StepObserver):
    """Observer of the step loop that keeps the road users near the ego at each step.

    ``ego_vclass``, ``ego_length_m`` and ``ego_width_m`` describe the ego's box;
    ``cg_to_centre_m`` is the distance from its centre of gravity forward to the box's centre;
    ``centreline`` and ``lane_width_m`` give the ego's original lane for the roles."""

    def __init__(
        self,
        ego_id: str,
        ego_vclass: str,
        ego_length_m: float,
        ego_width_m: float,
        cg_to_centre_m: float,
        centreline: Iterable[Sequence[float]],
        lane_width_m: float,
        radius_m: float = TRAFFIC_RADIUS_M,
    ):
        if not (math.isfinite(radius_m) and radius_m > 0.0):
            raise ValueError(f"radius_m={radius_m!r} must be a finite number > 0")
        if not lane_width_m > 0.0:
            raise ValueError(f"lane_width_m={lane_width_m!r} must be > 0")
        self.ego_id, self.ego_vclass = ego_id, ego_vclass
        self._ego_size = (float(ego_length_m), float(ego_width_m))
        self._to_centre = float(cg_to_centre_m)
        self._centreline = [(float(p[0]), float(p[1])) for p in centreline]
        self._lane_width = float(lane_width_m)
        self.radius_m = float(radius_m)
        self._r2 = self.radius_m * self.radius_m
        self._steps: list[tuple] = []
        self._columns: dict | None = None

    def __len__(self) -> int:
        return len(self._steps)

    def after_step(self, sim: RunView) -> None:
        """The ego and the road users at the start of the step just made."""
        self.add(sim.meas.time_s, sim.x_prev, sim.bodies_before)

    def end(self, sim: RunView) -> None:
        """The ego and the road users when the run ended."""
        self.add(sim.t, sim.x, sim.bodies)

    def add(self, t: float, x: Sequence[float], bodies: Sequence) -> None:
        """Keep the ego state ``x`` (plant state: X, Y at the centre of gravity, yaw, vx, ...)
        and ``bodies``, the other road users at time ``t`` (immutable ``Body`` tuples in a
        list the caller does not change afterwards)."""
        self._steps.append((t, x[0], x[1], x[2], x[3], bodies))
        self._columns = None

    def had_role(self, role: str) -> bool:
        """Some road user had ``role`` at some logged step."""
        if role == "oncoming" and self._columns is None:
            return self._had_oncoming()
        return role in self.columns()["role"]

    def _had_oncoming(self) -> bool:
        """``had_role("oncoming")`` without laying the log out (a run's summary asks it of
        every run, written or not): the rows ``_roles`` would judge (the road users within
        the radius, not parked), walked as it walks them (by id, in time order, the road
        frame placed at each one's first row), until one is oncoming."""
        r2 = self._r2
        rows: dict[str, list] = {}
        for _ti, ex, ey, _yaw, _vx, bodies in self._steps:
            for b in _within(bodies, ex, ey, r2):
                if not b.parked:
                    rows.setdefault(b.vid, []).append(b)
        if not rows:
            return False
        road = RoadFrame(self._centreline)
        band = lane_band_m(self._lane_width)
        for vid in sorted(rows):
            first = rows[vid][0]
            road.locate(first.x_m, first.y_m)
            for b in rows[vid]:
                _s, d, road_yaw = road.project(b.x_m, b.y_m)
                if b.speed_mps * math.cos(b.yaw_rad - road_yaw) < -ONCOMING_SPEED_MPS and d > -band:
                    return True
        return False

    def columns(self) -> dict:
        """The log as columns (TRAFFIC_COLUMNS order): numpy arrays, and lists of str for
        ``id``, ``vclass`` and ``role``. Rows are by time, then the ego, then in the order
        the road users were given. Worked out once (until the next ``add``)."""
        if self._columns is None:
            self._columns = self._lay_out()
        return self._columns

    def _lay_out(self) -> dict:
        """The rows as columns. A road user's row is its ``Body`` itself (its first nine
        fields: vid, vclass, x, y, yaw, speed, length, width, parked), the ego's a tuple of the
        same nine, so the transpose builds no tuple per row."""
        r2, to_centre = self._r2, self._to_centre
        length, width = self._ego_size
        rows: list = []
        times: list[float] = []
        counts: list[int] = []
        for ti, ex, ey, yaw, vx, bodies in self._steps:
            near = _within(bodies, ex, ey, r2)
            rows.append(
                (
                    self.ego_id,
                    self.ego_vclass,
                    ex + to_centre * math.cos(yaw),
                    ey + to_centre * math.sin(yaw),
                    math.remainder(yaw, math.tau),
                    vx,
                    length,
                    width,
                    False,
                )
            )
            rows += near
            times.append(ti)
            counts.append(1 + len(near))
        ids, vclasses, *nums, parked = list(zip(*rows)) if rows else [()] * 9
        num = np.array(nums[:6], dtype=float).reshape(6, -1).T  # x, y, heading, speed, L, W
        step_of = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
        ego_rows = np.flatnonzero(np.diff(step_of, prepend=-1))
        t = np.repeat(np.array(times, dtype=float), counts)
        roles = self._roles(list(ids), num, np.array(parked, dtype=bool), ego_rows, step_of)
        return {
            "time_s": t,
            "id": list(ids),
            "vclass": list(vclasses),
            "role": roles,
            "x_m": num[:, 0],
            "y_m": num[:, 1],
            "heading_rad": num[:, 2],
            "speed_mps": num[:, 3],
            "length_m": num[:, 4],
            "width_m": num[:, 5],
        }

    def _roles(
        self,
        ids: list,
        num: np.ndarray,
        parked: np.ndarray,
        ego_rows: np.ndarray,
        step_of: np.ndarray,
    ) -> list[str]:
        """Role of every row (module doc): the ego's station at each step first, then each
        road user's rows in time order, so the road frame's walk moves a little at a time.
        (The numbers as Python floats: the same doubles, without numpy's per-scalar cost.)"""
        roles = ["other"] * len(ids)
        if not ids:
            return roles
        xs: list[float] = num[:, 0].tolist()
        ys: list[float] = num[:, 1].tolist()
        yaws: list[float] = num[:, 2].tolist()
        speeds: list[float] = num[:, 3].tolist()
        road = RoadFrame(self._centreline)
        road.locate(xs[ego_rows[0]], ys[ego_rows[0]])
        ego_s: list[float] = []
        for k in ego_rows.tolist():
            ego_s.append(road.project(xs[k], ys[k])[0])
            roles[k] = "ego"
        band = lane_band_m(self._lane_width)
        others = np.flatnonzero(~parked)
        others = others[np.isin(others, ego_rows, invert=True)]
        for k in np.flatnonzero(parked).tolist():
            roles[k] = "parked"
        by_id = sorted(others.tolist(), key=lambda k: (ids[k], k))
        step_at = step_of.tolist()
        previous, met_ahead, was_aro = None, None, False
        for k in by_id:
            x, y = xs[k], ys[k]
            if ids[k] != previous:
                road.locate(x, y)
                previous, met_ahead, was_aro = ids[k], None, False
            s, d, road_yaw = road.project(x, y)
            if speeds[k] * math.cos(yaws[k] - road_yaw) < -ONCOMING_SPEED_MPS and d > -band:
                roles[k] = "oncoming"
            elif abs(d) < band:
                ahead = s > ego_s[step_at[k]]
                met_ahead = ahead if met_ahead is None else met_ahead
                crossing = crosses_lane(speeds[k], yaws[k], road_yaw)
                if (ahead or met_ahead) and (was_aro or not crossing):
                    roles[k], was_aro = "aro", True
        return roles

    def write(self, path: Path) -> None:
        """Write the log (atomically) as CSV, or as Parquet when ``path`` ends in
        ``.parquet``, through pyarrow (a tenth of the time of Python's or pandas' CSV
        formatting); numbers rounded (``_DECIMALS``), written in their shortest form, text
        quoted only where it must be."""
        import pyarrow as pa
        import pyarrow.csv as pa_csv
        import pyarrow.parquet as pa_parquet

        path = Path(path)
        cols = self.columns()
        table = pa.Table.from_arrays(
            [
                _float_array(np.round(cols[name], _DECIMALS[name]) + 0.0)
                if name in _DECIMALS
                else _text_array(cols[name])
                for name in TRAFFIC_COLUMNS
            ],
            names=list(TRAFFIC_COLUMNS),
        )
        sink = pa.BufferOutputStream()
        if path.suffix == ".parquet":
            pa_parquet.write_table(table, sink, compression="zstd")
        else:
            plain = pa_csv.WriteOptions(quoting_style="none", quoting_header="none")
            try:
                pa_csv.write_csv(table, sink, plain)
            except pa.ArrowInvalid:  # an id with a comma or a quote: quote the text
                sink = pa.BufferOutputStream()
                pa_csv.write_csv(table, sink, pa_csv.WriteOptions(quoting_header="none"))
        write_atomic(path, sink.getvalue().to_pybytes())


def _float_array(values: np.ndarray):
    """A pyarrow float64 array over the values' own buffer (NaN kept as a value, as
    ``pa.array`` keeps it). Built from buffers because ``pa.array`` imports pandas (0.2 s a
    worker) to ask whether its argument is a pandas object."""
    import pyarrow as pa

    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(values), [None, pa.py_buffer(values)])


def _text_array(texts: list[str]):
    """A pyarrow string array of ``texts`` (UTF-8 bytes and their offsets; see
    ``_float_array``)."""
    import pyarrow as pa

    data = [t.encode() for t in texts]
    offsets = np.zeros(len(data) + 1, dtype=np.int32)
    np.cumsum([len(d) for d in data], out=offsets[1:])
    return pa.Array.from_buffers(
        pa.string(), len(data), [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(data))]
    )


def read_traffic(path: Path):
    """A run's traffic.csv (or its .parquet: ``runlog.written_as``) as a DataFrame (numbers
    as floats); InputError naming the file when it cannot be read, lacks a column or has text
    where numbers belong."""
    import pandas as pd

    from eoam_sumo.errors import InputError
    from eoam_sumo.sim.runlog import check_finite, written_as

    path = written_as(path)
    try:
        if path.suffix == ".parquet":
            frame = pd.read_parquet(path)
        else:
            frame = pd.read_csv(
                path,
                dtype={"id": str, "vclass": str, "role": str, **dict.fromkeys(_DECIMALS, float)},
                keep_default_na=False,
                na_values={c: ["", "nan"] for c in _DECIMALS},
            )
    except (OSError, ValueError, pd.errors.EmptyDataError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot be read as a run's traffic log: {exc}") from exc
    missing = [c for c in TRAFFIC_COLUMNS if c not in frame.columns]
    if missing:
        raise InputError(f"{path}: cannot be read as a run's traffic log: no column {missing[0]}")
    check_finite(path, frame, ("time_s", "x_m", "y_m"))
    return frame


def _within(bodies: Sequence[Body], ex: float, ey: float, r2: float) -> list[Body]:
    """The road users whose centre is within sqrt(``r2``) of (ex, ey), in their order."""
    near = []
    for b in bodies:
        _, _, x_m, y_m, _, _, _, _, _, _ = b  # see ``_BodyFields``
        if (x_m - ex) * (x_m - ex) + (y_m - ey) * (y_m - ey) <= r2:
            near.append(b)
    return near
