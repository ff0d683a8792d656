"""Preallocated per-step log of a co-simulation run and its files (timeseries.csv, summary.json).

One entry per SUMO step, the step's values kept as a tuple in a preallocated list (no row
layout, numpy or pandas work in the loop); the rows and the float array are built once at the
end, pandas only when the run is written.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from eoam_sumo.errors import InputError

#: timeseries.csv columns (the paper's signals first, then the rest), SI units in the names.
COLUMNS = (
    "time_s", "mode", "fcw", "x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps", "yaw_rate_radps",
    "ax_mps2", "ay_mps2", "steer_rad", "ax_target_mps2", "y_target_m", "aro_range_m",
    "aro_range_rate_mps",
    "s_m", "lateral_offset_m", "heading_error_rad", "dx_m", "lateral_error_m",
    "lookahead_error_m", "steer_cmd_rad", "steer_ff_rad", "steer_fb_rad", "steer_yd_rad",
    "drive_force_n", "brake_force_n", "drive_force_cmd_n", "brake_force_cmd_n",
    "speed_target_mps", "mu", "oncoming_detected", "sector",
)
_INT_COLUMNS = ("mode", "fcw", "oncoming_detected")
_NAN = math.nan


PREALLOCATED_ROWS = 1 << 14  # 164 s of 10 ms steps; a longer run doubles the list as it goes


class RunLog:
    """Log of at most ``rows`` steps (preallocated up to ``PREALLOCATED_ROWS``, then grown by
    doubling, so that a huge time limit costs nothing up front); ``add`` keeps one step,
    ``array()`` / ``frame()`` give the table."""

    def __init__(self, rows: int):
        self._limit = rows
        self._rows: list = [None] * min(rows, PREALLOCATED_ROWS)
        self.n = 0
        self._col = {c: i for i, c in enumerate(COLUMNS)}
        self._array: np.ndarray | None = None

    def add(self, t, x, ax, ay, s, d, e_yaw, mu, cmd, perception) -> None:
        """Log the state ``x`` at time ``t`` with the command decided from it (None at the end).

        The arguments are kept as given (``x`` copied) and laid out as a row by ``array``: the
        step loop pays for one tuple. ``cmd`` and ``perception`` are immutable named tuples."""
        if self.n >= len(self._rows):
            if self.n >= self._limit:
                return
            self._rows.extend([None] * min(len(self._rows), self._limit - self.n))
        self._rows[self.n] = (t, tuple(x), ax, ay, s, d, e_yaw, mu, cmd, perception)
        self.n += 1
        self._array = None

    def array(self) -> np.ndarray:
        """(n, len(COLUMNS)) float array of the rows logged so far."""
        if self._array is None:
            rows = [_row(*args) for args in self._rows[: self.n]]
            self._array = np.array(rows, dtype=float).reshape(-1, len(COLUMNS))
        return self._array

    def column(self, name: str) -> np.ndarray:
        return self.array()[:, self._col[name]]

    def max_abs(self, name: str) -> float:
        col = self.column(name)
        col = col[np.isfinite(col)]
        return float(np.max(np.abs(col))) if col.size else 0.0

    def frame(self):
        import pandas as pd

        df = pd.DataFrame(self.array(), columns=COLUMNS)
        for c in _INT_COLUMNS:
            df[c] = df[c].astype("Int64")
        df["sector"] = [chr(int(v)) if np.isfinite(v) else "" for v in df["sector"]]
        return df


def _row(t, x, ax, ay, s, d, e_yaw, mu, cmd, perception) -> tuple:
    """One timeseries row (COLUMNS order) from what ``RunLog.add`` kept."""
    nan = _NAN
    if perception is not None and perception.aro_range_m is not None:
        rng, rate = perception.aro_range_m, perception.aro_range_rate_mps
    else:
        rng = rate = nan
    onc = float(perception.oncoming_detected) if perception is not None else nan
    if cmd is None:
        return (t, nan, nan, *x[:6], ax, ay, x[6], nan, nan, rng, rate, s, d, e_yaw,
                *(nan,) * 7, x[7], x[8], nan, nan, nan, mu, onc, nan)
    return (
        t, cmd.mode, float(cmd.fcw), x[0], x[1], x[2], x[3], x[4], x[5], ax, ay, x[6],
        cmd.ax_target_mps2, cmd.y_target_m, rng, rate, s, d, e_yaw, cmd.dx_m,
        cmd.lateral_error_m, cmd.lookahead_error_m, cmd.steer_cmd_rad, cmd.steer_ff_rad,
        cmd.steer_fb_rad, cmd.steer_yd_rad, x[7], x[8], cmd.drive_force_cmd_n,
        cmd.brake_force_cmd_n, cmd.speed_target_mps, mu, onc,
        float(ord(cmd.sector)) if cmd.sector else nan,
    )


def read_timeseries(path: Path, columns: list[str] | None = None):
    """A run's timeseries.csv as a DataFrame (``columns`` only, if given): InputError naming
    the file when it is missing, empty, cut short or not numbers where numbers belong."""
    import pandas as pd

    try:
        frame = pd.read_csv(path, usecols=columns)
    except (OSError, ValueError, pd.errors.EmptyDataError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot be read as a run's time series: {exc}") from exc
    numeric = [c for c in frame.columns if c != "sector"]
    if frame.empty or not all(pd.api.types.is_numeric_dtype(frame[c]) for c in numeric):
        raise InputError(f"{path}: cannot be read as a run's time series: no rows, or a row "
                         "cut short")
    return frame


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def write_run(out_dir: Path, summary: dict, log: RunLog, timeseries: str = "csv") -> None:
    """Write the time series (``timeseries.csv``, ``timeseries.parquet`` through pyarrow, or
    none) then ``summary.json`` (each atomically) into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    if timeseries == "csv":
        csv = log.frame().to_csv(index=False, float_format="%.9g")
        _atomic_write_text(out_dir / "timeseries.csv", csv)
    elif timeseries == "parquet":
        tmp = out_dir / "timeseries.parquet.tmp"
        log.frame().to_parquet(tmp, index=False, engine="pyarrow", compression="zstd")
        os.replace(tmp, out_dir / "timeseries.parquet")
    elif timeseries != "none":
        raise InputError(f"time series format {timeseries!r} is not csv, parquet or none")
    _atomic_write_text(out_dir / "summary.json", json.dumps(summary, indent=2) + "\n")
