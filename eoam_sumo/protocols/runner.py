"""A protocol run: its scenarios, one batch through the batch engine, results.csv, the
scorecard (markdown and PNG)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from eoam_sumo.batch.results import SUMMARY_COLUMNS
from eoam_sumo.batch.runner import run_cases
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.matrix import Case
from eoam_sumo.offline.tables import MIN_ENTRY_SPEED_KMH
from eoam_sumo.params import VehicleParams, ego_e_class_sedan
from eoam_sumo.protocols import rules, scoring
from eoam_sumo.protocols.impact import measure, steered
from eoam_sumo.protocols.points import PROTOCOLS, TestPoint, protocol_points
from eoam_sumo.protocols.scenario import write_scenarios
from eoam_sumo.protocols.scorecard import RunLabel, plot, scorecard_markdown
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

RESULTS_FILE = "results.csv"
SCORECARD_MD = "scorecard.md"
SCORECARD_PNG = "scorecard.png"
BATCH_DIR = "batch"
#: results.csv: the protocol's columns, then the run's summary fields
PROTOCOL_COLUMNS = (
    "point_id",
    "protocol",
    "system",
    "policy",
    "vehicle",
    "on_protocol",
    "sumo_step_s",
    "test",
    "ego_speed_kmh",
    "target_speed_kmh",
    "overlap",
    "gap_m",
    "target_decel_mps2",
    "target_offset_m",
    "range",
    "impact_speed_kmh",
    "speed_reduction_kmh",
    "manoeuvre",
    "colour",
    "points",
    "max_points",
    "verdict",
    "warning",
    "warning_lead_s",
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
    matrix: int = 0  # the protocol's points (0: as many as ``points``)
    off_protocol: str = ""  # why the run is no protocol condition ("": it is)
    scored: bool = True  # the protocol gives a score (Euro NCAP 2026), not verdicts per point

    def line(self, out: Path) -> str:
        """The summary line, naming the files in the output folder ``out``; a ``--points``
        subset is named a partial run (scored against the whole protocol)."""
        partial = ""
        if self.matrix > self.points:
            rest = (
                "the others counted as not run: not the protocol's score"
                if self.scored
                else "the verdicts are of the points run"
            )
            partial = (
                f"partial run: {self.points} of the protocol's {self.matrix} points "
                f"selected (--points), {rest}; "
            )
        off = f"{self.off_protocol}; " if self.off_protocol else ""
        return (
            f"{partial}{off}{self.points} points, {self.run} run, {self.failed} failed, "
            f"{self.outside} not run (below the design range); {out / RESULTS_FILE}, "
            f"{out / SCORECARD_MD}"
        )


def _design_low_kmh(tables_dir: Path | None, vehicle_id: str, params: VehicleParams) -> float:
    """The lowest entry speed the VUT runs at [km/h]: the design range's floor, or the lookup
    tables' lowest speed if lower (refused in one line when the VUT has no tables)."""
    from eoam_sumo.sim.vehicle import vehicle_tables

    tables = vehicle_tables(vehicle_id, params, tables_dir, cached=False)
    return min(MIN_ENTRY_SPEED_KMH, tables.speed_grid_mps[0] * 3.6)


def _case(
    point: TestPoint,
    cfg: Path,
    policy: str,
    mu: float,
    max_time_s: float,
    vehicle_id: str,
    params: VehicleParams,
    system: str = "aeb",
    sumo_step_s: float | None = None,
) -> Case:
    """The point's case; ``system`` aeb inhibits the EOAM's lane change; ``sumo_step_s``
    SUMO's step (None: the run's default)."""
    return Case(
        point.point_id,
        cfg,
        point.ego_speed_kmh,
        mu,
        None,
        None,
        None,
        max_time_s,
        policy=policy,
        abs_fitted=params.abs_fitted,
        esc_fitted=params.esc_fitted,
        vehicle=None if vehicle_id == DEFAULT_VEHICLE else vehicle_id,
        steering_inhibited=system == "aeb",
        sumo_step_s=sumo_step_s,
    )


def run_protocol(
    name: str,
    points: list[TestPoint],
    out: Path,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    policy: str = "paper",
    system: str = "aeb",
    mu: float = 1.0,
    vehicle: str = DEFAULT_VEHICLE,
    vehicle_id: str = DEFAULT_VEHICLE,
    params: VehicleParams | None = None,
    progress: bool = True,
    max_time_s: float = 40.0,
    tables_dir: Path | None = None,
    sumo_step_s: float | None = None,
) -> ProtocolSummary:
    """Write the scenarios, run the points inside the design range, score every point."""
    params = params or ego_e_class_sedan()
    low = _design_low_kmh(tables_dir, vehicle_id, params)
    runnable = [p for p in points if p.ego_speed_kmh >= low - 1e-9]
    cfgs = write_scenarios(points, out / "scenarios")
    cases = [
        _case(p, cfgs[p.point_id], policy, mu, max_time_s, vehicle_id, params, system, sumo_step_s)
        for p in runnable
    ]
    batch = run_cases(
        cases,
        out / BATCH_DIR,
        jobs,
        scheduler,
        progress=progress,
        tables_dir=tables_dir,
        meanwhile=_import_scorecard_plots,  # matplotlib, on a core the last points leave free
    )
    run = RunLabel(name, system, policy, vehicle, mu, low, params.width_m, vehicle_id)
    frame = results_frame(points, batch, run, out)
    frame["net_file"] = [_relative(v, out) for v in frame["net_file"]]
    write_atomic(out / RESULTS_FILE, frame.to_csv(index=False), durable=True)
    write_atomic(out / SCORECARD_MD, scorecard_markdown(frame, run))
    plot(frame, out / SCORECARD_PNG, run)
    failed = int((frame["status"] == "failed").sum())
    off = "" if rules.on_protocol_surface(mu) else rules.OFF_PROTOCOL.format(mu=mu)
    matrix = len(protocol_points(name, params.width_m))
    outside = len(points) - len(runnable)
    scored = name == PROTOCOLS[1]
    return ProtocolSummary(len(frame), len(runnable), failed, outside, matrix, off, scored)


def _import_scorecard_plots() -> None:
    import eoam_sumo.plotting.protocol_plots  # noqa: F401 - imported for scorecard.png


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
    points: list[TestPoint], batch: pd.DataFrame, run: RunLabel, out: Path
) -> pd.DataFrame:
    """One row per point: protocol columns, then the summary fields of its run."""
    by_id = {r["case_id"]: r for r in batch.to_dict("records")}
    rows = [_row(point, by_id.get(point.point_id), run, out) for point in points]
    return pd.DataFrame(rows, columns=[*PROTOCOL_COLUMNS, *SUMMARY_COLUMNS])


def _flag(value) -> bool:
    """A results.csv boolean (the batch reads every non-number column as text)."""
    return str(value).strip().lower() == "true"


def _facts(run: dict, width_m: float) -> scoring.RunFacts:
    """What the run did beside its impact (steered, left its lane, raised the FCW)."""
    return scoring.RunFacts(
        steered=steered(run.get("modes_visited", ""), float(run["time_in_next_lane_s"])),
        left_lane=rules.left_lane(
            _flag(run["left_road"]),
            float(run["max_lateral_offset_m"]),
            float(run["lane_width_m"]),
            width_m,
        ),
        fcw_raised=_flag(run["fcw_raised"]),
    )


def _row(point: TestPoint, run: dict | None, label: RunLabel, out: Path) -> dict:
    head = {
        "point_id": point.point_id,
        "system": label.system,
        "policy": label.policy,
        "vehicle": label.vehicle_id,
        "on_protocol": rules.on_protocol_surface(label.mu),
    }
    if run is None:
        note = scoring.OUTSIDE_DESIGN.format(v=point.ego_speed_kmh, low=label.low_kmh)
        row = scoring.point_row(point, None, note)
        return {**row, **head, "status": "not_run", "error": "", "case_dir": ""}
    summary = {c: run.get(c) for c in SUMMARY_COLUMNS}
    case_dir = f"{BATCH_DIR}/{run['case_dir']}"
    if run["status"] != "ok":
        note = "the run failed: " + str(run["error"])
        row = scoring.point_row(point, None, note, failed=True)
    else:
        contact = run.get("contact_time_s")
        measured = measure(out / case_dir, None if contact is None else float(contact))
        if measured is None:
            raise InputError(f"{out / case_dir}: no timeseries.csv to measure the impact from")
        row = scoring.point_row(point, measured, "", _facts(run, label.width_m))
    return {
        **summary,
        **row,
        **head,
        "sumo_step_s": run.get("sumo_step_s"),
        "status": run["status"],
        "error": run.get("error") or "",
        "case_dir": case_dir,
    }
