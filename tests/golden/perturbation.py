"""How far Table 2 moves when its inputs move in their last bits: the basis of the golden
tolerances (docs/reproducibility.md).

Another CPU, libm or BLAS changes a result in its last bits, and a closed loop of a thousand
steps grows such a change. This study makes that kind of change on purpose: every entry speed
scaled by ``1 + eps`` (``eps`` from 1e-15, a few ulps, up), each case run again and compared
with the golden files. It prints, per ``eps``, the largest deviation of each key figure and
time-series column, and every case whose words (colour, partner, modes) changed.

    python -m tests.golden.perturbation --eps 1e-15 1e-12 1e-9
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import pandas as pd

from tests.golden.table2_golden import (
    EXPECTED,
    FIGURE_TOLERANCE,
    MATRIX,
    SERIES,
    WORDS,
    Table2Run,
    _read,
    _switches_of,
    cells,
    mode_switches,
    series_deviation,
)

SPEEDS_KMH = (165, 120, 90, 55)


def _matrix(path: Path, eps: float) -> Path:
    """Table 2's matrix with every entry speed scaled by ``1 + eps``."""
    text = MATRIX.read_text()
    speeds = ", ".join(repr(v * (1.0 + eps)) for v in SPEEDS_KMH)
    text = re.sub(r"ego_speed_kmh = \[[^\]]*\]", f"ego_speed_kmh = [{speeds}]", text)
    text = text.replace('sumocfg = "', f'sumocfg = "{MATRIX.parent.as_posix()}/', 1)
    text = text.replace('table = "', f'table = "{MATRIX.parent.as_posix()}/', 1)
    path.write_text(text)
    return path


def _golden_id(case_id: str) -> str:
    """The golden case id of a perturbed case (its speed rounded back)."""
    return re.sub(r"_v([0-9.e-]+)_", lambda m: f"_v{round(float(m.group(1)))}_", case_id)


def _note(worst: dict, where: dict, col: str, dev: float, cid: str) -> None:
    if dev > worst.get(col, 0.0):
        worst[col], where[col] = dev, cid


def _deviations(run: Table2Run) -> tuple[dict[str, float], dict[str, str], list[str]]:
    want_cells = {r["case_id"]: r for r in _read(EXPECTED).to_dict("records")}
    want_series = dict(iter(pd.read_csv(SERIES).groupby("case_id")))
    switches = {c: _switches_of(r["mode_switches"]) for c, r in want_cells.items()}
    worst: dict[str, float] = {}
    where: dict[str, str] = {}
    changed = []
    got = cells(run)
    dirs = dict(run.cases())
    for row in got.to_dict("records"):
        cid = _golden_id(row["case_id"])
        want = want_cells[cid]
        changed += [f"{cid} {c}: {want[c]} -> {row[c]}" for c in WORDS if want[c] != row[c]]
        for col in FIGURE_TOLERANCE:
            if want[col] != "" and row[col] != "":
                _note(worst, where, col, abs(float(row[col]) - float(want[col])), cid)
        ts = pd.read_csv(run.timeseries_path(dirs[row["case_id"]]))
        got_switches = mode_switches(ts)
        for (tw, _), (tg, _) in zip(switches[cid], got_switches):
            _note(worst, where, "switch_time_s", abs(tg - tw), cid)
        for col, dev in series_deviation(want_series[cid], ts, switches[cid]).items():
            _note(worst, where, col, dev, cid)
    return worst, where, changed


def main(argv: list[str] | None = None) -> int:
    from eoam_sumo.batch.runner import run_batch

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", type=float, nargs="+", default=[1e-15, 1e-12, 1e-9])
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    for eps in args.eps:
        with tempfile.TemporaryDirectory() as tmp:
            matrix = _matrix(Path(tmp) / "perturbed.toml", eps)
            out = Path(tmp) / "run"
            run = Table2Run(out, run_batch(matrix, out, jobs=args.jobs, progress=False))
            worst, where, changed = _deviations(run)
        print(f"eps {eps:g}:")
        print("\n".join(f"  {k} {v:.3g} ({where.get(k, '-')})" for k, v in worst.items()))
        print("\n".join(f"  {line}" for line in changed) or "  every word unchanged")
    return 0


if __name__ == "__main__":
    sys.exit(main())
