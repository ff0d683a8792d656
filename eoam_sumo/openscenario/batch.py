"""``eoam-sumo batch`` over an .xosc: every case of its variations, one run each.

Every case is read and compiled before any runs (a refusal names the case and the element,
as ``run`` does); the runs go through the batch's worker processes (libsumo runs one
simulation per process). ``DIR/results.csv``: one row per case, its parameters (columns
``param:NAME``) and its summary's fields; ``DIR/cases/<case_id>/``: the run's files.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from eoam_sumo.batch.pool import run_local
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.openscenario.checks import check_places
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.departures import check_departures
from eoam_sumo.openscenario.geometry import LaneMap
from eoam_sumo.openscenario.reader import read_scenario
from eoam_sumo.openscenario.variations import XoscBatch

RESULTS = "results.csv"
CASES = "cases"
FIRST = ("case_id", "status", "error", "outcome", "collision_with", "impact_speed_mps")


def case_id(index: int) -> str:
    return f"case{index:05d}"


def check_cases(batch: XoscBatch) -> None:
    """Read and compile every case, check its departure speeds and its places on its road
    (each road converted once): InputError naming the first case refused."""
    from eoam_sumo.openscenario.runner import ego_speed_range_mps, road_map
    from eoam_sumo.sim.settings import RunSettings

    roads: dict[Path, LaneMap] = {}
    ego_range = ego_speed_range_mps(RunSettings())  # the cases run on the default tables
    for k, params in enumerate(batch.cases):
        try:
            scenario = read_scenario(batch.scenario, params)
            plan = compile_plan(scenario)
            check_departures(scenario.root, plan, ego_range)
            if scenario.road not in roads:
                roads[scenario.road] = road_map(scenario.road)[1]
            check_places(scenario.root, plan.places, roads[scenario.road])
        except InputError as exc:
            raise InputError(f"{case_id(k)} ({_params_text(params)}): {exc}") from None


def _params_text(params: dict[str, str]) -> str:
    return " ".join(f"{k}={v}" for k, v in params.items()) or "declared values"


def run_xosc_case(task: dict) -> dict:
    """One case in a worker process: load, run, the summary (module level, for the pool)."""
    from dataclasses import replace

    from eoam_sumo.openscenario.runner import load, run_loaded
    from eoam_sumo.sim.settings import RunSettings

    settings = RunSettings(tables_dir=task["tables_dir"])
    if task["max_time_s"] is not None:
        settings = replace(settings, max_time_s=float(task["max_time_s"]))
    if task["system"] == "aeb":
        settings = replace(settings, eoam=replace(settings.eoam, steering_inhibited=True))
    loaded = load(Path(task["xosc"]), task["params"])
    out = Path(task["out"])
    out.mkdir(parents=True, exist_ok=True)
    return run_loaded(loaded, out, settings, task["mu"], task["timeseries"])


def run_batch(
    batch: XoscBatch, out: Path, jobs: int, timeout_s: float, timeseries: str, tables_dir
) -> list[dict]:
    """Run every case into ``out`` and write ``results.csv``; the rows."""
    common = {"xosc": str(batch.scenario), "system": batch.system, "mu": batch.mu,
              "max_time_s": batch.max_time_s, "tables_dir": tables_dir,
              "timeseries": timeseries}  # fmt: skip
    tasks = [
        (case_id(k), {**common, "params": params, "out": str(out / CASES / case_id(k))})
        for k, params in enumerate(batch.cases)
    ]
    params = {key: task["params"] for key, task in tasks}
    rows = []
    preload = ("eoam_sumo.openscenario.runner", "eoam_sumo.sim.cosim")
    for result in run_local(run_xosc_case, tasks, jobs, timeout_s, preload):
        row: dict = {
            "case_id": result.key,
            "status": "ok" if result.ok else "failed",
            "error": result.error or "",
        }
        row |= {f"param:{k}": v for k, v in params[result.key].items()}
        if result.ok:
            row |= {k: v for k, v in result.value.items() if not isinstance(v, dict | list)}
            row["modes_visited"] = " ".join(str(m) for m in result.value.get("modes_visited", []))
        rows.append(row)
    rows.sort(key=lambda r: r["case_id"])
    write_results(rows, out / RESULTS)
    return rows


def write_results(rows: list[dict], path: Path) -> Path:
    names = list(FIRST)
    for row in rows:
        names += [k for k in row if k not in names]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=names, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return write_atomic(path, buf.getvalue())
