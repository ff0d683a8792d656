"""Outcome probabilities of a sampled batch: ``outcome_probabilities.csv``.

One group per combination of swept values (the case id without its ``_dNNN`` draw suffix);
in each, every outcome colour seen in the batch (and ``failed`` for draws that did not run)
with its count, the group's number of draws n, p = count / n and the Wilson 95 % interval
(:func:`eoam_sumo.sampling.wilson_interval`). The probabilities of a group sum to 1.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from eoam_sumo.batch.report import SETTINGS
from eoam_sumo.fileio import write_atomic
from eoam_sumo.sampling import wilson_interval

PROBABILITIES_FILE = "outcome_probabilities.csv"
OUTCOME_ORDER = ("none", "green", "unfinished", "yellow", "orange", "red")
FAILED = "failed"
#: Parameter columns that may identify a group (those constant within every group are kept).
GROUP_COLUMNS = (
    "road",
    "los",
    "lanes",
    "speed_limit_kmh",
    "curve_radius_m",
    "ego_speed_kmh",
    "mu",
    "oncoming_start_m",
    "aro_hold_s",
    "aro_decel_mps2",
    "max_time_s",
    "radar_range_m",
    "mu_belief",
    "radar_model",
    "after_stop_s",
)
_DRAW_SUFFIX = re.compile(r"_d\d+$")


def group_of(case_id: str) -> str:
    """The group (combination of swept values) of a draw's case id."""
    return _DRAW_SUFFIX.sub("", case_id)


def outcomes_of(results: pd.DataFrame) -> pd.Series:
    """Each case's outcome colour name; a case that did not finish ``failed``."""
    return results["outcome"].where(results["status"] == "ok", FAILED).fillna(FAILED)


def _group_columns(results: pd.DataFrame) -> list[str]:
    """``GROUP_COLUMNS``, then every other setting a matrix may sweep (``report.SETTINGS``:
    policy, driver, vehicle, ABS/ESC, V2X, SUMO step, ...) that the results hold."""
    extra = [s.column for s in SETTINGS if s.column not in GROUP_COLUMNS]
    return [c for c in (*GROUP_COLUMNS, *extra) if c in results]


def outcome_probabilities(results: pd.DataFrame) -> pd.DataFrame:
    """The outcome probabilities of a results frame (``runner.read_results``) of draws."""
    results = results.assign(group=results["case_id"].map(group_of), _outcome=outcomes_of(results))
    seen = set(results["_outcome"])
    order = [o for o in OUTCOME_ORDER if o != "unfinished" or o in seen]  # listed at 0 too
    order += sorted(seen - set(order) - {FAILED}) + ([FAILED] if FAILED in seen else [])
    keep = [
        c
        for c in _group_columns(results)
        if (results.groupby("group", sort=False)[c].nunique(dropna=False) <= 1).all()
    ]
    rows = []
    for group, draws in results.groupby("group", sort=False):
        n = len(draws)
        first = draws.iloc[0]
        for outcome in order:
            count = int((draws["_outcome"] == outcome).sum())
            low, high = wilson_interval(count, n)
            rows.append(
                {
                    "group": group,
                    **{c: first[c] for c in keep},
                    "outcome": outcome,
                    "count": count,
                    "n": n,
                    "p": count / n,
                    "ci_low": low,
                    "ci_high": high,
                }
            )
    return pd.DataFrame(rows)


def write_probabilities(out_dir: Path, results: pd.DataFrame) -> Path:
    """Write ``outcome_probabilities.csv`` (atomically) into ``out_dir``; return its path."""
    path = Path(out_dir) / PROBABILITIES_FILE
    write_atomic(path, outcome_probabilities(results).to_csv(index=False))
    return path
