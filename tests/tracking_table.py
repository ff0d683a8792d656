"""The lane change on the chassis plant: how far each Table 2 lane change runs off its
plan, and how close it passes the obstacle, for every catalogue vehicle with ABS on and off.

For each vehicle x ABS x friction x speed of Table 2 (no oncoming car: the lane changes the
DMM chooses; the oncoming columns add aborts) it runs the case and writes, per cell, the
largest |lateral error| in mode 2 (the ego's offset less the plan's, ``lateral_error_m``),
the smallest gap to the obstacle (``min_gap_aro_m``), the colour and the modes visited:
``tracking.csv`` and ``tracking.md`` (one table, a cell reads ``error / gap``, or ``brake``
where no lane change was begun) in ``--out``.

    python -m tests.tracking_table --out /tmp/tracking [--vehicles sedan compact] [--jobs 1]
    python -m tests.tracking_table --summary DIR1/tracking.csv DIR2/tracking.csv ...

``--summary`` prints, from the ``tracking.csv`` of earlier runs (one vehicle each, say), the
table docs/control.md shows: per vehicle x ABS x friction, the worst lane change's error (and
its speed) and the least gap to the obstacle over the lane changes.

One run takes a few seconds; the whole table (6 vehicles x 2 x 16) about a quarter of an hour
of one core. Tables are looked up as a run does (``tables/NAME``, ``-abs``/``-noabs``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.batch.runner import run_batch

REPO = Path(__file__).resolve().parents[1]
VEHICLES = ("sedan", "sedan-r13h", "compact", "suv", "van", "pickup")
SPEEDS_KMH = (165, 120, 90, 55)
MUS = (1.0, 0.7, 0.3, 0.1)


def write_matrix(path: Path, vehicles, speeds, mus) -> Path:
    """Table 2's no-oncoming column for each vehicle with ABS off and on."""
    names = ", ".join(f'"{v}"' for v in vehicles)
    path.write_text(
        "[scenario]\n"
        f'sumocfg = "{(REPO / "scenarios" / "baseline.sumocfg").as_posix()}"\n'
        "max_time_s = 60.0\n"
        "[sweep]\n"
        f"vehicle = [{names}]\n"
        'abs = ["off", "on"]\n'
        f"ego_speed_kmh = [{', '.join(str(v) for v in speeds)}]\n"
        f"mu = [{', '.join(str(m) for m in mus)}]\n"
        'oncoming_start_m = ["none"]\n'
    )
    return path


def lane_change_error_m(case_dir: Path) -> float:
    """The largest |lateral_error_m| while in mode 2 (NaN when mode 2 was never entered)."""
    ts = pd.read_csv(case_dir / "timeseries.csv", usecols=["mode", "lateral_error_m"])
    errors = ts.loc[ts["mode"] == 2, "lateral_error_m"].abs()
    return float(errors.max()) if len(errors) else float("nan")


def measure(results: pd.DataFrame, out: Path) -> pd.DataFrame:
    """One row per case: vehicle, abs, mu, speed, error, gap, colour, modes."""
    rows = []
    for _, r in results.iterrows():
        ok = r["status"] == "ok"
        rows.append(
            {
                "vehicle": r["vehicle"],
                "abs": "on" if str(r["abs_fitted"]).lower() in ("true", "1") else "off",
                "mu": r["mu"],
                "ego_speed_kmh": r["ego_speed_kmh"],
                "lane_change_error_m": lane_change_error_m(out / r["case_dir"]) if ok else np.nan,
                "min_gap_aro_m": r.get("min_gap_aro_m", np.nan),
                "outcome": r.get("outcome", r["status"]),
                "modes_visited": r.get("modes_visited", ""),
            }
        )
    return pd.DataFrame(rows)


def _cell(row: pd.Series) -> str:
    if not np.isfinite(row["lane_change_error_m"]):
        return f"brake ({row['outcome']})"
    return f"{row['lane_change_error_m']:.2f} / {row['min_gap_aro_m']:.2f} ({row['outcome']})"


def markdown(table: pd.DataFrame) -> str:
    """Rows vehicle x ABS x mu, columns the speeds; a cell: error / gap [m] (colour)."""
    speeds = sorted(table["ego_speed_kmh"].unique(), reverse=True)
    head = "| vehicle | ABS | mu | " + " | ".join(f"{v:g} km/h" for v in speeds) + " |"
    lines = [head, "|" + "---|" * (3 + len(speeds))]
    for (veh, abs_, mu), grp in table.groupby(["vehicle", "abs", "mu"], sort=False):
        by_speed = grp.set_index("ego_speed_kmh")
        cells = [_cell(by_speed.loc[v]) if v in by_speed.index else "" for v in speeds]
        lines.append(f"| {veh} | {abs_} | {mu:g} | " + " | ".join(cells) + " |")
    finite = table["lane_change_error_m"].dropna()
    lines.append("")
    lines.append(
        f"Lane changes: {len(finite)}; worst error {finite.max():.3f} m; within 0.25 m: "
        f"{int((finite <= 0.25).sum())}."
    )
    return "\n".join(lines) + "\n"


def summary(table: pd.DataFrame) -> str:
    """Rows vehicle x ABS, columns the frictions; a cell: worst error [m] (its speed, the
    number of lane changes) / least gap [m] over that friction's lane changes (- none)."""
    mus = sorted(table["mu"].unique(), reverse=True)
    head = "| vehicle | ABS | " + " | ".join(f"mu {m:g}" for m in mus) + " | worst |"
    lines = [head, "|" + "---|" * (3 + len(mus))]
    for (veh, abs_), grp in table.groupby(["vehicle", "abs"], sort=False):
        cells = [_summary_cell(grp[grp["mu"] == m]) for m in mus]
        lines.append(f"| {veh} | {abs_} | " + " | ".join(cells) + f" | {_summary_cell(grp)} |")
    lines.append("")
    lines.append(
        "A cell: worst mode-2 |lateral error| [m] (at km/h, of n lane changes) / least gap "
        "to the obstacle [m] over those lane changes; bold: over 0.25 m."
    )
    return "\n".join(lines) + "\n"


def _summary_cell(rows: pd.DataFrame) -> str:
    changes = rows[np.isfinite(rows["lane_change_error_m"].astype(float))]
    if changes.empty:
        return "-"
    worst = changes.loc[changes["lane_change_error_m"].idxmax()]
    err = f"{worst['lane_change_error_m']:.2f}"
    if worst["lane_change_error_m"] > 0.25:
        err = f"**{err}**"
    gap = changes["min_gap_aro_m"].min()
    return f"{err} ({worst['ego_speed_kmh']:g}, {len(changes)}) / {gap:.2f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--summary", nargs="+", type=Path, metavar="CSV")
    ap.add_argument("--vehicles", nargs="+", default=list(VEHICLES))
    ap.add_argument("--speeds-kmh", nargs="+", type=float, default=list(SPEEDS_KMH))
    ap.add_argument("--mu", nargs="+", type=float, default=list(MUS))
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    if args.summary:
        print(summary(pd.concat([pd.read_csv(f) for f in args.summary])), end="")
        return 0
    if args.out is None:
        ap.error("--out is required (or --summary)")
    args.out.mkdir(parents=True, exist_ok=True)
    matrix = write_matrix(args.out / "tracking.toml", args.vehicles, args.speeds_kmh, args.mu)
    runs = args.out / "runs"
    results = run_batch(matrix, runs, jobs=args.jobs, progress=False, resume=runs.exists())
    table = measure(results, runs)
    table.to_csv(args.out / "tracking.csv", index=False)
    text = markdown(table)
    (args.out / "tracking.md").write_text(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
