"""The task a batch worker runs: one matrix case through the co-simulation.

Kept apart from the runner so a worker process imports only what a case needs.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from eoam_sumo.matrix import Case

#: The files a case writes (``sim.runlog.write_run``), in the order they are written, by
#: ``--timeseries`` format.
TIMESERIES_FORMATS = ("csv", "parquet", "none")
CASE_FILES_OF = {"csv": ("timeseries.csv", "summary.json"),
                 "parquet": ("timeseries.parquet", "summary.json"),
                 "none": ("summary.json",)}
ALL_CASE_FILES = ("timeseries.csv", "timeseries.parquet", "summary.json")
#: Modules a worker imports before its first case, so start-up is not charged to a case.
PRELOAD = ("eoam_sumo.sim.cosim",)


@dataclass(frozen=True)
class CaseTask:
    """One case to run. ``case_dir`` None: run in a scratch folder and return the files'
    bytes (for Dask workers that may not share the client's file system)."""

    case: Case
    case_dir: Path | None
    tables_dir: Path | None = None
    timeseries: str = "csv"  # csv, parquet or none


def case_parameters(case: Case) -> dict:
    """The case's matrix parameters, stored with its summary."""
    return {
        "case_id": case.case_id,
        "ego_speed_kmh": case.ego_speed_kmh,
        "mu": case.mu,
        "oncoming_start_m": case.oncoming_start_m,
        "aro_hold_s": case.aro_hold_s,
        "aro_decel_mps2": case.aro_decel_mps2,
        "max_time_s": case.max_time_s,
        "radar_range_m": case.radar_range_m,
        "policy": case.policy,
        "v2x_range_m": case.v2x_range_m,
        "v2x_latency_s": case.v2x_latency_s,
        "v2x_loss": case.v2x_loss,
        "v2x_penetration": case.v2x_penetration,
        "mu_belief": case.mu_belief,
        "radar_model": case.radar_model,
        "seed": case.seed,
        "draw": case.draw,
        "sumocfg": str(case.sumocfg),
    }


def run_matrix_case(task: CaseTask) -> dict:
    """Run the case; ``{"summary": dict, "files": {name: bytes} or None}``.

    Old output files of the case are removed first, so a folder never mixes runs.
    """
    from eoam_sumo.sim.cosim import RunSettings, policy_settings, run_case
    from eoam_sumo.sim.radar import RadarSettings

    case = task.case
    settings = policy_settings(
        RunSettings(max_time_s=case.max_time_s, tables_dir=task.tables_dir,
                    mu_belief=case.mu_belief, radar_model=case.radar_model, seed=case.seed),
        case.policy, case.v2x_range_m, case.v2x_latency_s, case.v2x_loss, case.v2x_penetration)
    if case.radar_range_m is not None:
        settings = replace(settings, radar=RadarSettings(range_m=case.radar_range_m))
    extra = {"case": case_parameters(case)}
    if task.case_dir is not None:
        case_dir = Path(task.case_dir)
        case_dir.mkdir(parents=True, exist_ok=True)
        for name in ALL_CASE_FILES:
            (case_dir / name).unlink(missing_ok=True)
        summary = run_case(case.sumocfg, case.overrides(), case_dir, settings, extra=extra,
                           timeseries=task.timeseries)
        return {"summary": summary, "files": None}
    with tempfile.TemporaryDirectory(prefix="eoam-case-") as scratch:
        summary = run_case(case.sumocfg, case.overrides(), Path(scratch), settings, extra=extra,
                           timeseries=task.timeseries)
        files = {name: (Path(scratch) / name).read_bytes()
                 for name in CASE_FILES_OF[task.timeseries]}
    return {"summary": summary, "files": files}
