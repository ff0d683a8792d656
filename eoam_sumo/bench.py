"""The performance benchmark (``eoam-sumo bench``): what users wait for, measured in one run.

Figures:
- ``realtime_factor``: simulated seconds per wall second of the co-simulation step loop for
  the 120 km/h, mu 1.0, no-oncoming case (plant at 1 ms, logging on), median of repeats;
- ``sumo_only_realtime_factor``: the same scenario stepped by SUMO alone, SUMO driving the ego;
- ``cosim_over_sumo_cost``: co-simulation step-loop cost over SUMO alone's, each co-simulation
  repeat paired with a SUMO-alone repeat right after it (median of the pairs);
- ``tables_wall_s``: a full ``eoam-sumo tables`` build with 2 jobs;
- ``batch_wall_s`` / ``batch_cases`` / ``jobs``: the Table 2 batch with 2 jobs;
- per-step costs of decision + control and of the plant, plant sub-steps per second;
- ``peak_rss_mb`` of one ``eoam-sumo run`` in its own process;
- ``floor_over_sumo_cost``: the least the co-simulation step can cost over SUMO alone's, on
  the same scenario: only the SUMO calls a step makes (the ego written back, SUMO's step with
  the subscriptions, their results, the getters of the vehicles around the ego) and the plant's
  C step, none of the sensing, decision, control, contact check or logging (median of paired
  runs, as the cost ratio);
- ``compiled``: whether the step loop ran compiled (setup.py) or from the Python sources;
- the traffic case (``traffic_scenario``: 3 lanes each way, the ego departing at 120 s behind a
  broken-down car, SUMO's step 0.5 s before that): ``traffic_vehicles`` in SUMO at the ego's
  departure, ``traffic_cosim_wall_s`` of the whole co-simulation run (SUMO's start, the time
  before the departure at 0.5 s, the manoeuvre at 10 ms), ``traffic_sumo_only_wall_s`` of
  SUMO alone stepping the same scenario at 10 ms for the same simulated time, and
  ``traffic_us_per_user_step``: the co-simulation's own cost per road user in SUMO per step
  (CPU time of the step loop less SUMO alone's for as many steps).

``--studies`` measures instead each study (:data:`STUDIES`: Table 2, the 2026 protocol, the
traffic levels, the vehicles, the 10 000-draw Monte Carlo) at SUMO steps (``run_studies``):
its wall and CPU time and the load average, and per step the step loop's cost split and its
cost ratio against SUMO alone at the same SUMO step; Table 2's colours, contact partners and
figures against the first step's.

``--against REV`` measures instead this tree against git revision ``REV`` in one run
(``compare_against``): the plant's step and the Table 2 batch, each in fresh interpreters that
alternate between the trees, and the ratios of this tree's figures over ``REV``'s.
"""

from __future__ import annotations

import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from eoam_sumo.errors import InputError
from eoam_sumo.sim.observers import StepObserver
from eoam_sumo.sim.settings import STUDY_SUMO_STEP_S

ROOT = Path(__file__).resolve().parents[1]
BASELINE = ROOT / "scenarios" / "baseline.sumocfg"
SCENARIOS = ROOT / "scenarios"
TABLE2 = SCENARIOS / "table2.toml"
SPEED_MPS = 120 / 3.6
TARGETS = {
    "realtime_factor": (">=", 100.0),
    "cosim_over_sumo_cost": ("<=", 5.0),
    "batch_wall_s": ("<=", 60.0),
    "tables_wall_s": ("<=", 60.0),
    "control_us_per_step": ("<=", 10.0),
    "peak_rss_mb": ("<=", 300.0),
    "traffic_cosim_over_sumo_only": ("<", 1.0),
    "traffic_us_per_user_step": ("<=", 2.0),
}
TRAFFIC_DEPART_S = 120.0  # the ego's departure in the traffic case (about 280 vehicles)


def _compiled() -> bool:
    """Whether the step loop runs compiled: its module imported from an extension module."""
    from importlib import machinery

    from eoam_sumo.sim import cosim

    return isinstance(getattr(cosim.__spec__, "loader", None), machinery.ExtensionFileLoader)


def _cosim_and_sumo_only(repeats: int, sumo_step_s: float | None = None) -> dict:
    """The co-simulation's step-loop figures and SUMO alone on the same scenario, measured in
    pairs (one co-simulation run, then SUMO alone for as long at the same SUMO step) so that
    both see the same machine load; medians over the repeats, the cost ratio the median of the
    pairs' ratios (also in CPU time, which other load disturbs far less). Per-step figures are
    per control step (10 ms)."""
    from eoam_sumo.sim.cosim import CoSimulation
    from eoam_sumo.sim.observers import PhaseTimer
    from eoam_sumo.sim.scenario import ScenarioOverrides
    from eoam_sumo.sim.settings import RunSettings

    over = ScenarioOverrides(ego_speed_mps=SPEED_MPS, mu=1.0)
    timer, loop_cpu = PhaseTimer(), _LoopCpu()
    settings = RunSettings(sumo_step_s=sumo_step_s)
    sim = CoSimulation(BASELINE, over, settings, observers=[timer, loop_cpu])
    runs, sumo_rates, cpu_ratios = [], [], []
    for _ in range(repeats):
        summary, _log = sim.run()
        prof = {
            "sense": timer.totals["sense"],
            "control": timer.totals["decide"],
            "plant": timer.totals["actuate"],
            "sumo": timer.totals["write_back"],
            "contact": timer.totals["check_contact"],
            "loop_wall_s": sim.loop_wall_s,
            "steps": timer.steps,
            "loop_cpu_s": loop_cpu.cpu_s,
        }
        prof["sim_time_s"] = summary["sim_time_s"]
        prof["wall_time_s"] = summary["wall_time_s"]
        runs.append(prof)
        rate, sumo_cpu_s = _sumo_only(summary["sim_time_s"], settings.sumo_step_length_s)
        sumo_rates.append(rate)
        cpu_ratios.append(loop_cpu.cpu_s / sumo_cpu_s)
    med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
    steps = med["steps"]
    substeps = sim.settings.substeps
    ratios = [so * r["loop_wall_s"] / r["sim_time_s"] for r, so in zip(runs, sumo_rates)]
    return {
        "realtime_factor": med["sim_time_s"] / med["loop_wall_s"],
        "realtime_factor_with_startup": med["sim_time_s"] / med["wall_time_s"],
        "cosim_sim_time_s": med["sim_time_s"],
        "cosim_steps": steps,
        "control_us_per_step": 1e6 * med["control"] / steps,
        "plant_us_per_step": 1e6 * med["plant"] / steps,
        "sense_us_per_step": 1e6 * med["sense"] / steps,
        "sumo_us_per_step": 1e6 * med["sumo"] / steps,
        "contact_us_per_step": 1e6 * med["contact"] / steps,
        "plant_substeps_per_s": substeps * steps / med["plant"],
        "sumo_only_realtime_factor": statistics.median(sumo_rates),
        "cosim_over_sumo_cost": statistics.median(ratios),
        "loop_cpu_us_per_step": 1e6 * med["loop_cpu_s"] / steps,
        "cosim_over_sumo_cpu_cost": statistics.median(cpu_ratios),
    }


def _sumo_only_rate(sim_time_s: float, step_s: float) -> float:
    """Simulated seconds per wall second of SUMO alone stepping the scenario for
    ``sim_time_s`` at ``step_s`` (the ego driven by SUMO, no co-simulation work)."""
    return _sumo_only(sim_time_s, step_s)[0]


def _sumo_only(sim_time_s: float, step_s: float) -> tuple[float, float]:
    """(:func:`_sumo_only_rate`, CPU time of those steps [s])."""
    from eoam_sumo.sim.scenario import ScenarioOverrides
    from eoam_sumo.sim.session import SumoSession

    steps = max(1, round(sim_time_s / step_s))
    session = SumoSession.start(
        BASELINE,
        ScenarioOverrides(ego_speed_mps=SPEED_MPS, mu=1.0),
        step_length_s=step_s,
    )
    try:
        t0, cpu0 = time.perf_counter(), time.thread_time()
        for _ in range(steps):
            session.step()
        cpu_s = time.thread_time() - cpu0
        return steps * step_s / (time.perf_counter() - t0), cpu_s
    finally:
        session.close()


def _floor_over_sumo(repeats: int, steps: int = 903) -> float:
    """``floor_over_sumo_cost`` (module doc): a straight drive at the bench's speed, each run
    paired with SUMO alone for as many steps right after it."""
    import libsumo

    from eoam_sumo.params import ego_e_class_sedan
    from eoam_sumo.plant import Plant, initial_state
    from eoam_sumo.sim.scenario import ScenarioOverrides
    from eoam_sumo.sim.session import SumoSession
    from eoam_sumo.sim.session.calls import StepCalls

    over = ScenarioOverrides(ego_speed_mps=SPEED_MPS, mu=1.0)
    advance = Plant(ego_e_class_sedan()).advance
    calls, u = StepCalls(libsumo), (0.0, 300.0, 0.0)
    ratios = []
    for _ in range(repeats):
        session = SumoSession.start(BASELINE, over)
        try:
            ego = session.ego_id
            session.nearby(100.0)  # the step's subscriptions, as the co-simulation sets them
            body = session.ego_body()  # heading east (nav angle 90)
            x = initial_state(body.x_m, body.y_m, 0.0, SPEED_MPS, drive_force_n=300.0).tolist()
            t0 = time.perf_counter()
            for _k in range(steps):
                x, _y = advance(x, u, 1.0)
                calls.move_to_xy(ego, "", -1, x[0] + 0.5 * body.length_m, x[1], 90.0, 2)
                calls.set_speed(ego, SPEED_MPS)
                calls.step(0.0)
                calls.vehicle_results()
                for vid in calls.context_results(ego):
                    if vid != ego:
                        calls.type_id(vid), calls.angle(vid), calls.speed(vid)
                        calls.stop_state(vid)
            floor_s = time.perf_counter() - t0
        finally:
            session.close()
        ratios.append(floor_s / (steps * 0.01 / _sumo_only_rate(steps * 0.01, 0.01)))
    return statistics.median(ratios)


class _LoopCpu(StepObserver):
    """CPU time of this thread over a run's step loop (SUMO's too: libsumo runs in-process),
    which other load on the machine disturbs far less than wall time."""

    cpu_s = 0.0

    def start(self, sim) -> None:
        self._t0 = time.thread_time()

    def end(self, sim) -> None:
        self.cpu_s = time.thread_time() - self._t0


def _traffic(tmp: Path, quick: bool) -> dict:
    """The traffic case: a co-simulation run and SUMO alone at 10 ms for as long. Our side's
    cost per road user and step: the step loop's CPU time less SUMO alone's for the same steps
    (the ego driven by SUMO), over the steps and the vehicles in SUMO at the departure."""
    import libsumo
    import sumolib

    from eoam_sumo.sim.cosim import CoSimulation
    from eoam_sumo.sim.scenario import ScenarioOverrides, check_scenario
    from eoam_sumo.sim.session.launch import sumo_command
    from eoam_sumo.sim.settings import RunSettings
    from eoam_sumo.traffic_scenario import write_traffic_scenario

    depart_s = 20.0 if quick else TRAFFIC_DEPART_S
    cfg = write_traffic_scenario(tmp / "traffic", ego_depart_s=depart_s)
    loop_cpu = _LoopCpu()
    sim = CoSimulation(cfg, ScenarioOverrides(), RunSettings(), observers=[loop_cpu])
    t0 = time.perf_counter()
    summary, _log = sim.run()
    cosim_wall_s = time.perf_counter() - t0
    depart_step = round(depart_s / 0.01)
    steps = depart_step + max(1, round(summary["sim_time_s"] / 0.01))
    cmd, _ = sumo_command(
        sumolib.checkBinary("sumo"),
        cfg,
        check_scenario(cfg).options,
        0.01,
        tmp / "traffic-errors.log",
        (),
        False,
    )
    t0 = time.perf_counter()
    libsumo.start(cmd)
    try:
        vehicles, cpu_depart = 0, time.thread_time()
        for k in range(steps):
            libsumo.simulationStep()
            if k == depart_step:
                vehicles = libsumo.vehicle.getIDCount()
                cpu_depart = time.thread_time()
        sumo_only_wall_s = time.perf_counter() - t0
        sumo_cpu_s = time.thread_time() - cpu_depart
    finally:
        libsumo.close()
    manoeuvre_steps = max(1, steps - depart_step - 1)
    return {
        "traffic_vehicles": vehicles,
        "traffic_cosim_wall_s": cosim_wall_s,
        "traffic_sumo_only_wall_s": sumo_only_wall_s,
        "traffic_cosim_over_sumo_only": cosim_wall_s / sumo_only_wall_s,
        "traffic_cosim_sim_time_s": summary["sim_time_s"],
        "traffic_us_per_user_step": 1e6
        * (loop_cpu.cpu_s - sumo_cpu_s)
        / (manoeuvre_steps * max(1, vehicles)),
    }


def _peak_rss_mb(out_dir: Path) -> float:
    """Peak resident memory of one ``eoam-sumo run`` (its own process, from wait4)."""
    cmd = [
        sys.executable,
        "-m",
        "eoam_sumo",
        "run",
        str(BASELINE),
        "--speed-kmh",
        "120",
        "--mu",
        "1.0",
        "--out",
        str(out_dir),
    ]
    err = out_dir.with_suffix(".stderr")
    with open(err, "wb") as sink:  # a file, not a pipe: a full pipe would block the child
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=sink)
        _pid, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"benchmark run failed: {err.read_text().strip()}")
    return usage.ru_maxrss / 1024.0  # kB on Linux


def _tables(out_dir: Path, quick: bool) -> float:
    from eoam_sumo.offline.build import build_tables

    t0 = time.perf_counter()
    if quick:
        build_tables(out_dir, jobs=2, speeds_kmh=[100.0, 120.0], mus=[1.0], progress=False)
    else:
        build_tables(out_dir, jobs=2, progress=False)
    return time.perf_counter() - t0


def _batch(out_dir: Path, quick: bool) -> tuple[float, int]:
    from eoam_sumo.batch.runner import run_batch

    matrix = _quick_matrix(out_dir) if quick else TABLE2
    t0 = time.perf_counter()
    results = run_batch(matrix, out_dir / "batch", jobs=2, progress=False)
    return time.perf_counter() - t0, len(results)


def _quick_matrix(out_dir: Path) -> Path:
    """A two-case matrix for quick runs (tests)."""
    matrix = out_dir / "quick.toml"
    matrix.write_text(
        f'[scenario]\nsumocfg = "{BASELINE.as_posix()}"\nmax_time_s = 20.0\n'
        "[sweep]\nego_speed_kmh = [120]\nmu = [1.0, 0.7]\n"
    )
    return matrix


def interpreter() -> dict:
    """The Python the benchmark runs on: implementation, version, executable, and whether its
    core is a shared libpython loaded at start (Linux: found in the process's memory map) or
    linked into the executable. The step loop spends about half its time in that core, so a
    study's time depends on how the interpreter was built (docs/performance.md)."""
    maps = Path("/proc/self/maps")
    shared = None
    if maps.exists():
        shared = any("libpython" in line for line in maps.read_text().splitlines())
    return {
        "implementation": sys.implementation.name,
        "version": platform.python_version(),
        "executable": sys.executable,
        "shared_libpython": shared,
    }


def interpreter_text(record: dict) -> str:
    """One line for the tables' heads, e.g. ``python: cpython 3.11.2 (/usr/bin/python3),
    core in the executable``."""
    core = {True: "shared libpython", False: "core in the executable", None: "core unknown"}
    return (
        f"python: {record['implementation']} {record['version']} ({record['executable']}), "
        f"{core[record['shared_libpython']]}"
    )


def run_bench(out_dir: Path, quick: bool = False) -> dict:
    """Measure every figure; ``quick`` uses tiny settings (one repeat, 2-case batch)."""
    repeats = 1 if quick else 15  # short runs on a shared machine: a median of many
    with tempfile.TemporaryDirectory(prefix="eoam-bench-") as tmp_dir:
        tmp = Path(tmp_dir)
        result: dict[str, Any] = {"quick": quick, "jobs": 2, "compiled": _compiled()}
        result["python"] = interpreter()
        result["peak_rss_mb"] = _peak_rss_mb(tmp / "rss")
        result.update(_cosim_and_sumo_only(repeats))
        result["floor_over_sumo_cost"] = _floor_over_sumo(repeats)
        result.update(_traffic(tmp, quick))
        result["tables_wall_s"] = _tables(tmp / "tables", quick)
        result["batch_wall_s"], result["batch_cases"] = _batch(tmp, quick)
    result["targets"] = {
        k: {"target": f"{op} {v:g}", "met": (result[k] >= v) if op == ">=" else (result[k] <= v)}
        for k, (op, v) in TARGETS.items()
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "bench.json").write_text(json.dumps(result, indent=2) + "\n")
    return result


def format_table(result: dict) -> str:
    rows = [
        (k, v)
        for k, v in result.items()
        if isinstance(v, (int, float)) and k not in ("quick", "compiled")
    ]
    width = max(len(k) for k, _ in rows)
    lines = [
        f"step loop: {'compiled' if result['compiled'] else 'Python sources'}",
        interpreter_text(result["python"]),
        f"{'figure':<{width}}  value        target",
    ]
    for k, v in rows:
        tgt = result["targets"].get(k)
        mark = "" if tgt is None else f"{tgt['target']:<9} {'met' if tgt['met'] else 'MISSED'}"
        lines.append(f"{k:<{width}}  {v:<12.4g} {mark}")
    return "\n".join(lines)


# --- the studies at SUMO steps (``eoam-sumo bench --studies``) --------------------------------

#: Table 2's figures compared with the reference step's (the golden Table 2's key figures).
TABLE2_FIGURES = (
    "impact_speed_mps",
    "min_gap_aro_m",
    "max_lateral_offset_m",
    "sim_time_s",
    "contact_overlap",
    "delta_v_ego_mps",
    "min_gap_oncoming_m",
    "min_ttc_oncoming_s",
)
_LOOP_KEYS = (
    "cosim_over_sumo_cost",
    "cosim_over_sumo_cpu_cost",
    "loop_cpu_us_per_step",
    "realtime_factor",
    "sumo_only_realtime_factor",
    "sumo_us_per_step",
    "sense_us_per_step",
    "control_us_per_step",
    "plant_us_per_step",
    "contact_us_per_step",
)


def _process_tree_cpu_s() -> float:
    """CPU time of this process and of its ended child processes (batch workers) [s]."""
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def load_average() -> list[float]:
    """The 1, 5 and 15 minute load averages (``os.getloadavg``); [] where there are none."""
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except OSError:
        return []


def _number(value) -> float | None:
    """A figure of results.csv as a float (None: empty or not a number)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def table2_changes(reference, other) -> dict:
    """``other``'s Table 2 (results frame) against ``reference``'s, case by case: the cases
    whose colour or contact partner changed, and each figure's largest absolute change (a
    figure empty on one side only is a colour or partner change, not a number)."""
    ref = {r["case_id"]: r for r in reference.to_dict("records")}
    got = {r["case_id"]: r for r in other.to_dict("records")}
    common = [c for c in ref if c in got]

    def changed(col: str) -> list[str]:
        return [
            f"{c}: {ref[c][col]} -> {got[c][col]}"
            for c in common
            if str(ref[c][col]) != str(got[c][col])
        ]

    deltas: dict[str, float] = {}
    for col in TABLE2_FIGURES:
        pairs = [(_number(ref[c].get(col)), _number(got[c].get(col))) for c in common]
        diffs = [abs(b - a) for a, b in pairs if a is not None and b is not None]
        deltas[col] = max(diffs, default=0.0)
    return {
        "cases": len(common),
        "colour_changes": changed("outcome"),
        "partner_changes": changed("collision_with"),
        "max_abs_delta": deltas,
    }


@dataclass(frozen=True)
class Study:
    """One study users run: a matrix file or a protocol, run as its command runs it, and the
    goal for its wall time on 2 cores [s] (docs/performance.md)."""

    source: str  # the matrix file, or the protocol's name
    goal_wall_s: float
    protocol: bool = False
    timeseries: str = "csv"


#: The studies ``bench --studies`` runs (``--study NAME``), the fewest runs first.
STUDIES = {
    "table2": Study(str(TABLE2), 5.0),
    "protocol": Study("euroncap-aeb-c2c-2026", 20.0, protocol=True),
    "traffic-levels": Study(str(SCENARIOS / "traffic_levels.toml"), 180.0, timeseries="none"),
    "vehicles": Study(str(SCENARIOS / "vehicles.toml"), 120.0),
    "monte-carlo": Study(str(SCENARIOS / "monte_carlo.toml"), 300.0, timeseries="none"),
}
#: ``--quick``: this many runs of each study, spread evenly over it (every len/N-th run).
QUICK_RUNS = 2


def check_studies(names) -> tuple[str, ...]:
    """The studies asked for, in order, without repeats (none: every study); InputError
    naming an unknown one."""
    for name in names:
        if name not in STUDIES:
            raise InputError(f"--study {name!r} is not one of {', '.join(STUDIES)}")
    return tuple(dict.fromkeys(names)) or tuple(STUDIES)


def _spread(items: list, quick: bool) -> list:
    """``items``, or with ``quick`` :data:`QUICK_RUNS` of them spread evenly."""
    return items[:: max(1, len(items) // QUICK_RUNS)][:QUICK_RUNS] if quick else items


def _matrix_study(study: Study, out: Path, step_s: float, jobs: int, quick: bool):
    """A matrix study as ``eoam-sumo batch`` runs it (its figures not drawn): (runs in the
    study, results frame)."""
    from dataclasses import replace

    from eoam_sumo.batch.output import BATCH_OUTPUT
    from eoam_sumo.batch.runner import plan_batch, run_batch
    from eoam_sumo.outputs.staging import output_folder

    plan = plan_batch(Path(study.source), sumo_step_s=step_s)
    total = len(plan.cases)
    plan = replace(plan, cases=_spread(plan.cases, quick))
    with output_folder(out, BATCH_OUTPUT) as folder:
        results = run_batch(
            Path(study.source),
            folder,
            jobs=jobs,
            progress=False,
            timeseries=study.timeseries,
            plan=plan,
        )
    return total, results


def _protocol_study(study: Study, out: Path, step_s: float, jobs: int, quick: bool):
    """A protocol study as ``eoam-sumo protocol NAME`` runs it (its own options): (points in
    the protocol, the rows of its results.csv)."""
    import argparse
    import csv

    from eoam_sumo.outputs.staging import output_folder
    from eoam_sumo.protocols import command
    from eoam_sumo.protocols.runner import RESULTS_FILE

    parser = argparse.ArgumentParser(prog="eoam-sumo")
    command.add_arguments(parser.add_subparsers())
    argv = ["protocol", study.source, "--out", str(out), "--jobs", str(jobs)]
    args = parser.parse_args([*argv, "--sumo-step-s", str(step_s), "--no-progress"])
    points = command.selected_points(args)
    with output_folder(out, command.PROTOCOL_OUTPUT) as folder:
        command.run_points(args, _spread(points, quick), folder)
    with (out / RESULTS_FILE).open(encoding="utf-8", newline="") as f:
        return len(points), list(csv.DictReader(f))


def _study_row(name: str, step_s: float, out_dir: Path, jobs: int, quick: bool) -> dict:
    """One study at one SUMO step, timed (wall, and CPU of this process and its ended
    workers), with the load average before and after; its folder kept in ``out_dir``."""
    study = STUDIES[name]
    run = _protocol_study if study.protocol else _matrix_study
    out = out_dir / f"{name}_{round(step_s * 1000)}ms"
    row: dict[str, Any] = {"study": name, "sumo_step_s": step_s, "jobs": jobs}
    row["load_avg_start"] = load_average()
    t0, cpu0 = time.perf_counter(), _process_tree_cpu_s()
    total, results = run(study, out, step_s, jobs, quick)
    row["wall_s"] = time.perf_counter() - t0
    row["cpu_s"] = _process_tree_cpu_s() - cpu0
    row["load_avg_end"] = load_average()
    row["runs"], row["study_runs"] = len(results), total
    row["cpu_s_per_run"] = row["cpu_s"] / max(1, len(results))
    row["goal_wall_s"] = study.goal_wall_s
    row["out"] = str(out)
    return {**row, "_results": results}


def _study_step(
    sumo_step_s: float, out_dir: Path, repeats: int, jobs: int, quick: bool, names
) -> tuple[dict, list[dict]]:
    """One SUMO step: the step loop's figures (bench case) and its cost ratio against SUMO
    alone at that step, then each study, timed (:func:`_study_row`)."""
    step: dict[str, Any] = {"sumo_step_s": sumo_step_s, "load_avg_start": load_average()}
    loop = _cosim_and_sumo_only(repeats, sumo_step_s)
    step.update({k: loop[k] for k in _LOOP_KEYS})
    rows = [_study_row(n, sumo_step_s, out_dir, jobs, quick) for n in names]
    for row in rows:
        row["cosim_over_sumo_cost"] = loop["cosim_over_sumo_cost"]
        row["cosim_over_sumo_cpu_cost"] = loop["cosim_over_sumo_cpu_cost"]
        if row["study"] == "table2":
            step["table2_wall_s"], step["table2_cpu_s"] = row["wall_s"], row["cpu_s"]
            step["table2_cases"], step["_results"] = row["runs"], row["_results"]
        row.pop("_results")
    step["load_avg_end"] = load_average()
    return step, rows


def run_studies(
    out_dir: Path,
    steps_s: tuple[float, ...] = (STUDY_SUMO_STEP_S,),
    jobs: int = 2,
    quick: bool = False,
    studies: tuple[str, ...] = (),
) -> dict:
    """Each study (:data:`STUDIES`; none named: all) at each SUMO step (:func:`_study_step`),
    Table 2 against the first step's (:func:`table2_changes`); writes ``bench-studies.json``
    and keeps each study's folder."""
    names = check_studies(studies)
    repeats = 1 if quick else 7
    out_dir.mkdir(parents=True, exist_ok=True)
    done = [_study_step(s, out_dir, repeats, jobs, quick, names) for s in steps_s]
    steps = [step for step, _rows in done]
    if "table2" in names:
        reference = steps[0].pop("_results")
        for step in steps[1:]:
            step["table2_vs_reference"] = table2_changes(reference, step.pop("_results"))
    result = {
        "quick": quick,
        "jobs": jobs,
        "compiled": _compiled(),
        "python": interpreter(),
        "studies": steps,
        "study_rows": [row for _step, rows in done for row in rows],
    }
    (out_dir / "bench-studies.json").write_text(json.dumps(result, indent=2) + "\n")
    return result


def _loads(row: dict) -> str:
    """The 1-minute load average before and after, as ``a-b``."""
    loads = row["load_avg_start"][:1] + row["load_avg_end"][:1]
    return "-".join(f"{v:g}" for v in loads) or "-"


def format_study_table(result: dict) -> str:
    """The studies as one table (docs/performance.md): one row per study and SUMO step."""
    lines = [
        f"step loop: {'compiled' if result['compiled'] else 'Python sources'}"
        + (f"; --quick: {QUICK_RUNS} runs of each study" if result["quick"] else ""),
        interpreter_text(result["python"]),
        "study | runs | sumo step s | jobs | wall s | goal s | CPU s | CPU s per run | "
        "load avg (1 min) | cost ratio wall (CPU)",
    ]
    for r in result["study_rows"]:
        runs = f"{r['runs']}" + (f" of {r['study_runs']}" if r["runs"] != r["study_runs"] else "")
        lines.append(
            f"{r['study']} | {runs} | {r['sumo_step_s']:g} | {r['jobs']} | {r['wall_s']:.1f} | "
            f"<= {r['goal_wall_s']:g} | {r['cpu_s']:.1f} | {r['cpu_s_per_run']:.2f} | "
            f"{_loads(r)} | "
            f"{r['cosim_over_sumo_cost']:.2f} ({r['cosim_over_sumo_cpu_cost']:.2f})"
        )
    return "\n".join(lines)


def format_studies(result: dict) -> str:
    """The step loop at each SUMO step (per-step costs per 10 ms step), Table 2 against the
    first step where Table 2 ran at more than one."""
    lines = [
        "sumo step s | load avg (1 min) | cost ratio wall (CPU) | "
        "us/step: sumo sense control plant contact (loop CPU) | Table 2 colour / partner "
        "changes | max |d| impact m/s, gap ARO m",
    ]
    for r in result["studies"]:
        cmp = r.get("table2_vs_reference")
        diff = "reference" if "table2_cases" in r else "-"
        if cmp is not None:
            d = cmp["max_abs_delta"]
            diff = (
                f"{len(cmp['colour_changes'])} / {len(cmp['partner_changes'])} | "
                f"{d.get('impact_speed_mps', 0.0):.3f}, {d.get('min_gap_aro_m', 0.0):.3f}"
            )
        lines.append(
            f"{r['sumo_step_s']:g} | {_loads(r)} | "
            f"{r['cosim_over_sumo_cost']:.2f} ({r['cosim_over_sumo_cpu_cost']:.2f}) | "
            f"{r['sumo_us_per_step']:.1f} {r['sense_us_per_step']:.1f} "
            f"{r['control_us_per_step']:.1f} {r['plant_us_per_step']:.1f} "
            f"{r['contact_us_per_step']:.1f} ({r['loop_cpu_us_per_step']:.1f}) | {diff}"
        )
    return "\n".join(lines)


def run_studies_cli(
    out_dir: Path, steps_s: tuple[float, ...], jobs: int, quick: bool, studies: tuple[str, ...]
) -> int:
    result = run_studies(out_dir, steps_s, jobs, quick, studies)
    print(format_study_table(result))
    print(format_studies(result))
    print(f"written {out_dir / 'bench-studies.json'}")
    return 0


def run_bench_cli(out_dir: Path, quick: bool = False) -> int:
    result = run_bench(out_dir, quick)
    print(format_table(result))
    print(f"written {out_dir / 'bench.json'}")
    return 0


# --- the previous plant, measured in the same run (``eoam-sumo bench --against REV``) --------

#: Ratio targets against a previous revision: the plant's step at most 2x the previous
#: plant's, the Table 2 batch at most 1.3x, both measured in one run (docs/performance.md).
AGAINST_TARGETS = {
    "plant_us_per_step_ratio": 2.0,
    "plant_cpu_us_per_step_ratio": 2.0,
    "batch_wall_ratio": 1.3,
    "batch_cpu_ratio": 1.3,
}
#: The figures a probe measures in a tree, by kind.
PROBE_FIGURES = {
    "plant": ("plant_us_per_step", "plant_cpu_us_per_step"),
    "batch": ("batch_wall_s", "batch_cpu_s"),
}

#: Run with ``python -c`` in a subprocess whose ``PYTHONPATH`` is one tree: measures that
#: tree's figures through the API both trees share, prints them as one line of JSON.
_PROBE = r"""
import json, math, os, resource, statistics, sys, time
from importlib import machinery
from pathlib import Path

import eoam_sumo
from eoam_sumo.sim import cosim

kind, quick, out = sys.argv[1], sys.argv[2] == "1", Path(sys.argv[3])
root = Path(eoam_sumo.__file__).resolve().parents[1]
speed_mps = 120 / 3.6
res = {"package": str(root), "load_avg_1min": os.getloadavg()[0],
       "compiled": isinstance(getattr(cosim.__spec__, "loader", None),
                              machinery.ExtensionFileLoader)}

def cpu_s():
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

if kind == "plant":
    from eoam_sumo.params import ego_e_class_sedan
    from eoam_sumo.plant import Plant, initial_state
    from eoam_sumo.sim.cosim import CoSimulation
    from eoam_sumo.sim.observers import PhaseTimer
    from eoam_sumo.sim.scenario import ScenarioOverrides
    from eoam_sumo.sim.settings import RunSettings

    timer = PhaseTimer()
    over = ScenarioOverrides(ego_speed_mps=speed_mps, mu=1.0)
    sim = CoSimulation(root / "scenarios" / "baseline.sumocfg", over, RunSettings(),
                       observers=[timer])
    per_step = []
    for _ in range(1 if quick else 5):
        sim.run()
        per_step.append(1e6 * timer.totals["actuate"] / timer.steps)
    res["plant_us_per_step"] = statistics.median(per_step)
    advance = Plant(ego_e_class_sedan()).advance
    x = initial_state(0.0, 0.0, 0.0, speed_mps, drive_force_n=300.0).tolist()
    calls = 2000 if quick else 20000
    t0 = time.process_time()
    for k in range(calls):
        x, _y = advance(x, (0.02 * math.sin(0.0314 * k), 300.0, 0.0), 1.0)
    res["plant_cpu_us_per_step"] = 1e6 * (time.process_time() - t0) / calls
else:
    from eoam_sumo.batch.runner import run_batch

    matrix = root / "scenarios" / "table2.toml"
    if quick:
        matrix = out / "quick.toml"
        matrix.write_text(
            f'[scenario]\nsumocfg = "{(root / "scenarios" / "baseline.sumocfg").as_posix()}"\n'
            "max_time_s = 20.0\n[sweep]\nego_speed_kmh = [120]\nmu = [1.0, 0.7]\n")
    c0, t0 = cpu_s(), time.perf_counter()
    results = run_batch(matrix, out / "batch", jobs=2, progress=False)
    res["batch_wall_s"] = time.perf_counter() - t0
    res["batch_cpu_s"] = cpu_s() - c0
    res["batch_cases"] = len(results)
print(json.dumps(res))
"""


def _git(args: list[str], what: str) -> str:
    """The output of ``git -C ROOT ARGS``; InputError naming ``what`` when git fails."""
    try:
        done = subprocess.run(
            ["git", "-C", str(ROOT), *args], capture_output=True, text=True, check=False
        )
    except OSError as exc:
        raise InputError(f"bench --against: git not found ({exc})") from exc
    if done.returncode != 0:
        raise InputError(f"bench --against: {what}")
    return done.stdout.strip()


def export_revision(rev: str, dest: Path) -> str:
    """Export ``rev``'s tree (``git archive``) into ``dest``; its commit. InputError when this
    source tree is not a git checkout or ``rev`` names no commit in it."""
    _git(["rev-parse", "--is-inside-work-tree"], f"{ROOT} is not a git checkout")
    commit = _git(
        ["rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"], f"unknown revision {rev!r}"
    )
    dest.mkdir(parents=True, exist_ok=True)
    archive = subprocess.Popen(["git", "-C", str(ROOT), "archive", commit], stdout=subprocess.PIPE)
    subprocess.run(["tar", "-x", "-C", str(dest)], stdin=archive.stdout, check=True)
    if archive.stdout is not None:
        archive.stdout.close()
    if archive.wait() != 0:
        raise RuntimeError(f"git archive {commit} failed")
    return commit


def _probe(tree: Path, kind: str, quick: bool, work: Path) -> dict:
    """One probe (``_PROBE``) of ``tree`` in a fresh interpreter: only that tree on the path,
    its own plant cache (``work/cache``) so that the two trees' C builds never mix."""
    out = Path(tempfile.mkdtemp(prefix=f"{kind}-", dir=work))
    env = dict(os.environ, PYTHONPATH=str(tree), EOAM_SUMO_CACHE_DIR=str(work / "cache"))
    cmd = [sys.executable, "-c", _PROBE, kind, "1" if quick else "0", str(out)]
    done = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"bench --against: the {kind} probe of {tree} failed: {tail}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if Path(result["package"]) != tree.resolve():
        raise RuntimeError(f"bench --against: the probe of {tree} imported {result['package']}")
    return result


def _compile_tree(tree: Path) -> None:
    """Compile the tree's step loop in place (setup.py, mypyc), as ``make compiled`` does."""
    env = dict(os.environ, EOAM_SUMO_COMPILE="1")
    cmd = [sys.executable, "setup.py", "-q", "build_ext", "--inplace"]
    subprocess.run(cmd, cwd=tree, env=env, check=True, capture_output=True)


def _alternate(trees: dict[str, Path], quick: bool, pairs: int, tmp: Path) -> dict:
    """Each probe kind ``pairs`` times per tree, the trees alternating (previous, current, then
    current, previous, ...) so that both see the same machine load; every probe's figures."""
    samples: dict[str, list[dict]] = {side: [] for side in trees}
    for side, tree in trees.items():  # warm-up: each tree's plant compiled into its cache
        (tmp / side).mkdir()
        _probe(tree, "plant", True, tmp / side)
    for kind in PROBE_FIGURES:
        for i in range(pairs):
            order = list(trees) if i % 2 == 0 else list(reversed(trees))
            for side in order:
                samples[side].append(_probe(trees[side], kind, quick, tmp / side))
    return samples


def _summarise(samples: dict[str, list[dict]]) -> dict:
    """Medians per tree and figure, the current tree's over the previous one's, the load."""
    result: dict[str, Any] = {}
    for side, probes in samples.items():
        for figures in PROBE_FIGURES.values():
            for name in figures:
                result[f"{side}_{name}"] = statistics.median(p[name] for p in probes if name in p)
        loads = [p["load_avg_1min"] for p in probes]
        result[f"{side}_load_avg_1min"] = [min(loads), max(loads)]
        result[f"{side}_compiled"] = all(p["compiled"] for p in probes)
    for ratio, name in zip(AGAINST_TARGETS, [n for f in PROBE_FIGURES.values() for n in f]):
        result[ratio] = result[f"current_{name}"] / result[f"previous_{name}"]
    result["targets"] = {
        k: {"target": f"<= {v:g}", "met": result[k] <= v} for k, v in AGAINST_TARGETS.items()
    }
    return result


def compare_against(rev: str, out_dir: Path, quick: bool = False, pairs: int = 3) -> dict:
    """The plant's step and the Table 2 batch of this tree against ``rev``'s, in one run:
    ``rev`` exported to a temporary folder (compiled when this tree runs compiled), each
    figure measured ``pairs`` times per tree in alternation; writes ``bench-against.json``."""
    with tempfile.TemporaryDirectory(prefix="eoam-bench-against-") as tmp_dir:
        tmp = Path(tmp_dir)
        commit = export_revision(rev, tmp / "tree")
        if _compiled():
            _compile_tree(tmp / "tree")
        trees = {"previous": tmp / "tree", "current": ROOT}
        result = {"against": rev, "against_commit": commit, "quick": quick, "pairs": pairs}
        result.update(_summarise(_alternate(trees, quick, pairs, tmp)))
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "bench-against.json").write_text(json.dumps(result, indent=2) + "\n")
    return result


def format_against(result: dict) -> str:
    """The comparison as a table: each figure for both trees, the ratios beside their targets."""
    lines = [
        f"against {result['against']} ({result['against_commit'][:12]}), "
        f"{result['pairs']} alternating probes per tree",
        f"load average (1 min) previous {result['previous_load_avg_1min']}, "
        f"current {result['current_load_avg_1min']}",
        f"{'figure':<24}  {'previous':>10}  {'current':>10}  {'ratio':>6}  target",
    ]
    names = [n for f in PROBE_FIGURES.values() for n in f]
    for ratio, name in zip(AGAINST_TARGETS, names):
        tgt = result["targets"][ratio]
        lines.append(
            f"{name:<24}  {result[f'previous_{name}']:>10.4g}  {result[f'current_{name}']:>10.4g}"
            f"  {result[ratio]:>6.3f}  {tgt['target']} {'met' if tgt['met'] else 'MISSED'}"
        )
    return "\n".join(lines)


def run_against_cli(out_dir: Path, rev: str, quick: bool = False, pairs: int = 3) -> int:
    result = compare_against(rev, out_dir, quick, pairs)
    print(format_against(result))
    print(f"written {out_dir / 'bench-against.json'}")
    return 0
