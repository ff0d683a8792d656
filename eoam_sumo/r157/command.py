"""``eoam-sumo r157-study --type cut-in|cut-out|deceleration --out DIR``: the study's runs,
``DIR/results.csv``, the chart ``DIR/r157_<type>.png`` and a one-line verdict per speed."""

from __future__ import annotations

import sys
from pathlib import Path

from eoam_sumo.drivers import DRIVERS
from eoam_sumo.errors import InputError
from eoam_sumo.outputs.staging import OutputKind, output_folder
from eoam_sumo.r157.scenario import TYPES
from eoam_sumo.r157.study import SPEEDS_KMH, eoam_fails_where_careful_avoids, grid, run_study

R157_OUTPUT = OutputKind(
    "r157-study",
    ("results.csv", "runs", "scenarios"),
    foreign=("batch", "scorecard.md", "scorecard.png", "cases", "table2.md"),
)


def add_arguments(subparsers) -> None:
    p = subparsers.add_parser(
        "r157-study",
        help="UN R157 Annex 4 App. 3 study: the EOAM beside the careful driver",
        description="Run an R157 scenario type over its grid for each driver, write "
        "results.csv and the chart (docs/reference-drivers.md).",
    )
    p.add_argument("--type", dest="kind", choices=TYPES, required=True, help="scenario type")
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument(
        "--speeds-kmh",
        default=",".join(f"{v:g}" for v in SPEEDS_KMH),
        help="ego speeds, comma-separated (60,100,130)",
    )
    p.add_argument(
        "--drivers", default="eoam,r157-cc", help="drivers, comma-separated (eoam,r157-cc)"
    )


def _parse(args) -> tuple[list[float], list[str]]:
    try:
        speeds = [float(v) for v in args.speeds_kmh.split(",")]
    except ValueError:
        raise InputError(f"--speeds-kmh {args.speeds_kmh!r}: not comma-separated numbers") from None
    if not speeds or not all(20.0 <= v <= 175.0 for v in speeds):
        raise InputError(f"--speeds-kmh {args.speeds_kmh!r}: each must be in [20, 175]")
    if len(set(speeds)) < len(speeds):
        raise InputError(f"--speeds-kmh {args.speeds_kmh!r}: a speed given twice")
    drivers = [d.strip() for d in args.drivers.split(",") if d.strip()]
    bad = [d for d in drivers if d not in DRIVERS]
    if bad or not drivers:
        raise InputError(f"--drivers: {', '.join(bad) or 'none'} (choose from {DRIVERS})")
    if len(set(drivers)) < len(drivers):
        raise InputError(f"--drivers {args.drivers!r}: a driver given twice")
    return speeds, drivers


#: R157's test compares these two (Annex 4 App. 3: the system avoids what the careful driver does)
COMPARED = ("eoam", "r157-cc")


def verdict_lines(
    kind: str, speeds: list[float], drivers: list[str], failed: list[dict]
) -> list[str]:
    """Per speed, the points where the EOAM hits and the careful driver avoids (R157 Annex 4
    App. 3); without both drivers run, one line saying the study is not compared."""
    if not all(d in drivers for d in COMPARED):
        return [
            f"{kind}: not compared (R157's test needs both drivers eoam and r157-cc; ran "
            f"{', '.join(drivers)}): no verdict"
        ]
    return [
        f"{kind} {v:g} km/h: the EOAM hits where the careful driver avoids at "
        f"{sum(1 for r in failed if r['ego_kmh'] == v)} points"
        for v in speeds
    ]


def run(args) -> int:
    from eoam_sumo.plotting.r157_plots import r157_figure

    speeds, drivers = _parse(args)
    points = grid(args.kind, speeds)
    with output_folder(args.out, R157_OUTPUT) as out:
        rows = run_study(points, drivers, out, progress=lambda s: print(s, file=sys.stderr))
        failed = eoam_fails_where_careful_avoids(rows)
        r157_figure(rows, args.kind, failed, out / f"r157_{args.kind.replace('-', '_')}.png")
    for line in verdict_lines(args.kind, speeds, drivers, failed):
        print(line)
    return 0
