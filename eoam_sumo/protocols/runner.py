"""A protocol run: its scenarios, one batch through the batch engine, results.csv, the
scorecard (markdown and PNG)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from eoam_sumo.batch.results import SUMMARY_COLUMNS
from eoam_sumo.batch.runner import run_cases
from eoam_sumo.fileio import write_atomic
from eoam_sumo.matrix import Case
from eoam_sumo.params import VehicleParams, ego_e_class_sedan
from eoam_sumo.protocols import scoring
from eoam_sumo.protocols.points import TestPoint
from eoam_sumo.protocols.scenario import write_scenarios
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

RESULTS_FILE = "results.csv"
SCORECARD_MD = "scorecard.md"
SCORECARD_PNG = "scorecard.png"
BATCH_DIR = "batch"
#: results.csv: the protocol's columns, then the run's summary fields
PROTOCOL_COLUMNS = (
    "point_id",
    "protocol",
    "test",
    "ego_speed_kmh",
    "target_speed_kmh",
    "overlap",
    "gap_m",
    "target_decel_mps2",
    "target_offset_m",
    "range",
    "policy",
    "policy_side",
    "impact_speed_kmh",
    "colour",
    "points",
    "max_points",
    "verdict",
    "note",
    "status",
    "error",
    "case_dir",
)


@dataclass(frozen=True)
class ProtocolSummary:
    """What ``eoam-sumo protocol`` prints (:meth:`line`) and whether a point failed."""

    points: int
    run: int
    failed: int
    outside: int

    def line(self, out: Path) -> str:
        """The summary line, naming the files in the output folder ``out``."""
        return (
            f"{self.points} points, {self.run} run, {self.failed} failed, {self.outside} "
            f"outside the design range; {out / RESULTS_FILE}, {out / SCORECARD_MD}"
        )


def _design_low_kmh(tables_dir: Path | None, vehicle_id: str, params: VehicleParams) -> float:
    """The lowest speed of the VUT's lookup tables (refused in one line when it has none)."""
    from eoam_sumo.sim.vehicle import vehicle_tables

    tables = vehicle_tables(vehicle_id, params, tables_dir, cached=False)
    return tables.speed_grid_mps[0] * 3.6


def _case(
    point: TestPoint,
    cfg: Path,
    policy: str,
    mu: float,
    max_time_s: float,
    vehicle_id: str,
    params: VehicleParams,
) -> Case:
    return Case(
        point.point_id,
        cfg,
        point.ego_speed_kmh,
        mu,
        None,
        None,
        None,
        max_time_s,
        policy=point.policy or policy,
        abs_fitted=params.abs_fitted,
        esc_fitted=params.esc_fitted,
        vehicle=None if vehicle_id == DEFAULT_VEHICLE else vehicle_id,
    )


def run_protocol(
    name: str,
    points: list[TestPoint],
    out: Path,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    policy: str = "paper",
    mu: float = 1.0,
    vehicle: str = DEFAULT_VEHICLE,
    vehicle_id: str = DEFAULT_VEHICLE,
    params: VehicleParams | None = None,
    progress: bool = True,
    max_time_s: float = 40.0,
    tables_dir: Path | None = None,
) -> ProtocolSummary:
    """Write the scenarios, run the points inside the design range, score every point."""
    params = params or ego_e_class_sedan()
    low = _design_low_kmh(tables_dir, vehicle_id, params)
    runnable = [p for p in points if p.ego_speed_kmh >= low - 1e-9]
    cfgs = write_scenarios(points, out / "scenarios")
    cases = [
        _case(p, cfgs[p.point_id], policy, mu, max_time_s, vehicle_id, params) for p in runnable
    ]
    batch = run_cases(
        cases, out / BATCH_DIR, jobs, scheduler, progress=progress, tables_dir=tables_dir
    )
    frame = results_frame(points, batch, low, policy)
    frame["net_file"] = [_relative(v, out) for v in frame["net_file"]]
    write_atomic(out / RESULTS_FILE, frame.to_csv(index=False), durable=True)
    write_atomic(out / SCORECARD_MD, scorecard_markdown(name, frame, vehicle, mu, policy, low))
    from eoam_sumo.plotting.protocol_plots import plot_scorecard

    plot_scorecard(frame, out / SCORECARD_PNG, title=f"{name}: {vehicle}, mu {mu:g}")
    failed = int((frame["status"] == "failed").sum())
    return ProtocolSummary(len(frame), len(runnable), failed, len(points) - len(runnable))


def _relative(path, out: Path):
    """A file of the run relative to the output folder (results.csv then does not depend on
    where the protocol ran)."""
    if not isinstance(path, str) or not path:
        return path
    try:
        return str(Path(path).resolve().relative_to(out.resolve()))
    except ValueError:
        return path


def results_frame(
    points: list[TestPoint], batch: pd.DataFrame, low_kmh: float, policy: str
) -> pd.DataFrame:
    """One row per point: protocol columns, then the summary fields of its run."""
    by_id = {r["case_id"]: r for r in batch.to_dict("records")}
    rows = []
    for point in points:
        run = by_id.get(point.point_id)
        rows.append(_row(point, run, low_kmh, point.policy or policy))
    return pd.DataFrame(rows, columns=[*PROTOCOL_COLUMNS, *SUMMARY_COLUMNS])


def _row(point: TestPoint, run: dict | None, low_kmh: float, policy: str) -> dict:
    if run is None:
        note = scoring.OUTSIDE_DESIGN.format(v=point.ego_speed_kmh, low=low_kmh)
        row = scoring.point_row(point, None, note)
        return {
            **row,
            "point_id": point.point_id,
            "policy": policy,
            "status": "not_run",
            "error": "",
            "case_dir": "",
        }
    ok = run["status"] == "ok"
    impact: float | None = None
    if ok:
        mps = run["impact_speed_mps"]
        impact = 0.0 if mps is None or math.isnan(mps) else round(float(mps) * 3.6, 3)
    row = scoring.point_row(point, impact, "" if ok else "the run failed: " + str(run["error"]))
    summary = {c: run.get(c) for c in SUMMARY_COLUMNS}
    return {
        **summary,
        **row,
        "point_id": point.point_id,
        "policy": policy,
        "status": run["status"],
        "error": run.get("error") or "",
        "case_dir": f"{BATCH_DIR}/{run['case_dir']}",
    }


def scorecard_markdown(
    name: str, frame: pd.DataFrame, vehicle: str, mu: float, policy: str, low_kmh: float
) -> str:
    """The scorecard: edition, totals per test and overall, R152 verdicts, points not run,
    every failed point with its reason."""
    rows = frame.to_dict("records")
    lines = [
        f"# Scorecard: {name}",
        "",
        f"Edition: {scoring.EDITION[name]}.",
        "",
        f"Vehicle {vehicle}, friction {mu:g}, policy {policy} (head-on tests: both policies "
        "side by side). Colours and points per point in results.csv; docs/protocols.md.",
        "",
    ]
    lines += _totals_table(scoring.totals(rows))
    unscored = [r["point_id"] for r in rows if r["colour"] == scoring.NO_BAND]
    if unscored:
        lines += [
            f"Not scored (no band row for their VUT speed; run, impact speed in "
            f"results.csv, left out of the totals): {', '.join(unscored)}.",
            "",
        ]
    lines += _not_run_lines(rows, low_kmh) + _failed_lines(rows)
    return "\n".join(lines) + "\n"


def _totals_table(totals: list[dict]) -> list[str]:
    lines = ["| test | policy | rows | points | of | verdicts |", "|---|---|---|---|---|---|"]
    points = maxima = 0.0
    for t in totals:
        extra = ", ".join(
            f"{k} {t[k]}" for k in ("pass", "fail", "undetermined", "not_run") if k in t
        )
        if math.isnan(t["points"]):
            lines.append(
                f"| {t['test']} | {t['policy_side'] or '-'} | {t['rows']} | - | - | {extra} |"
            )
            continue
        points, maxima = points + t["points"], maxima + t["max_points"]
        lines.append(
            f"| {t['test']} | {t['policy_side'] or '-'} | {t['rows']} | "
            f"{t['points']:.3f} | {t['max_points']:.3f} | |"
        )
    if maxima:
        lines.append(f"| **overall** | | | **{points:.3f}** | **{maxima:.3f}** | |")
    return [*lines, ""]


def _not_run_lines(rows: list[dict], low_kmh: float) -> list[str]:
    out = [r for r in rows if r["status"] == "not_run"]
    if not out:
        return []
    ids = ", ".join(r["point_id"] for r in out)
    return [
        f"## Not run: outside the design range ({len(out)} points)",
        "",
        f"The lookup tables and DMM boundaries start at {low_kmh:g} km/h "
        "(offline/design.py speeds_kmh): a run below it is refused, so these points score "
        f"0 (counted in the totals): {ids}.",
        "",
    ]


def _failed_lines(rows: list[dict]) -> list[str]:
    bad = [
        r
        for r in rows
        if r["status"] == "failed"
        or r["colour"] in ("red", "brown", "orange", "yellow")
        or r["verdict"] in ("fail", "undetermined")
    ]
    if not bad:
        return ["No point short of full marks among those run.", ""]
    lines = [
        f"## Points short of full marks ({len(bad)})",
        "",
        "Cause: the scoring's note, why the EOAM did not do better, and the run's own account "
        "(results.csv `reason`).",
        "",
        "| point | impact km/h | colour / verdict | cause |",
        "|---|---|---|---|",
    ]
    lines += [
        f"| {r['point_id']} | {r['impact_speed_kmh']} | {r['colour'] or r['verdict']} "
        f"| {scoring.failure_cause(r)} |"
        for r in bad
    ]
    return [*lines, ""]
