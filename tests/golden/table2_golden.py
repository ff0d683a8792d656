"""The golden Table 2: the 64 paper-policy cases reduced to colours, key figures and a digest
of every time series, so that a change in behaviour is seen, and a refactoring that was meant
to change nothing is proven to change nothing.

Regenerate deliberately (and explain each changed cell in the commit) with::

    .venv/bin/python -m tests.golden.table2_golden --update
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import tempfile
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]
MATRIX = REPO / "scenarios" / "table2.toml"
EXPECTED = Path(__file__).with_name("table2_expected.csv")
FIGURES = (
    "impact_speed_mps",
    "min_gap_aro_m",
    "max_lateral_offset_m",
    "sim_time_s",
    "contact_overlap",
    "delta_v_ego_mps",
    "min_gap_oncoming_m",
    "min_ttc_oncoming_s",
)
COLUMNS = (
    "case_id",
    "outcome",
    "collision_with",
    "collision_with_id",
    *FIGURES,
    "near_miss",
    "modes_visited",
    "timeseries_sha256",
)


def _figure(value) -> str:
    if value is None or value == "" or (isinstance(value, float) and math.isnan(value)):
        return ""
    return f"{float(value):.3f}"


def observed(out_dir: Path, jobs: int = 2) -> pd.DataFrame:
    """Run the Table 2 matrix into ``out_dir`` and reduce it to the golden columns."""
    from eoam_sumo.batch.runner import run_batch

    results = run_batch(MATRIX, out_dir, jobs=jobs, progress=False)
    rows = []
    for _, r in results.iterrows():
        case = out_dir / r["case_dir"]
        summary = json.loads((case / "summary.json").read_text())
        digest = hashlib.sha256((case / "timeseries.csv").read_bytes()).hexdigest()[:16]
        rows.append(
            {
                "case_id": r["case_id"],
                "outcome": summary["outcome"],
                "collision_with": summary["collision_with"],
                "collision_with_id": summary["collision_with_id"] or "",
                **{k: _figure(summary.get(k)) for k in FIGURES},
                "near_miss": str(summary["near_miss"]).lower(),
                "modes_visited": " ".join(str(m) for m in summary["modes_visited"]),
                "timeseries_sha256": digest,
            }
        )
    return pd.DataFrame(rows, columns=list(COLUMNS))


def expected() -> pd.DataFrame:
    return pd.read_csv(EXPECTED, dtype=str, keep_default_na=False)


def differences(got: pd.DataFrame, want: pd.DataFrame) -> list[str]:
    """One line per differing field: ``case column: expected -> observed``."""
    lines = []
    want_by_id = {r["case_id"]: r for _, r in want.iterrows()}
    got_by_id = {r["case_id"]: r for _, r in got.iterrows()}
    for cid in sorted(set(want_by_id) | set(got_by_id)):
        if cid not in got_by_id or cid not in want_by_id:
            lines.append(f"{cid}: {'missing' if cid not in got_by_id else 'unexpected'}")
            continue
        for col in COLUMNS[1:]:
            a, b = str(want_by_id[cid].get(col, "(none)")), str(got_by_id[cid][col])
            if a != b:
                lines.append(f"{cid} {col}: {a} -> {b}")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--update", action="store_true", help="rewrite the expected file")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        got = observed(Path(tmp), args.jobs)
    diff = differences(got, expected()) if EXPECTED.is_file() else ["(no expected file)"]
    print("\n".join(diff) if diff else "Table 2 identical to the golden file")
    if args.update:
        got.to_csv(EXPECTED, index=False, lineterminator="\n")
        print(f"wrote {EXPECTED}")
    return 0 if (args.update or not diff) else 1


if __name__ == "__main__":
    sys.exit(main())
