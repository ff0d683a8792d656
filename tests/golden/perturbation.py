"""How far Table 2 moves when it runs the way another machine runs it: the basis of the golden
tolerances (docs/reproducibility.md).

Another CPU, libm or BLAS changes a result in its last bits, and a closed loop of a thousand
steps carries such a change forward. This study makes that kind of change on purpose and
measures what it does to every figure the golden test compares:

- ``glibc``: the whole batch run again with glibc's AVX2 and FMA code paths switched off
  (``GLIBC_TUNABLES``), so libm's ``sin``, ``exp``, ``pow``... take the code another CPU takes;
- ``eps``: every entry speed scaled by ``1 + eps`` (``eps`` from 1e-15, a few ulps, up).

Each variant is compared with a reference run of the unchanged matrix at full precision
(``summary.json``'s figures, the whole 100 Hz time series, the times of the mode switches).
It prints a table: each compared figure, its golden tolerance and the largest deviation per
variant, and every case whose words (colour, partner, modes) changed.

    python -m tests.golden.perturbation --eps 1e-15 1e-12 1e-9 --glibc
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from tests.golden.table2_golden import (
    FIGURE_TOLERANCE,
    MATRIX,
    SERIES_TOLERANCE,
    SWITCH_SHIFT_S,
    WORDS,
    mode_switches,
)

SPEEDS_KMH = (165, 120, 90, 55)
#: glibc's CPU-feature code paths off: what a machine without AVX2 and FMA runs
GLIBC_SWITCH = "glibc.cpu.hwcaps=-AVX2_Usable,-FMA_Usable,-AVX2,-FMA"
TOLERANCES = {**FIGURE_TOLERANCE, **SERIES_TOLERANCE, "switch_time_s": SWITCH_SHIFT_S}


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


def _batch(matrix: Path, out: Path, jobs: int, env: dict | None = None) -> dict[str, Path]:
    """Run ``matrix`` through the command line into ``out``; each golden case id's folder."""
    cmd = [sys.executable, "-m", "eoam_sumo", "batch", str(matrix), "--out", str(out)]
    subprocess.run([*cmd, "--jobs", str(jobs)], check=True, capture_output=True, env=env)
    results = pd.read_csv(out / "results.csv")
    return {_golden_id(c): out / d for c, d in zip(results["case_id"], results["case_dir"])}


def _series_spread(a: pd.DataFrame, b: pd.DataFrame) -> dict[str, float]:
    """Per compared column, the largest difference of two runs' series over their common
    steps (0 where both are empty)."""
    n = min(len(a), len(b))
    out = {}
    for col in SERIES_TOLERANCE:
        diff = np.abs(a[col].to_numpy(float)[:n] - b[col].to_numpy(float)[:n])
        out[col] = float(np.nanmax(diff)) if n and not np.isnan(diff).all() else 0.0
    return out


def _case_spread(ref: Path, var: Path) -> tuple[dict[str, float], list[str]]:
    """The deviations of one case's variant from its reference, and its changed words."""
    sa = json.loads((ref / "summary.json").read_text())
    sb = json.loads((var / "summary.json").read_text())
    words = [f"{w}: {sa[w]} -> {sb[w]}" for w in WORDS if sa[w] != sb[w]]
    spread = {
        k: abs(float(sa[k]) - float(sb[k]))
        for k in FIGURE_TOLERANCE
        if sa.get(k) is not None and sb.get(k) is not None
    }
    ta, tb = pd.read_csv(ref / "timeseries.csv"), pd.read_csv(var / "timeseries.csv")
    spread.update(_series_spread(ta, tb))
    sw_a, sw_b = mode_switches(ta), mode_switches(tb)
    if [m for _, m in sw_a] != [m for _, m in sw_b]:
        words.append(f"mode switches {sw_a} -> {sw_b}")
    spread["switch_time_s"] = max((abs(x[0] - y[0]) for x, y in zip(sw_a, sw_b)), default=0.0)
    return spread, words


def spread(reference: dict[str, Path], variant: dict[str, Path]) -> tuple[dict, list[str]]:
    """Per compared figure, (largest deviation, its case) over Table 2; changed words."""
    worst: dict[str, tuple[float, str]] = {}
    changed = []
    for cid in sorted(reference):
        dev, words = _case_spread(reference[cid], variant[cid])
        changed += [f"{cid} {w}" for w in words]
        for k, v in dev.items():
            if v > worst.get(k, (-1.0, ""))[0]:
                worst[k] = (v, cid)
    return worst, changed


def _table(columns: dict[str, dict]) -> str:
    names = list(columns)
    lines = ["| figure | tolerance | " + " | ".join(names) + " |"]
    lines.append("|---|---|" + "---|" * len(names))
    for key, tol in TOLERANCES.items():
        cells = [f"{columns[n].get(key, (0.0, ''))[0]:.2g}" for n in names]
        lines.append(f"| {key} | {tol:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", type=float, nargs="*", default=[1e-15, 1e-12, 1e-9])
    ap.add_argument("--glibc", action="store_true", help="also run with AVX2/FMA off")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    columns, changed = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        reference = _batch(_matrix(work / "ref.toml", 0.0), work / "ref", args.jobs)
        variants = {f"eps {e:g}": (e, None) for e in args.eps}
        if args.glibc:
            variants["glibc switch"] = (0.0, {**os.environ, "GLIBC_TUNABLES": GLIBC_SWITCH})
        for i, (name, (eps, env)) in enumerate(variants.items()):
            run = _batch(_matrix(work / f"v{i}.toml", eps), work / f"v{i}", args.jobs, env)
            columns[name], words = spread(reference, run)
            changed += [f"{name}: {w}" for w in words]
    print(_table(columns))
    print("\n".join(changed) or "every word unchanged")
    return 0


if __name__ == "__main__":
    sys.exit(main())
