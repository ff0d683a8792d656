"""Table 2 at another SUMO step against the golden 10 ms files: the check that a study's SUMO
step (``STUDY_SUMO_STEP_S``) keeps the reference's colours and contact partners, and its
figures within the golden tolerances (``table2_golden.FIGURE_TOLERANCE``, mode switches
within ``SWITCH_SHIFT_S``).

    python -m tests.golden.step_check                      # the study step (0.05 s)
    python -m tests.golden.step_check --sumo-step-s 0.1 --jobs 2
    python -m tests.golden.step_check --cases 'onc-400_v120'   # the cases matching a regex

Prints every difference by kind and exits 1 when a colour, contact partner, hit id, near miss
or the modes visited change, or a figure or a mode switch leaves its tolerance; 0 otherwise.
``--series`` also prints the time series' differences at 10 Hz (for information: their
tolerances are set for another machine's rounding, not for another SUMO step).
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
    cell_differences,
    cells,
    series_differences,
)

KINDS = ("words", "figures", "switches")


def run_table2_at(out_dir: Path, sumo_step_s: float, jobs: int = 1, cases: str = "") -> Table2Run:
    """Table 2's cases (those whose id matches the regex ``cases``; all when empty) with SUMO
    at ``sumo_step_s``, into ``out_dir``."""
    from eoam_sumo.batch.runner import plan_batch, run_cases

    plan = plan_batch(MATRIX, sumo_step_s=sumo_step_s)
    chosen = [c for c in plan.cases if re.search(cases, c.case_id)]
    if not chosen:
        raise ValueError(f"no Table 2 case matches {cases!r}")
    return Table2Run(out_dir, run_cases(chosen, out_dir, jobs, progress=False))


def _kind(line: str) -> str:
    """The kind of one ``cell_differences`` line: ``words`` (a missing case too), ``figures``
    or ``switches``."""
    field = line.split(" ", 1)[-1].split(":", 1)[0]
    if field in FIGURE_TOLERANCE:
        return "figures"
    if field in WORDS or line.endswith((": missing", ": unexpected")):
        return "words"
    return "switches"


def step_differences(got: pd.DataFrame, want: pd.DataFrame) -> dict[str, list[str]]:
    """``cell_differences`` of the cases ``got`` holds, by kind (``KINDS``)."""
    want = want[want["case_id"].isin(set(got["case_id"]))]
    out: dict[str, list[str]] = {kind: [] for kind in KINDS}
    for line in cell_differences(got, want):
        out[_kind(line)].append(line)
    return out


def report(diff: dict[str, list[str]], sumo_step_s: float, n_cases: int) -> str:
    """The differences by kind and a closing verdict line."""
    titles = {
        "words": "colour, contact partner, hit id, near miss, modes visited",
        "figures": "figures outside the golden tolerances",
        "switches": "mode switches (moved by more than the golden's tolerance)",
    }
    lines = []
    for kind in KINDS:
        lines.append(f"{titles[kind]}: {len(diff[kind])}")
        lines += [f"  {line}" for line in diff[kind]]
    same = not any(diff.values())
    verdict = "keeps" if same else "does not keep"
    lines.append(
        f"Table 2 at a {sumo_step_s:g} s SUMO step ({n_cases} cases) {verdict} the golden 10 ms "
        "colours, partners and figures within the golden tolerances"
    )
    return "\n".join(lines)


def _parser() -> argparse.ArgumentParser:
    from eoam_sumo.sim.settings import STUDY_SUMO_STEP_S

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sumo-step-s", type=float, default=STUDY_SUMO_STEP_S)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--cases", default="", help="only the case ids matching this regex")
    ap.add_argument("--series", action="store_true", help="also print the 10 Hz series' diff")
    return ap


def main(argv: list[str] | None = None) -> int:
    from eoam_sumo.errors import InputError

    args = _parser().parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            run = run_table2_at(Path(tmp), args.sumo_step_s, args.jobs, args.cases)
        except (InputError, ValueError, re.error) as exc:
            print(f"step_check: {exc}", file=sys.stderr)
            return 2
        got = cells(run)
        diff = step_differences(got, _read(EXPECTED))
        print(report(diff, args.sumo_step_s, len(got)))
        if args.series:
            want = pd.read_csv(SERIES)
            lines = series_differences(run, want[want["case_id"].isin(set(got["case_id"]))])
            print(f"10 Hz series outside the series tolerances (information): {len(lines)}")
            print("\n".join(f"  {line}" for line in lines))
    return 1 if any(diff.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
