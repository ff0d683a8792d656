"""A study: the grid of one R157 scenario type, every point run for each driver (the EOAM and
the reference drivers), one row per run in ``results.csv``.

Grids (coarse, a few minutes per study; R157 Annex 4 App. 3 figures' axes):

* cut-in: initial gap x lateral speed, the cutting-in car ``relative_kmh`` slower;
* cut-out: distance from the lead's cut-out to the stopped car x lateral speed;
* deceleration: initial gap x the lead's deceleration."""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Iterable
from dataclasses import asdict, replace
from pathlib import Path

from eoam_sumo.fileio import write_atomic
from eoam_sumo.r157.scenario import R157Point, write_scenario
from eoam_sumo.sensing.radar import RadarSettings
from eoam_sumo.sim.settings import RunSettings

SPEEDS_KMH = (60.0, 100.0, 130.0)
CUT_IN_GAPS_M = (4.0, 8.0, 12.0, 16.0, 20.0, 30.0, 45.0)
CUT_IN_LATERAL_MPS = (0.5, 1.0, 1.5, 2.0, 3.0)
CUT_IN_RELATIVE_KMH = 20.0  # the cutting-in car's speed below the ego's (the study's choice)
CUT_OUT_GAPS_M = (20.0, 40.0, 60.0, 90.0)
CUT_OUT_LATERAL_MPS = (1.0, 2.0, 3.0)
DECEL_GAPS_S = (1.0, 1.6, 2.5)  # the lead's time gap (x the ego's speed)
DECELS_MPS2 = (3.0, 5.0, 7.0, 9.0)
MAX_TIME_S = 16.0
#: The radar of the studies: the project's forward radar with its near-range beam (40 m,
#: 90 deg), so that a car cutting in close ahead is seen from its first lateral move, as R157
#: assumes of the careful driver; the EOAM and the drivers see the same.
STUDY_RADAR = RadarSettings(near_range_m=40.0)
FIELDS = (
    "kind",
    "driver",
    "ego_kmh",
    "gap_m",
    "lateral_mps",
    "relative_kmh",
    "decel_mps2",
    "collision",
    "outcome",
    "collision_with",
    "impact_speed_mps",
    "min_gap_aro_m",
    "case_dir",
)


def grid(kind: str, speeds_kmh: Iterable[float] = SPEEDS_KMH) -> list[R157Point]:
    """The points of a study of ``kind``."""
    pts = []
    for v in speeds_kmh:
        if kind == "cut-in":
            pts += [
                R157Point(kind, v, g, lateral_mps=y, relative_kmh=CUT_IN_RELATIVE_KMH)
                for g in CUT_IN_GAPS_M
                for y in CUT_IN_LATERAL_MPS
            ]
        elif kind == "cut-out":
            pts += [
                R157Point(kind, v, g, lateral_mps=y)
                for g in CUT_OUT_GAPS_M
                for y in CUT_OUT_LATERAL_MPS
            ]
        else:
            pts += [
                R157Point(kind, v, round(h * v / 3.6, 2), decel_mps2=d)
                for h in DECEL_GAPS_S
                for d in DECELS_MPS2
            ]
    return pts


def run_study(
    points: list[R157Point],
    drivers: Iterable[str],
    out: Path,
    settings: RunSettings | None = None,
    progress: Callable[[str], None] | None = None,
    timeseries: str = "none",
) -> list[dict]:
    """Run every point for every driver under ``out``; write and return the rows (each run's
    summary.json, and with ``timeseries`` csv its time series and traffic log)."""
    from eoam_sumo.sim.cosim import run_case  # here: the command's parser needs none of it

    base = settings or RunSettings(max_time_s=MAX_TIME_S, radar=STUDY_RADAR)
    rows = []
    for point in points:
        cfg = write_scenario(point, out / "scenarios" / point.point_id)
        for driver in drivers:
            case_dir = out / "runs" / point.point_id / driver
            summary = run_case(
                cfg, None, case_dir, replace(base, driver=driver), timeseries=timeseries
            )
            rows.append(_row(point, driver, summary, case_dir.relative_to(out)))
            if progress is not None:
                progress(f"{point.point_id} {driver}: {summary['outcome']}")
    write_results(rows, out / "results.csv")
    return rows


def _row(point: R157Point, driver: str, summary: dict, case_dir: Path) -> dict:
    fields = asdict(point)
    return {
        **{k: fields[k] for k in FIELDS if k in fields},
        "driver": driver,
        "collision": summary["collision_with"] != "none",
        "outcome": summary["outcome"],
        "collision_with": summary["collision_with"],
        "impact_speed_mps": summary["impact_speed_mps"],
        "min_gap_aro_m": summary["min_gap_aro_m"],
        "case_dir": str(case_dir),
    }


def write_results(rows: list[dict], path: Path) -> Path:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, FIELDS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return write_atomic(path, buf.getvalue(), durable=True)


def read_results(path: Path) -> list[dict]:
    """``results.csv`` back, numbers as floats and ``collision`` as a bool."""
    with open(path, encoding="utf-8", newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in ("ego_kmh", "gap_m", "lateral_mps", "relative_kmh", "decel_mps2"):
            r[k] = float(r[k])
        r["collision"] = r["collision"] == "True"
    return rows


def eoam_fails_where_careful_avoids(rows: list[dict]) -> list[dict]:
    """The points R157's test fails: the careful driver avoids the collision, the EOAM not."""
    key = ("kind", "ego_kmh", "gap_m", "lateral_mps", "relative_kmh", "decel_mps2")
    careful = {tuple(r[k] for k in key): r for r in rows if r["driver"] == "r157-cc"}
    return [
        r
        for r in rows
        if r["driver"] == "eoam"
        and r["collision"]
        and tuple(r[k] for k in key) in careful
        and not careful[tuple(r[k] for k in key)]["collision"]
    ]
