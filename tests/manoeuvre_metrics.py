"""Manoeuvre-quality figures of a batch output folder (results.csv + cases/*/timeseries.csv).

    .venv/bin/python -m tests.manoeuvre_metrics OUT_DIR

- ``max_lane_change_error_m``: largest |lateral_error_m| in mode 2 (the table lane change);
- ``min_green_lane_change_gap_m``: smallest ``min_gap_aro_m`` of the green cases that changed
  lanes (mode 2 visited);
- ``max_mode3_drift_m``: largest growth of |lateral offset| after mode 3 began, over its value
  at the start of mode 3;
- ``red_at_mu_0_3_up``: red cases at mu >= 0.3.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd


def case_figures(case_dir: Path) -> dict:
    """The per-case figures from one ``timeseries.csv``."""
    ts = pd.read_csv(
        case_dir / "timeseries.csv", usecols=["mode", "lateral_offset_m", "lateral_error_m"]
    )
    lane_change = ts[ts["mode"] == 2]
    err = float(lane_change["lateral_error_m"].abs().max()) if len(lane_change) else 0.0
    drift = 0.0
    in_3 = (ts["mode"] == 3).to_numpy().nonzero()[0]
    if len(in_3):
        d = ts["lateral_offset_m"].iloc[in_3[0] :].abs()
        drift = float(d.max() - d.iloc[0])
    return {"max_lateral_error_m": err, "mode3_drift_m": drift}


def batch_figures(out_dir: Path) -> tuple[pd.DataFrame, dict]:
    """Per-case table and the summary figures of one batch folder."""
    res = pd.read_csv(out_dir / "results.csv")
    per = pd.DataFrame([case_figures(out_dir / c) for c in res["case_dir"]])
    res = pd.concat([res.reset_index(drop=True), per], axis=1)
    changed = res["modes_visited"].astype(str).str.split("-").apply(lambda m: "2" in m)
    green_lc = res[changed & (res["outcome"] == "green")]
    summary = {
        "max_lane_change_error_m": float(res["max_lateral_error_m"].max()),
        "min_green_lane_change_gap_m": float(green_lc["min_gap_aro_m"].min())
        if len(green_lc)
        else float("nan"),
        "max_mode3_drift_m": float(res["mode3_drift_m"].max()),
        "red_at_mu_0_3_up": int(((res["outcome"] == "red") & (res["mu"] >= 0.3)).sum()),
        "colours": res["outcome"].value_counts().to_dict(),
    }
    return res, summary


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir", type=Path)
    ap.add_argument("--cases", action="store_true", help="print the per-case figures too")
    args = ap.parse_args(argv)
    res, summary = batch_figures(args.out_dir)
    if args.cases:
        cols = [
            "case_id",
            "outcome",
            "impact_speed_mps",
            "min_gap_aro_m",
            "max_lateral_error_m",
            "mode3_drift_m",
            "modes_visited",
        ]
        print(res[cols].to_string(index=False))
    for k, v in summary.items():
        print(f"{k}: {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
