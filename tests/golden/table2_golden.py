"""The golden Table 2: what the 64 paper-policy cases must show on any machine, and a strict
same-machine digest of every time series.

Three committed files, all written by ``--update`` from one run of ``scenarios/table2.toml``:

- ``table2_expected.csv``: each case's colour, contact partner, modes, near miss, key figures
  and mode switches (``mode@time_s``). The words must match exactly, the figures within
  ``FIGURE_TOLERANCE``, the switches in the same order within ``SWITCH_SHIFT_S``.
- ``table2_series.csv``: each case's time series at 10 Hz (``SERIES_COLUMNS``). A run matches
  when every reference sample is met, within ``SERIES_TOLERANCE``, by the run's own 100 Hz
  series no more than ``SHIFT_S`` away in time (a switch of mode one or two steps later moves a
  jump in acceleration or steering by as much), over the whole run: every choice the EOAM makes
  from the state is continuous in it (the return's length is found by root-finding, not on a
  grid), so a last-bit change stays in the last bits to the end (docs/reproducibility.md).
- ``table2_digests.csv``: SHA-256 of each case's ``timeseries.csv`` as written (9 significant
  digits). Byte identity holds only on the machine and install that recorded it (``--strict``;
  ``make golden-strict``), the check for a refactoring meant to change nothing.

docs/reproducibility.md says what is bit-identical where, and how the tolerances were chosen.

    python -m tests.golden.table2_golden              # the tolerant check (as make test)
    python -m tests.golden.table2_golden --strict     # byte identity of every time series
    python -m tests.golden.table2_golden --record-digests   # this machine's digests only
    python -m tests.golden.table2_golden --update     # all three files (explain each change)
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
MATRIX = REPO / "scenarios" / "table2.toml"
EXPECTED = HERE / "table2_expected.csv"
SERIES = HERE / "table2_series.csv"
DIGESTS = HERE / "table2_digests.csv"

#: Key figures of summary.json and how far another machine may move them (absolute, SI).
FIGURE_TOLERANCE = {
    "impact_speed_mps": 0.05,
    "min_gap_aro_m": 0.02,
    "max_lateral_offset_m": 0.02,
    "sim_time_s": 0.05,
    "contact_overlap": 0.05,  # contact found one 1 ms sub-step later: up to about 0.015
    "delta_v_ego_mps": 0.05,
    "min_gap_oncoming_m": 0.05,
    "min_ttc_oncoming_s": 0.05,
}
#: Words that must be equal everywhere.
WORDS = ("outcome", "collision_with", "collision_with_id", "near_miss", "modes_visited")
CELL_COLUMNS = (
    "case_id",
    *WORDS[:3],
    *FIGURE_TOLERANCE,
    *WORDS[3:],
    "mode_switches",
)

#: Time-series columns kept at 10 Hz and how far another machine may move them (absolute, SI).
SERIES_TOLERANCE = {
    "x_m": 0.05,
    "y_m": 0.05,
    "yaw_rad": 0.005,
    "vx_mps": 0.05,
    "vy_mps": 0.02,
    "yaw_rate_radps": 0.01,
    "ax_mps2": 0.2,
    "steer_rad": 0.002,
    "lateral_offset_m": 0.02,
    "aro_range_m": 0.05,
}
SERIES_COLUMNS = ("case_id", "time_s", *SERIES_TOLERANCE)
SAMPLE_EVERY = 10  # rows of the 100 Hz series: 10 Hz
SHIFT_S = 0.03  # how far in time a reference sample may be met [s]
SWITCH_SHIFT_S = 0.05  # how far in time a switch of mode may move [s]
STEP_S = 0.01  # the co-simulation's step [s]


@dataclass(frozen=True)
class Table2Run:
    """One run of the matrix: the results table and where its case folders are."""

    out_dir: Path
    results: pd.DataFrame

    def summary(self, case_dir: str) -> dict:
        return json.loads((self.out_dir / case_dir / "summary.json").read_text())

    def timeseries_path(self, case_dir: str) -> Path:
        return self.out_dir / case_dir / "timeseries.csv"

    def cases(self):
        return ((r["case_id"], r["case_dir"]) for _, r in self.results.iterrows())


def run_table2(out_dir: Path, jobs: int = 2) -> Table2Run:
    """Run the Table 2 matrix into ``out_dir`` at the 10 ms reference step (a study's default
    is a longer one: ``tests/golden/step_check.py`` compares it)."""
    from eoam_sumo.batch.runner import run_batch
    from eoam_sumo.sim.settings import REFERENCE_SUMO_STEP_S

    results = run_batch(
        MATRIX, out_dir, jobs=jobs, progress=False, sumo_step_s=REFERENCE_SUMO_STEP_S
    )
    return Table2Run(out_dir, results)


def _figure(value) -> str:
    if value is None or value == "" or (isinstance(value, float) and math.isnan(value)):
        return ""
    return f"{float(value):.3f}"


def cells(run: Table2Run) -> pd.DataFrame:
    """Each case's words and key figures, as ``table2_expected.csv`` holds them."""
    rows = []
    for case_id, case_dir in run.cases():
        s = run.summary(case_dir)
        rows.append(
            {
                "case_id": case_id,
                "outcome": s["outcome"],
                "collision_with": s["collision_with"],
                "collision_with_id": s["collision_with_id"] or "",
                **{k: _figure(s.get(k)) for k in FIGURE_TOLERANCE},
                "near_miss": str(s["near_miss"]).lower(),
                "modes_visited": " ".join(str(m) for m in s["modes_visited"]),
                "mode_switches": _switches_text(mode_switches(_mode_series(run, case_dir))),
            }
        )
    return pd.DataFrame(rows, columns=list(CELL_COLUMNS))


def _mode_series(run: Table2Run, case_dir: str) -> pd.DataFrame:
    return pd.read_csv(run.timeseries_path(case_dir), usecols=["time_s", "mode"])


def _switches_text(switches: list[tuple[float, int]]) -> str:
    return " ".join(f"{m}@{t:.2f}" for t, m in switches)


def _switches_of(text: str) -> list[tuple[float, int]]:
    pairs = (item.split("@") for item in text.split())
    return [(float(t), int(m)) for m, t in pairs]


def _timeseries(run: Table2Run, case_dir: str) -> pd.DataFrame:
    columns = ["mode", *SERIES_COLUMNS[1:]]
    return pd.read_csv(run.timeseries_path(case_dir), usecols=columns)


def series(run: Table2Run) -> pd.DataFrame:
    """Every case's time series at 10 Hz, as ``table2_series.csv`` holds them."""
    parts = []
    for case_id, case_dir in run.cases():
        ts = _timeseries(run, case_dir)
        steps = np.rint(ts["time_s"].to_numpy() / STEP_S).astype(np.int64)
        part = ts[steps % SAMPLE_EVERY == 0].drop(columns="mode")
        part.insert(0, "case_id", case_id)
        parts.append(part)
    return pd.concat(parts, ignore_index=True)[list(SERIES_COLUMNS)]


def digests(run: Table2Run) -> pd.DataFrame:
    """SHA-256 (16 hex digits) of each case's ``timeseries.csv``."""
    rows = [
        {
            "case_id": case_id,
            "timeseries_sha256": hashlib.sha256(
                run.timeseries_path(case_dir).read_bytes()
            ).hexdigest()[:16],
        }
        for case_id, case_dir in run.cases()
    ]
    return pd.DataFrame(rows, columns=["case_id", "timeseries_sha256"])


def _read(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, dtype=str, keep_default_na=False)


def _by_case(frame: pd.DataFrame) -> dict[str, dict]:
    return {r["case_id"]: r for r in frame.to_dict("records")}


def _cases_differ(want: dict, got: dict) -> list[str]:
    missing = sorted(set(want) - set(got))
    extra = sorted(set(got) - set(want))
    return [f"{c}: missing" for c in missing] + [f"{c}: unexpected" for c in extra]


def _figure_differs(want: str, got: str, tolerance: float) -> bool:
    if want == "" or got == "":
        return want != got
    return abs(float(got) - float(want)) > tolerance + 1e-9


def cell_differences(got: pd.DataFrame, want: pd.DataFrame) -> list[str]:
    """One line per differing field: words exactly, figures within ``FIGURE_TOLERANCE``."""
    want_by, got_by = _by_case(want), _by_case(got)
    lines = _cases_differ(want_by, got_by)
    for cid in sorted(set(want_by) & set(got_by)):
        w, g = want_by[cid], got_by[cid]
        for col in WORDS:
            if str(w[col]) != str(g[col]):
                lines.append(f"{cid} {col}: {w[col]} -> {g[col]}")
        switches = (_switches_of(w["mode_switches"]), _switches_of(g["mode_switches"]))
        for col, tol in FIGURE_TOLERANCE.items():
            if _figure_differs(str(w[col]), str(g[col]), tol):
                lines.append(f"{cid} {col}: {w[col]} -> {g[col]} (tolerance {tol})")
        lines += [f"{cid} {line}" for line in switch_differences(*switches)]
    return lines


def mode_switches(frame: pd.DataFrame) -> list[tuple[float, int]]:
    """``(time_s, mode)`` of the first row and of every row whose mode differs from the last."""
    modes = frame["mode"].to_numpy(float)
    times = frame["time_s"].to_numpy(float)
    keep = np.ones(len(modes), dtype=bool)
    keep[1:] = modes[1:] != modes[:-1]
    keep &= ~np.isnan(modes)
    return [(float(t), int(m)) for t, m in zip(times[keep], modes[keep])]


def switch_differences(want: list, got: list) -> list[str]:
    """Differences of two cases' mode switches: the same modes in the same order, each switch
    within ``SWITCH_SHIFT_S``."""
    if [m for _, m in want] != [m for _, m in got]:
        return [f"modes switched {[m for _, m in want]} -> {[m for _, m in got]}"]
    lines = []
    for (tw, mode), (tg, _) in zip(want, got):
        if abs(tg - tw) > SWITCH_SHIFT_S + 1e-9:
            lines.append(f"switch to mode {mode} at {tw:.2f} s -> {tg:.2f} s")
    return lines


def _nearest_within(ref_t, ref_v, obs_t, obs_v) -> np.ndarray:
    """Per reference sample, the smallest deviation of an observed sample within ``SHIFT_S``
    (0 where both are NaN; inf where none lies that close in time)."""
    best = np.full(len(ref_t), np.inf)
    for i, (t, v) in enumerate(zip(ref_t, ref_v)):
        lo, hi = np.searchsorted(obs_t, [t - SHIFT_S - 1e-9, t + SHIFT_S + 1e-9])
        window = obs_v[lo:hi]
        if window.size == 0:
            continue
        if math.isnan(v):
            best[i] = 0.0 if np.isnan(window).any() else np.inf
        else:
            dev = np.abs(window[~np.isnan(window)] - v)
            best[i] = dev.min() if dev.size else np.inf
    return best


def series_deviation(reference: pd.DataFrame, observed: pd.DataFrame) -> dict[str, float]:
    """Per column, the largest deviation of one case's reference samples from its observed
    100 Hz series (``_nearest_within``), until the earlier end of the two (whose times the
    figures compare)."""
    until = min(float(reference["time_s"].iloc[-1]), float(observed["time_s"].iloc[-1]))
    reference = reference[reference["time_s"] <= until + 1e-9]
    ref_t = reference["time_s"].to_numpy(float)
    obs_t = observed["time_s"].to_numpy(float)
    out = {}
    for col in SERIES_TOLERANCE:
        ref_v, obs_v = reference[col].to_numpy(float), observed[col].to_numpy(float)
        dev = _nearest_within(ref_t, ref_v, obs_t, obs_v)
        out[col] = float(dev.max()) if dev.size else 0.0
    return out


def _case_series_differences(
    cid: str, reference: pd.DataFrame, observed: pd.DataFrame
) -> list[str]:
    lines = []
    for col, value in series_deviation(reference, observed).items():
        tol = SERIES_TOLERANCE[col]
        if value > tol + 1e-9:
            lines.append(f"{cid} {col}: off by {value:.4g} (tolerance {tol})")
    return lines


def series_differences(run: Table2Run, want: pd.DataFrame) -> list[str]:
    """One line per case and column that leaves its tolerance."""
    reference = dict(iter(want.groupby("case_id", sort=True)))
    observed = dict(run.cases())
    lines = _cases_differ(reference, observed)
    for cid in sorted(set(reference) & set(observed)):
        lines += _case_series_differences(
            cid,
            reference[cid].astype(dict.fromkeys(SERIES_COLUMNS[1:], float)),
            _timeseries(run, observed[cid]),
        )
    return lines


def digest_differences(got: pd.DataFrame, want: pd.DataFrame) -> list[str]:
    """Cases whose time series is not byte-identical to the recorded digest."""
    want_by, got_by = _by_case(want), _by_case(got)
    lines = _cases_differ(want_by, got_by)
    for cid in sorted(set(want_by) & set(got_by)):
        a, b = want_by[cid]["timeseries_sha256"], got_by[cid]["timeseries_sha256"]
        if a != b:
            lines.append(f"{cid} timeseries_sha256: {a} -> {b}")
    return lines


def tolerant_differences(run: Table2Run) -> list[str]:
    """What the golden files say must hold on any machine, and where the run differs."""
    return cell_differences(cells(run), _read(EXPECTED)) + series_differences(
        run, pd.read_csv(SERIES)
    )


def _write(frame: pd.DataFrame, path: Path) -> None:
    frame.to_csv(path, index=False, lineterminator="\n", float_format="%.7g")
    print(f"wrote {path}")


def _compiled() -> bool:
    from importlib import machinery

    from eoam_sumo.sim import cosim

    return isinstance(getattr(cosim.__spec__, "loader", None), machinery.ExtensionFileLoader)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--strict", action="store_true", help="byte identity (this machine)")
    mode.add_argument("--update", action="store_true", help="rewrite all three golden files")
    mode.add_argument("--record-digests", action="store_true", help="rewrite the digests")
    ap.add_argument("--expect-compiled", action="store_true", help="fail unless compiled")
    ap.add_argument("--jobs", type=int, default=2)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.expect_compiled and not _compiled():
        print("the step loop is not compiled (make compiled)", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        run = run_table2(Path(tmp), args.jobs)
        if args.update or args.record_digests:
            if args.update:
                _write(cells(run), EXPECTED)
                _write(series(run), SERIES)
            _write(digests(run), DIGESTS)
            return 0
        if args.strict:
            diff = digest_differences(digests(run), _read(DIGESTS))
        else:
            diff = tolerant_differences(run)
    kind = "byte-identical to" if args.strict else "within the tolerances of"
    print("\n".join(diff) if diff else f"Table 2 {kind} the golden files")
    return 1 if diff else 0


if __name__ == "__main__":
    sys.exit(main())
