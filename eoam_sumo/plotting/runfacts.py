"""What a run folder says about its scenario, for the plots: the friction the manoeuvre ran
on, the lane width and point of no return, the oncoming traffic, and titles wrapped to fit.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.params import LANE_CHANGE_HEIGHT_M, PONR_FRACTION
from eoam_sumo.sim.runlog import written_as
from eoam_sumo.sim.trafficlog import TRAFFIC_FILE


def manoeuvre_mu(summary: dict, ts: pd.DataFrame) -> tuple[float, str]:
    """(friction, what it is): the friction under the ego when the EOAM left mode 0 (the
    tables and the DMM use the friction under the ego), else the one at the start."""
    mode = ts["mode"].to_numpy(dtype=float)
    mu = ts["mu"].to_numpy(dtype=float)
    active = np.flatnonzero(np.isfinite(mode) & (mode != 0) & np.isfinite(mu))
    if active.size:
        return float(mu[active[0]]), "under the ego when the manoeuvre began"
    return float(summary["mu"]), "under the ego at the start"


def frictions_seen(ts: pd.DataFrame) -> list[float]:
    """The distinct frictions under the ego during the run, in order of first meeting."""
    mu = ts["mu"].to_numpy(dtype=float)
    mu = mu[np.isfinite(mu)]
    return [float(v) for v in pd.unique(np.round(mu, 6))]


def lane_width_m(summary: dict) -> tuple[float, bool]:
    """(the ego lane's width, whether the run recorded it): summaries of runs before the
    width was recorded give the paper's 3.5 m."""
    width = summary.get("lane_width_m")
    if isinstance(width, (int, float)) and math.isfinite(width) and width > 0:
        return float(width), True
    return LANE_CHANGE_HEIGHT_M, False


def point_of_no_return_m(width_m: float) -> float:
    """Lateral travel of the point of no return on a lane of ``width_m`` (paper sec. 8.1)."""
    return PONR_FRACTION * width_m


def oncoming_seen(run_dir: Path) -> bool:
    """The run had oncoming traffic: a road user with role ``oncoming`` in traffic.csv, or
    (a run without traffic.csv) the radar reported oncoming traffic at some step."""
    run_dir = Path(run_dir)
    traffic = written_as(run_dir / TRAFFIC_FILE)
    try:
        if traffic.is_file():
            roles = _column(traffic, "role")
            return bool((roles == "oncoming").any())
        flags = _column(written_as(run_dir / "timeseries.csv"), "oncoming_detected")
    except (OSError, ValueError, pd.errors.EmptyDataError, pd.errors.ParserError):
        return False
    return bool((flags == 1).any())


def _column(path: Path, name: str) -> pd.Series:
    """One column of a run's csv or parquet file."""
    if path.suffix == ".parquet":
        return pd.read_parquet(path, columns=[name])[name]
    return pd.read_csv(path, usecols=[name], dtype=str if name == "role" else None)[name]


def traffic_text(oncoming_start_m, saw_oncoming: bool) -> str:
    """How a run's oncoming traffic is named: the car the co-simulation added, else what the
    run saw of the scenario's own traffic."""
    if oncoming_start_m is not None and not (
        isinstance(oncoming_start_m, float) and math.isnan(oncoming_start_m)
    ):
        return f"oncoming from {oncoming_start_m:g} m"
    return "oncoming traffic" if saw_oncoming else "no oncoming"


def fit(text: str, width_in: float, fontsize: float) -> str:
    """``text`` wrapped onto lines that fit ``width_in`` inches at ``fontsize`` points (an
    average glyph is taken as 0.55 em wide); existing line breaks are kept."""
    chars = max(20, int(width_in * 72.0 / (0.55 * fontsize)))
    return "\n".join(textwrap.fill(line, chars) for line in text.split("\n"))
