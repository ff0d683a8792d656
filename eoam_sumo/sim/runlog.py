"""Preallocated per-step log of a co-simulation run and its files (timeseries.csv, road.csv,
summary.json).

One entry per SUMO step, the step's values kept as a tuple in a preallocated list (no row
layout, numpy or pandas work in the loop); the rows and the float array are built once at the
end, pandas only when the run is written.
"""

from __future__ import annotations

import json
import math
from operator import attrgetter
from pathlib import Path
from typing import NamedTuple

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic

#: timeseries.csv columns (the paper's signals first, then the rest), SI units in the names.
COLUMNS = (
    "time_s",
    "mode",
    "fcw",
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "ax_mps2",
    "ay_mps2",
    "steer_rad",
    "ax_target_mps2",
    "y_target_m",
    "aro_range_m",
    "aro_range_rate_mps",
    "s_m",
    "lateral_offset_m",
    "heading_error_rad",
    "dx_m",
    "lateral_error_m",
    "lookahead_error_m",
    "steer_cmd_rad",
    "steer_ff_rad",
    "steer_fb_rad",
    "steer_yd_rad",
    "drive_force_n",
    "brake_force_n",
    "drive_force_cmd_n",
    "brake_force_cmd_n",
    "speed_target_mps",
    "mu",
    "oncoming_detected",
    "sector",
)
_INT_COLUMNS = ("mode", "fcw", "oncoming_detected")
_NAN = math.nan


class InForce(NamedTuple):
    """What of the last command is still in force at the end state (its row): the mode and
    the DMM sector; the command's other columns are empty there."""

    mode: int
    sector: str


PREALLOCATED_ROWS = 1 << 14  # 164 s of 10 ms steps; a longer run doubles the list as it goes


class RunLog:
    """Log of at most ``rows`` steps (preallocated up to ``PREALLOCATED_ROWS``, then grown by
    doubling, so that a huge time limit costs nothing up front); ``add`` keeps one step,
    ``array()`` / ``frame()`` give the table."""

    def __init__(self, rows: int, brake_gains: tuple[float, ...]):
        """``brake_gains``: road brake force per bar of each wheel's pressure
        (``plant.stepping.brake_gains_n_per_bar`` of the ego)."""
        self._limit = rows
        self._brake_gains = brake_gains
        self._rows: list = [None] * min(rows, PREALLOCATED_ROWS)
        self.n = 0
        self._col = {c: i for i, c in enumerate(COLUMNS)}
        self._array: np.ndarray | None = None
        self._columns: dict[str, np.ndarray] = {}  # columns read before the whole table

    def add(self, meas, x, cmd, perception, mu) -> None:
        """Log the ego at ``meas`` (an ``EgoMeasurement``) with its plant state ``x`` (copied),
        the command decided from it (None at the end), the radar's view and the road's
        friction ``mu`` under the ego (``meas.mu`` is the friction the EOAM believed).

        The arguments are kept as given and laid out as a row by ``array``: the step loop pays
        for one tuple. ``meas``, ``cmd`` and ``perception`` are immutable named tuples."""
        if self.n >= len(self._rows):
            if self.n >= self._limit:
                return
            self._rows.extend([None] * min(len(self._rows), self._limit - self.n))
        self._rows[self.n] = (meas, tuple(x), cmd, perception, mu)
        self.n += 1
        self._array = None
        if self._columns:
            self._columns = {}

    def add_end(self, meas, x, in_force, mu) -> None:
        """Log the end state as ``add`` does with no command and no radar view, but with the
        mode and DMM sector in force: those of ``in_force``, the last command (None: none)."""
        held = None if in_force is None else InForce(in_force.mode, in_force.sector)
        self.add(meas, x, held, None, mu)

    def array(self) -> np.ndarray:
        """(n, len(COLUMNS)) float array of the rows logged so far."""
        if self._array is None:
            self._array = _table(self._rows[: self.n], self._brake_gains)
        return self._array

    def column(self, name: str) -> np.ndarray:
        """One column, without laying out the others while the whole table is not needed."""
        if self._array is not None:
            return self._array[:, self._col[name]]
        col = self._columns.get(name)
        if col is None:
            col = self._columns[name] = _column(self._rows[: self.n], name, self._brake_gains)
        return col

    def max_abs(self, name: str) -> float:
        col = self.column(name)
        col = col[np.isfinite(col)]
        return float(np.max(np.abs(col))) if col.size else 0.0

    def frame(self):
        return table_frame(self.array())

    def csv_text(self) -> str:
        """timeseries.csv's text (:func:`csv_text`)."""
        return csv_text(self.array())


def table_frame(array: np.ndarray):
    """The log's (n, len(COLUMNS)) array as a DataFrame: the integer columns as Int64 (empty
    where NaN), ``sector`` as its letter ("" where NaN)."""
    import pandas as pd

    df = pd.DataFrame(array, columns=COLUMNS)
    for c in _INT_COLUMNS:
        df[c] = df[c].astype("Int64")
    df["sector"] = [chr(int(v)) if np.isfinite(v) else "" for v in df["sector"]]
    return df


_SECTOR_INDEX = COLUMNS.index("sector")
_INT_INDEX = [COLUMNS.index(c) for c in _INT_COLUMNS]
_ROW_FORMAT = ",".join("%s" if c == "sector" else "%.9g" for c in COLUMNS)


def csv_text(array: np.ndarray) -> str:
    """The log's array as CSV text, byte for byte what ``table_frame(array).to_csv(index=False,
    float_format="%.9g")`` writes, one ``%`` per row instead of pandas' per-value formatting:
    numbers ``%.9g`` (an integer column's whole numbers print as integers, its -0 as 0), NaN
    empty, ``sector`` its letter."""
    lines = [",".join(COLUMNS)]
    for row in array.tolist():
        for i in _INT_INDEX:
            row[i] += 0.0  # Int64 writes -0.0 as 0
        code = row[_SECTOR_INDEX]
        row[_SECTOR_INDEX] = chr(int(code)) if math.isfinite(code) else ""
        lines.append((_ROW_FORMAT % tuple(row)).replace("nan", ""))
    return "\n".join(lines) + "\n"


#: Where each column comes from, by name: the plant state's index, or a field of the
#: ``EgoMeasurement``, of the ``Command`` (in the end state's row only the mode and sector in
#: force, an ``InForce``) or of the ``Perception`` (the radar's view: empty at the end, ranges
#: empty when nothing is in path); ``mu`` is the road's friction under the ego (the EOAM may
#: believe another).
_FROM_STATE = {
    "x_m": 0,
    "y_m": 1,
    "yaw_rad": 2,
    "vx_mps": 3,
    "vy_mps": 4,
    "yaw_rate_radps": 5,
    "steer_rad": 6,
    "drive_force_n": 7,
}
#: the plant states of the four wheels' pressures [bar] (``plant.model.PRESSURES``):
#: ``brake_force_n`` is the road brake force they apply (``plant.stepping.brake_gains_n_per_bar``)
_BRAKE_PRESSURES = (8, 9, 10, 11)
_FROM_MEAS = {
    "time_s": "time_s",
    "ax_mps2": "ax_mps2",
    "ay_mps2": "ay_mps2",
    "s_m": "s_m",
    "lateral_offset_m": "d_m",
    "heading_error_rad": "e_yaw_rad",
}
_FROM_CMD = {
    "mode": "mode",
    "fcw": "fcw",
    "ax_target_mps2": "ax_target_mps2",
    "y_target_m": "y_target_m",
    "dx_m": "dx_m",
    "lateral_error_m": "lateral_error_m",
    "lookahead_error_m": "lookahead_error_m",
    "steer_cmd_rad": "steer_cmd_rad",
    "steer_ff_rad": "steer_ff_rad",
    "steer_fb_rad": "steer_fb_rad",
    "steer_yd_rad": "steer_yd_rad",
    "drive_force_cmd_n": "drive_force_cmd_n",
    "brake_force_cmd_n": "brake_force_cmd_n",
    "speed_target_mps": "speed_target_mps",
}
_FROM_PERCEPTION = {
    "aro_range_m": "aro_range_m",
    "aro_range_rate_mps": "aro_range_rate_mps",
    "oncoming_detected": "oncoming_detected",
}
_SECTOR = "sector"  # the command's DMM sector letter, stored as its character code
_ROAD_MU = "mu"  # the road's friction under the ego


def _table(rows: list, brake_gains: tuple[float, ...]) -> np.ndarray:
    """The (n, len(COLUMNS)) float array of logged steps, each column filled by name: from
    each kind of logged value transposed once (``_transposed``), the rest by ``_column``."""
    out = np.full((len(rows), len(COLUMNS)), _NAN)
    whole = _transposed(rows, brake_gains) if rows else {}
    for i, name in enumerate(COLUMNS):
        col = whole.get(name)
        out[:, i] = _column(rows, name, brake_gains) if col is None else col
    return out


def _transposed(rows: list, brake_gains: tuple[float, ...]) -> dict[str, np.ndarray]:
    """The columns ``_column`` would give of the plant state, the brake force, the
    measurement, the command (but its mode and sector) and the radar's view, from one
    transpose of each (a kind whose values are not all of one named-tuple type is left out)."""
    state = list(zip(*[r[1] for r in rows]))
    cols = {name: np.array(state[k], dtype=float) for name, k in _FROM_STATE.items()}
    brake = np.zeros(len(rows))  # summed in sum()'s order: 0, then each wheel's force
    for g, i in zip(brake_gains, _BRAKE_PRESSURES):
        brake = brake + g * np.array(state[i], dtype=float)
    cols["brake_force_n"] = brake
    for names, fields in (
        (_FROM_MEAS, _fields_of([r[0] for r in rows])),
        (_FROM_PERCEPTION, _fields_of([r[3] for r in rows])),
        (
            {n: f for n, f in _FROM_CMD.items() if f not in InForce._fields},
            _fields_of([None if isinstance(r[2], InForce) else r[2] for r in rows]),
        ),
    ):
        if fields is not None:
            cols.update((n, np.array(fields[f], dtype=float)) for n, f in names.items())
    return cols


def _fields_of(values: list) -> dict[str, tuple] | None:
    """The fields of ``values`` by name, each a tuple over the rows (a None value: None in
    every field, which ``np.array(..., dtype=float)`` makes NaN); None unless every value
    that is not None is a named tuple of one type."""
    kind = next((type(v) for v in values if v is not None), None)
    names = getattr(kind, "_fields", None)
    if names is None or any(v is not None and type(v) is not kind for v in values):
        return None
    blank = (None,) * len(names)
    return dict(zip(names, zip(*[blank if v is None else v for v in values])))


def _column(rows: list, name: str, brake_gains: tuple[float, ...]) -> np.ndarray:
    """One column of the logged steps (``_table``'s, without the rest: a run's summary reads
    four of the 34)."""
    if name in _FROM_STATE:
        k = _FROM_STATE[name]
        return np.array([r[1][k] for r in rows], dtype=float)
    if name == "brake_force_n":
        pairs = tuple(zip(brake_gains, _BRAKE_PRESSURES))
        return np.array([sum(g * r[1][i] for g, i in pairs) for r in rows], dtype=float)
    if name in _FROM_MEAS:
        get = attrgetter(_FROM_MEAS[name])
        return np.array([get(r[0]) for r in rows], dtype=float)
    if name in _FROM_CMD:
        field = _FROM_CMD[name]
        if field in InForce._fields:  # the end state's row holds an InForce
            get = attrgetter(field)
            return np.array([_NAN if r[2] is None else get(r[2]) for r in rows], dtype=float)
        return np.array(
            [
                _NAN if r[2] is None or isinstance(r[2], InForce) else getattr(r[2], field)
                for r in rows
            ],
            dtype=float,
        )
    if name == _SECTOR:
        return np.array(
            [float(ord(r[2].sector)) if r[2] is not None and r[2].sector else _NAN for r in rows],
            dtype=float,
        )
    if name == _ROAD_MU:
        return np.array([r[4] for r in rows], dtype=float)
    field = _FROM_PERCEPTION[name]
    return np.array(
        [
            _NAN if r[3] is None or getattr(r[3], field) is None else getattr(r[3], field)
            for r in rows
        ],
        dtype=float,
    )


#: The columns a run writes finite in every row (the plant's state and its clock); a plot
#: or an animation of a time series with a NaN or an infinity there is refused.
FINITE_COLUMNS = ("time_s", "x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps", "yaw_rate_radps")


def written_as(path: Path) -> Path:
    """``path`` (a run's ``.csv``), or its ``.parquet`` beside it where the run wrote that
    (``--timeseries parquet``) and no ``.csv``."""
    path = Path(path)
    parquet = path.with_suffix(".parquet")
    return parquet if not path.exists() and parquet.exists() else path


def read_timeseries(path: Path, columns: list[str] | None = None):
    """A run's timeseries.csv (or its .parquet: ``written_as``) as a DataFrame (``columns``
    only, if given): InputError naming the file when it is missing, empty, cut short or not
    numbers where numbers belong, and naming the column and row of a non-finite value in
    ``FINITE_COLUMNS``."""
    import pandas as pd

    path = written_as(path)
    try:
        if path.suffix == ".parquet":
            frame = pd.read_parquet(path, columns=columns)
        else:
            frame = pd.read_csv(path, usecols=columns)
    except (OSError, ValueError, pd.errors.EmptyDataError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot be read as a run's time series: {exc}") from None
    numeric = [c for c in frame.columns if c != "sector"]
    if frame.empty or not all(pd.api.types.is_numeric_dtype(frame[c]) for c in numeric):
        raise InputError(
            f"{path}: cannot be read as a run's time series: no rows, or a row cut short"
        )
    check_finite(path, frame, FINITE_COLUMNS)
    return frame


def check_finite(path: Path, frame, columns: tuple[str, ...]) -> None:
    """InputError naming the file, column, value and row (1 = the first after the header)
    of the first non-finite value in ``columns`` (those of the frame's)."""
    for column in (c for c in columns if c in frame.columns):
        values = frame[column].to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            row = int(bad[0])
            raise InputError(
                f"{path}: column {column} is {values[row]} in row {row + 1} (line {row + 2}); "
                "a run writes it finite in every row"
            )


def write_run(
    out_dir: Path,
    summary: dict,
    log: RunLog,
    timeseries: str = "csv",
    traffic=None,
    centreline=None,
) -> None:
    """Write the time series (``timeseries.csv``, ``timeseries.parquet`` through pyarrow, or
    none), the traffic log (a ``TrafficLog``, if given, in the same format: ``traffic.csv``
    or ``traffic.parquet``), the road frame's ``centreline`` (if given, with a time series:
    ``road.csv``, :func:`write_road`) then ``summary.json`` (each atomically) into
    ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    if timeseries == "csv":
        write_atomic(out_dir / "timeseries.csv", log.csv_text())
    elif timeseries == "parquet":
        data = log.frame().to_parquet(None, index=False, engine="pyarrow", compression="zstd")
        write_atomic(out_dir / "timeseries.parquet", data)
    elif timeseries != "none":
        raise InputError(f"time series format {timeseries!r} is not csv, parquet or none")
    if traffic is not None and timeseries != "none":
        traffic.write(out_dir / f"traffic.{timeseries}")
    if centreline is not None and timeseries != "none":
        write_road(out_dir / ROAD_FILE, centreline)
    write_atomic(out_dir / "summary.json", json.dumps(summary, indent=2) + "\n")


#: The road frame's centre line: the ego's start lane followed along its route, the line the
#: run's stations and lateral offsets (``s_m``, ``lateral_offset_m``) and traffic.csv's roles
#: are measured from (``sim.roadframe``), so that a plot can place every road user in it.
ROAD_FILE = "road.csv"
ROAD_COLUMNS = ("s_m", "x_m", "y_m")


def write_road(path: Path, centreline) -> None:
    """The centre line's vertices (an (N, 2) sequence of x, y in network coordinates) as CSV:
    ``s_m, x_m, y_m``, the station from the line's start (mm precision)."""
    from eoam_sumo.sim.roadframe import arclength

    xy = np.asarray(centreline, dtype=float).reshape(-1, 2)
    rows = [",".join(ROAD_COLUMNS)]
    rows += [f"{s:.3f},{x:.3f},{y:.3f}" for s, (x, y) in zip(arclength(xy), xy)]
    write_atomic(Path(path), "\n".join(rows) + "\n")


def read_road(path: Path) -> np.ndarray:
    """The (N, 2) vertices of a run's road.csv; InputError naming the file when it cannot be
    read, lacks a column or has fewer than two points."""
    import pandas as pd

    try:
        frame = pd.read_csv(path, dtype=float)
        xy = frame[["x_m", "y_m"]].to_numpy(dtype=float)
    except (OSError, KeyError, ValueError, pd.errors.EmptyDataError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot be read as a run's road centre line: {exc}") from exc
    if len(xy) < 2 or not np.isfinite(xy).all():
        raise InputError(
            f"{path}: cannot be read as a run's road centre line: fewer than two points, "
            "or a value that is not a number"
        )
    return xy
