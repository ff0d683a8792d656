"""The ``eoam-sumo`` command line (its commands: ``eoam-sumo --help``).

Bad input ends with one line on stderr naming the file or value and exit status 2; the
library raises, only this module prints and exits.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import signal
import sys
import threading
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

from eoam_sumo import __version__
from eoam_sumo.arguments import finite, mu, speed_kmh, sumo_step_argument
from eoam_sumo.drivers import DRIVERS
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import writable_dir
from eoam_sumo.openscenario.command import (
    is_xosc,
    prepare_command,
    refuse_params_for_sumocfg,
    run_xosc_command,
    xosc_arguments,
)
from eoam_sumo.outputs.staging import OutputKind, output_folder
from eoam_sumo.seeds import seed_argument
from eoam_sumo.sim.settings import (
    DEFAULT_MAX_TIME_S,
    MAX_TIME_LIMIT_S,
    STUDY_SUMO_STEP_S,
    check_sumo_step_s,
)
from eoam_sumo.traffic_levels.command import add_scenario_arguments, cmd_scenario
from eoam_sumo.vehicle_tests import command as vehicle_test_command

EXIT_BAD_INPUT = 2
PROG = "eoam-sumo"
DESCRIPTION = (
    "Emergency obstacle avoidance (brake, steer around, or brake in lane) at highway speeds, "
    "in SUMO co-simulations: build the tables, run scenarios, batches, protocols and "
    "vehicle tests, and plot them."
)


class _Parser(argparse.ArgumentParser):
    """argparse that reports a usage error as one line (no usage block) with status 2."""

    def error(self, message: str):
        command = self.prog.removeprefix(PROG).strip()  # "run" of "eoam-sumo run"
        raise InputError(f"{command}: {message}" if command else message)


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} must be >= 1")
    return value


def _screenshot_times(text: str) -> tuple[tuple[float, bool], ...]:
    """``T[,T...]``: (seconds, absolute) pairs; T is in seconds after the ego's departure,
    ``@T`` in SUMO's time."""
    try:
        times = tuple((float(t.strip().removeprefix("@")), "@" in t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a list of seconds T[,T...] (@T: SUMO's time)"
        ) from None
    if not all(math.isfinite(t) and t >= 0.0 for t, _ in times):
        raise argparse.ArgumentTypeError(f"times {text} s must be numbers >= 0")
    return times


def _distance_or_none(text: str) -> float | None:
    if text.lower() == "none":
        return None
    value = finite(text)
    if value < 0.0:
        raise argparse.ArgumentTypeError(f"distance {text} m must be >= 0 (or 'none')")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The ``eoam-sumo`` parser: one sub-command per job, each with its own arguments."""
    parser = _Parser(prog=PROG, description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"eoam-sumo {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for add_arguments in (
        _tables_arguments,
        _run_arguments,
        _batch_arguments,
        _plot_arguments,
        _animate_arguments,
        _bench_arguments,
        vehicle_test_command.add_arguments,
        _protocol_arguments,
        add_scenario_arguments,
        _r157_arguments,
    ):
        add_arguments(sub)
    return parser


def _r157_arguments(sub) -> None:
    from eoam_sumo.r157.command import add_arguments

    add_arguments(sub)


def _cmd_r157(args) -> int:
    from eoam_sumo.r157.command import run

    return run(args)


def _protocol_arguments(sub) -> None:
    from eoam_sumo.protocols.command import add_arguments

    add_arguments(sub)


def _tables_arguments(sub) -> None:
    p = sub.add_parser("tables", help="build the lookup tables and DMM phase boundaries")
    p.add_argument(
        "--out",
        type=Path,
        help="output folder (default: the vehicle's: tables/, tables/NAME/, tables/NAME-abs/; "
        "a vehicle file named as a catalogue vehicle: tables/NAME-file/)",
    )
    p.add_argument("--jobs", type=_positive_int, default=2, help="parallel processes (2)")
    p.add_argument("--speeds-kmh", type=speed_kmh, nargs="+", help="speed grid (km/h)")
    p.add_argument("--mu", type=mu, nargs="+", help="friction grid")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--vehicle", help="a catalogue name or a vehicle file (default: the sedan)")
    p.add_argument(
        "--abs", choices=("on", "off"), help="ABS fitted or not (default: the vehicle's own)"
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="write even over another vehicle's tables in the folder (refused by default)",
    )


def _run_arguments(sub) -> None:
    p = sub.add_parser("run", help="one co-simulation of a SUMO scenario")
    p.add_argument("cfg", type=Path, help="the scenario's .sumocfg, or an OpenSCENARIO .xosc")
    p.add_argument("--speed-kmh", type=speed_kmh, help="ego initial speed (km/h)")
    p.add_argument("--mu", type=mu, help="surface friction for every lane")
    _scenario_override_arguments(p)
    p.add_argument(
        "--ego", help="the ego vehicle's id (default: ego); of an .xosc, the ego entity's name"
    )
    xosc_arguments(p)
    p.add_argument("--out", type=Path, default=Path("out/run"), help="output folder")
    p.add_argument(
        "--max-time-s", type=finite, default=DEFAULT_MAX_TIME_S, help="simulated time limit"
    )
    p.add_argument(
        "--tables",
        type=Path,
        help="lookup tables folder (default: tables/); a vehicle other than the sedan uses "
        "its sub-folder TABLES/NAME",
    )
    p.add_argument(
        "--vehicle",
        metavar="NAME|FILE",
        help="the ego: a catalogue vehicle (vehicles/NAME.toml) or a vehicle file "
        "(default: the paper's sedan)",
    )
    p.add_argument("--radar-range-m", type=finite, help="ego radar range (default 100 m)")
    p.add_argument(
        "--mu-belief",
        default="known",
        help="friction the EOAM decides with: known (the road's), estimate (a "
        "friction estimator's output) or a number (default: known)",
    )
    p.add_argument(
        "--radar-model",
        default="ideal",
        help="ideal (exact, every step) or automotive (noise, misses, latency, "
        "occlusion, tracker; docs/sensing.md)",
    )
    p.add_argument("--seed", type=seed_argument, default=0, help="seed of every random model (0)")
    p.add_argument(
        "--driver",
        choices=DRIVERS,
        default="eoam",
        help="the ego's controller: the EOAM or a reference driver (docs/reference-drivers.md)",
    )
    _after_stop_argument(p)
    sumo_step_argument(p)
    p.add_argument("--gui", action="store_true", help="run in sumo-gui through TraCI")
    _policy_arguments(p)
    _gui_arguments(p)


def _scenario_override_arguments(p: argparse.ArgumentParser) -> None:
    """``run``'s overrides of a sumocfg's scenario: an oncoming car, the obstacle's stop."""
    p.add_argument(
        "--oncoming-m",
        type=_distance_or_none,
        default=None,
        help="add an oncoming car this far ahead (m), or 'none'",
    )
    p.add_argument(
        "--aro-hold-s",
        type=finite,
        help="the obstacle (eoam.role=aro) holds its speed this long before its stop "
        "(default: the route file's; a matrix's aro_hold_s)",
    )
    p.add_argument(
        "--aro-decel-mps2",
        type=finite,
        help="the obstacle's stop deceleration (default: the route file's; aro_decel_mps2)",
    )


def _after_stop_argument(p: argparse.ArgumentParser) -> None:
    """``run`` and ``batch``: how long a run goes on after the ego stops."""
    p.add_argument(
        "--after-stop-s",
        type=finite,
        metavar="S",
        help="simulate S s after the ego stops (default: 2 s, then as long as a road user "
        "behind it in its lane, within 150 m, still moves towards it)",
    )


def _policy_arguments(p: argparse.ArgumentParser) -> None:
    """``run``: the decision policy and the V2X link that informs the safe one."""
    p.add_argument(
        "--policy",
        choices=("paper", "safe"),
        default="paper",
        help="decision policy: the paper's (default) or safe (sight-distance gate)",
    )
    p.add_argument(
        "--v2x-range-m",
        type=finite,
        default=0.0,
        help="V2X reception range (m), 0 = no V2X (safe policy only)",
    )
    p.add_argument("--v2x-latency-s", type=finite, default=0.1, help="V2X latency (s)")
    p.add_argument(
        "--v2x-loss", type=finite, default=0.0, help="V2X packet-loss probability, in [0, 1)"
    )
    p.add_argument(
        "--v2x-penetration",
        type=finite,
        default=1.0,
        help="share of road users equipped with V2X, in [0, 1]",
    )


def _gui_arguments(p: argparse.ArgumentParser) -> None:
    """``run --gui``: the sumo-gui view's pace and screenshots."""
    p.add_argument(
        "--gui-delay-ms",
        type=finite,
        metavar="N",
        help="with --gui: wall ms per SUMO step (default: real time)",
    )
    p.add_argument(
        "--gui-screenshot",
        type=_screenshot_times,
        metavar="T[,T...]",
        default=(),
        help="with --gui: screenshots T s after the ego's departure (@T: at SUMO's time T) "
        "into --out, named screenshot_+Ts.png (screenshot_@Ts.png)",
    )
    p.add_argument(
        "--gui-close",
        action="store_true",
        help="with --gui: close the window at the end (default: it stays open, except on "
        "a virtual display, Xvfb)",
    )


def _batch_arguments(sub) -> None:
    p = sub.add_parser(
        "batch",
        help="run every case of an experiment matrix",
        description="Run every case of an experiment matrix. Exit status: 0 every case ran; "
        "1 at least one case failed (results.csv and the report are still written, the "
        "failed count is the last line on stderr); 2 bad input, found before any case runs "
        "(the matrix, its scenario files, a speed or friction outside the lookup tables).",
    )
    p.add_argument(
        "matrix", type=Path, help="experiment matrix (.toml), or an .xosc parameter variation file"
    )
    p.add_argument("--out", type=Path, default=Path("out/batch"), help="output folder")
    p.add_argument("--jobs", type=_positive_int, default=1, help="parallel processes")
    p.add_argument("--scheduler", help="Dask scheduler address, or 'local' for a LocalCluster")
    p.add_argument("--resume", action="store_true", help="run only the cases not yet done")
    p.add_argument("--timeout-s", type=finite, default=300.0, help="per-case time limit")
    p.add_argument(
        "--timeseries",
        choices=("csv", "parquet", "none"),
        default="csv",
        help="per-case time series format, or none (summary.json only)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    _after_stop_argument(p)
    sumo_step_argument(p, study=True)


def _plot_arguments(sub) -> None:
    p = sub.add_parser("plot", help="plots of a run, a batch or a tables folder")
    p.add_argument("folder", type=Path, help="a run, batch or tables output folder")
    p.add_argument("--out", type=Path, help="where to put the PNGs (default: the folder)")


def _animate_arguments(sub) -> None:
    p = sub.add_parser("animate", help="animated bird's-eye view of a run folder")
    p.add_argument(
        "run_dir", type=Path, help="a run folder (summary.json, timeseries.csv, traffic.csv)"
    )
    p.add_argument(
        "--out",
        type=Path,
        help="GIF, MP4 with ffmpeg, or PNG: one still (default: RUN_DIR/animation.gif)",
    )
    p.add_argument(
        "--at-s",
        type=finite,
        default=None,
        help="a PNG still's time_s (default: the ego farthest from its lane's centre)",
    )
    p.add_argument("--fps", type=_positive_int, default=10, help="frames per second of run time")
    p.add_argument("--labels", action="store_true", help="write each road user's id beside it")


def _bench_arguments(sub) -> None:
    p = sub.add_parser("bench", help="the performance benchmark")
    p.add_argument("--out", type=Path, default=Path("out/bench"), help="output folder")
    p.add_argument("--quick", action="store_true", help="tiny settings (for tests)")
    p.add_argument(
        "--against",
        metavar="REV",
        help="instead: the plant's step and Table 2 batch against git revision REV, as ratios",
    )
    p.add_argument("--pairs", type=_positive_int, default=3, help="with --against: probes per tree")
    p.add_argument(
        "--studies",
        action="store_true",
        help="instead: each study timed at each SUMO step, with the step loop's "
        "cost ratio against SUMO alone at that step and the load average",
    )
    p.add_argument(
        "--study",
        action="append",
        default=[],
        metavar="NAME",
        help="with --studies (implied): this study only, repeatable (table2, protocol, "
        "traffic-levels, vehicles, monte-carlo; default: all)",
    )
    p.add_argument(
        "--sumo-steps",
        type=finite,
        nargs="+",
        metavar="S",
        default=(STUDY_SUMO_STEP_S,),
        help="with --studies: SUMO steps [s], the first Table 2's reference "
        f"(default {STUDY_SUMO_STEP_S:g})",
    )
    p.add_argument("--jobs", type=_positive_int, default=2, help="with --studies: batch jobs")


def _cmd_tables(args) -> int:
    from eoam_sumo.matrix import vehicle_params
    from eoam_sumo.offline.build import build_tables
    from eoam_sumo.offline.owner import check_owner
    from eoam_sumo.sim.vehicle import vehicle_tables_dir
    from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

    vehicle = args.vehicle or DEFAULT_VEHICLE
    params = vehicle_params(vehicle, None if args.abs is None else args.abs == "on")
    out = args.out or vehicle_tables_dir(vehicle, None, params)
    if not args.overwrite:
        check_owner(out, params)
    out = writable_dir(out)
    build_tables(
        out,
        jobs=args.jobs,
        speeds_kmh=args.speeds_kmh,
        mus=args.mu,
        progress=not args.no_progress,
        params=params,
    )
    print(f"tables written to {out}")
    return 0


def _cmd_run(args) -> int:
    """``eoam-sumo run``: one co-simulation into ``--out``, its outcome on one line."""
    from eoam_sumo.sim.cosim import run_case
    from eoam_sumo.sim.scenario import ScenarioOverrides

    _check_run_args(args)
    if is_xosc(args):
        xosc = prepare_command(args)  # refuses what the subset lacks before writing anything
    else:
        from eoam_sumo.sim.scenario.files import check_scenario

        check_scenario(args.cfg, args.ego or "ego")  # a file that is no sumocfg: nothing written
    # a refused or failed run leaves no folder; a re-run replaces a run folder once complete
    with output_folder(args.out, RUN_OUTPUT, keep_partial=False) as out:
        settings = _run_settings(args, out)
        if is_xosc(args):
            s = run_xosc_command(args, xosc, out, settings)
        else:
            overrides = ScenarioOverrides(
                ego_speed_mps=None if args.speed_kmh is None else args.speed_kmh / 3.6,
                mu=args.mu,
                oncoming_start_m=args.oncoming_m,
                aro_hold_s=args.aro_hold_s,
                aro_decel_mps2=args.aro_decel_mps2,
            )
            s = run_case(args.cfg, overrides, out, settings)
    print(
        f"{s['outcome']}: collision_with={s['collision_with']} "
        f"impact={s['impact_speed_mps']:.1f} m/s modes={s['modes_visited']} "
        f"fcw={s['fcw_raised']} mu={s['mu']:.2f} policy={s['policy']} "
        f"{_sight_text(s)}sim={s['sim_time_s']:.2f} s "
        f"rtf={s['realtime_factor']:.0f} -> {args.out}"
    )
    if s.get("sumo_overrides"):
        options = ", ".join(f"{k}={v}" for k, v in s["sumo_overrides"].items())
        print(f"eoam-sumo: SUMO options set over the scenario's: {options}", file=sys.stderr)
    if args.gui and settings.gui_settings.keep_open:
        print("eoam-sumo: the sumo-gui window stays open until you close it", file=sys.stderr)
    return 0


#: What shows a folder holds a run's output (``eoam-sumo run``, a .sumocfg's or an .xosc's):
#: a re-run over it is staged and replaces it once complete; a batch's, a protocol's or a
#: study's folder is refused.
RUN_OUTPUT = OutputKind(
    "run",
    ("summary.json", "timeseries.csv", "timeseries.parquet", "traffic.csv", "road.csv"),
    foreign=("results.csv", "cases", "runs", "batch", "scenarios", "scorecard.md"),
)


def _check_run_args(args) -> None:
    """InputError for a ``run`` option out of its range, before anything is written."""
    if args.cfg.is_dir():
        raise InputError(f"{args.cfg}: a folder, not a scenario file (.sumocfg or .xosc)")
    if not args.cfg.is_file():
        raise InputError(f"{args.cfg}: no such scenario file")
    if not 0 < args.max_time_s <= MAX_TIME_LIMIT_S:
        raise InputError(f"--max-time-s {args.max_time_s:g} is outside (0, {MAX_TIME_LIMIT_S:g}]")
    if args.radar_range_m is not None and args.radar_range_m <= 0:
        raise InputError(f"--radar-range-m {args.radar_range_m} must be > 0")
    if args.after_stop_s is not None and args.after_stop_s < 0:
        raise InputError(f"--after-stop-s {args.after_stop_s:g} must be >= 0")
    if args.sumo_step_s is not None:
        check_sumo_step_s(args.sumo_step_s, "--sumo-step-s")
    _check_v2x(args)
    refuse_params_for_sumocfg(args)
    if not args.gui and (args.gui_delay_ms is not None or args.gui_screenshot or args.gui_close):
        raise InputError("--gui-delay-ms, --gui-screenshot and --gui-close need --gui")


def _run_settings(args, out: Path):
    """The run's ``RunSettings`` from the ``run`` options (screenshots go to ``out``)."""
    from eoam_sumo.sensing.automotive import parse_radar_model
    from eoam_sumo.sensing.friction import parse_mu_belief
    from eoam_sumo.sensing.radar import RadarSettings
    from eoam_sumo.sim.cosim import policy_settings
    from eoam_sumo.sim.session.gui import GuiSettings, virtual_display
    from eoam_sumo.sim.settings import RunSettings
    from eoam_sumo.vehicle_files import load_vehicle

    gui = GuiSettings(
        delay_ms=args.gui_delay_ms,
        screenshots_s=tuple(t for t, absolute in args.gui_screenshot if not absolute),
        screenshots_at_s=tuple(t for t, absolute in args.gui_screenshot if absolute),
        screenshot_dir=out,
        keep_open=not (args.gui_close or virtual_display()),  # Xvfb: nobody sees the window
    )
    settings = RunSettings(
        max_time_s=args.max_time_s,
        ego_id=args.ego or "ego",
        gui=args.gui,
        use_traci=args.gui,
        gui_settings=gui,
        tables_dir=args.tables,
        mu_belief=parse_mu_belief(args.mu_belief),
        seed=args.seed,
        radar_model=parse_radar_model(args.radar_model),
        after_stop_s=args.after_stop_s,
        driver=args.driver,
        sumo_step_s=args.sumo_step_s,
    )
    if args.radar_range_m is not None:
        settings = replace(settings, radar=RadarSettings(range_m=args.radar_range_m))
    if args.vehicle is not None:
        settings = replace(
            settings, vehicle=load_vehicle(args.vehicle), vehicle_id=str(args.vehicle)
        )
    return policy_settings(
        settings,
        args.policy,
        args.v2x_range_m,
        args.v2x_latency_s,
        args.v2x_loss,
        args.v2x_penetration,
    )


def _check_v2x(args) -> None:
    """InputError for a V2X option out of its range, or V2X without the safe policy."""
    if args.v2x_range_m < 0.0:
        raise InputError(f"--v2x-range-m {args.v2x_range_m:g} must be >= 0")
    if args.v2x_latency_s < 0.0:
        raise InputError(f"--v2x-latency-s {args.v2x_latency_s:g} must be >= 0")
    if not 0.0 <= args.v2x_loss < 1.0:
        raise InputError(f"--v2x-loss {args.v2x_loss:g} must be in [0, 1)")
    if not 0.0 <= args.v2x_penetration <= 1.0:
        raise InputError(f"--v2x-penetration {args.v2x_penetration:g} must be in [0, 1]")
    if args.v2x_range_m > 0.0 and args.policy != "safe":
        raise InputError("--v2x-range-m needs --policy safe (V2X informs the safe policy only)")


def _sight_text(summary: dict) -> str:
    """The sight-distance gate's record for the run's line (empty when it was not asked)."""
    if not summary.get("sight_gate"):
        return ""
    need = summary["sight_needed_m"]
    need_text = "never passes" if need is None else f"{need:.0f} m"
    return (
        f"gate={summary['sight_gate']} (needed {need_text}, known free "
        f"{summary['sight_known_free_m']:.0f} m) "
    )


def _cmd_batch(args) -> int:
    """``eoam-sumo batch``: run the batch, draw its images; SIGTERM stops it like Ctrl-C
    (the rows written in place kept; a staging folder removed).

    The folder is written by this process alone; a re-run without ``--resume`` over an
    earlier batch writes a staging folder that replaces it once complete
    (:mod:`eoam_sumo.outputs.staging`). Returns 0 when every case ran, ``EXIT_CASES_FAILED``
    when at least one failed (after results.csv and the report are written; each failed case
    and then the count on stderr). Bad input raises InputError before any case runs (exit
    status 2 in :func:`main`).
    """
    from eoam_sumo.openscenario.variations import is_xosc_batch

    if is_xosc_batch(args.matrix):
        from eoam_sumo.batch.runner import check_options

        check_options(args.jobs, args.timeout_s, args.timeseries)
        return _cmd_xosc_batch(args)
    if args.scheduler is not None:
        return _run_matrix_batch(args)
    from eoam_sumo.batch.case import PRELOAD
    from eoam_sumo.batch.pool import warm_workers
    from eoam_sumo.matrix import load_matrix

    # no more than its cases (a resumed batch: those left, known once planned; none warmed)
    cases = 0 if args.resume else len(load_matrix(Path(args.matrix)).cases())
    with warm_workers(args.jobs, PRELOAD, cases):  # they import while the batch is planned
        return _run_matrix_batch(args)


def _run_matrix_batch(args) -> int:
    """``_cmd_batch`` of a TOML matrix: check it, run it, draw its images."""
    from eoam_sumo.batch.runner import check_options, plan_batch, run_batch
    from eoam_sumo.outputs.staging import output_folder

    check_options(args.jobs, args.timeout_s, args.timeseries)
    plan = plan_batch(
        args.matrix,
        after_stop_s=args.after_stop_s,
        sumo_step_s=args.sumo_step_s,
        default_sumo_step_s=STUDY_SUMO_STEP_S,
    )
    with (
        _sigterm_interrupts(),
        output_folder(args.out, _batch_output(), in_place=args.resume) as out,
    ):
        results = run_batch(
            args.matrix,
            out,
            jobs=args.jobs,
            scheduler=args.scheduler,
            resume=args.resume,
            timeout_s=args.timeout_s,
            progress=not args.no_progress,
            timeseries=args.timeseries,
            after_stop_s=args.after_stop_s,
            plan=plan,
            meanwhile=_import_batch_plots,  # matplotlib: in this process only, on a free core
        )
        from eoam_sumo.plotting.batch_plots import plot_batch_report

        plot_batch_report(results, out)
    return _batch_status(results, Path(args.out))


def _import_batch_plots() -> None:
    import eoam_sumo.plotting.batch_plots  # noqa: F401 - imported for the images to come


def _cmd_xosc_batch(args) -> int:
    """``batch`` over an .xosc's variations (docs/openscenario.md): every case checked, then
    run; counts per outcome on stdout; status 1 when a case failed."""
    from eoam_sumo.openscenario.batch import CASES, RESULTS, check_cases, run_batch
    from eoam_sumo.openscenario.variations import load_batch
    from eoam_sumo.outputs.staging import OutputKind, output_folder

    for flag, given in (("--scheduler", args.scheduler), ("--resume", args.resume),
                        ("--after-stop-s", args.after_stop_s is not None)):  # fmt: skip
        if given:
            raise InputError(f"{flag} does not apply to a batch over an .xosc")
    batch = load_batch(args.matrix)
    check_cases(batch)  # refusals before anything is written
    with output_folder(args.out, OutputKind("xosc batch", (RESULTS, CASES))) as out:
        rows = run_batch(batch, out, args.jobs, args.timeout_s, args.timeseries, None)
    counts: dict[str, int] = {}
    for row in rows:
        key = row.get("outcome") or row["status"]
        counts[key] = counts.get(key, 0) + 1
    text = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    print(f"{len(rows)} cases ({batch.left_out} outside the parameter constraints left out): "
          f"{text}; {Path(args.out) / RESULTS}")  # fmt: skip
    failed = [r for r in rows if r["status"] != "ok"]
    for row in failed:
        print(f"eoam-sumo: {row['case_id']} failed: {row['error']}", file=sys.stderr)
    return 1 if failed else 0


def _batch_output():
    """A batch's output folder: what shows a folder holds one."""
    from eoam_sumo.batch.output import BATCH_OUTPUT

    return BATCH_OUTPUT


def _raise_interrupt(signum, frame):
    raise KeyboardInterrupt


@contextlib.contextmanager
def _sigterm_interrupts() -> Iterator[None]:
    """SIGTERM raises KeyboardInterrupt inside the block (in the main thread only)."""
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        yield
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _batch_status(results, out: Path) -> int:
    """Print the batch's counts (stdout) and its failed cases (stderr); the exit status."""
    from eoam_sumo.batch.probabilities import PROBABILITIES_FILE
    from eoam_sumo.batch.report import TABLE_MD
    from eoam_sumo.batch.results import RESULTS_FILE
    from eoam_sumo.batch.runner import EXIT_CASES_FAILED

    failed = results[results["status"] != "ok"]
    results_path = out / RESULTS_FILE
    report = (
        f"outcome probabilities in {out / PROBABILITIES_FILE}"
        if results["draw"].notna().any()
        else f"Table 2 in {out / TABLE_MD}"
    )
    print(
        f"{len(results)} cases, {len(results) - len(failed)} ok, {len(failed)} failed; "
        f"results in {results_path}, {report}"
    )
    if failed.empty:
        return 0
    for _, row in failed.iterrows():
        print(f"failed: {row['case_id']}: {row['error']}", file=sys.stderr)
    print(
        f"eoam-sumo: {len(failed)} of {len(results)} cases failed; their errors are in the "
        f"'error' column of {results_path}",
        file=sys.stderr,
    )
    return EXIT_CASES_FAILED


def _cmd_plot(args) -> int:
    from eoam_sumo.plotting.dispatch import plot_folder

    if not args.folder.is_dir():
        raise InputError(f"{args.folder}: no such folder")
    for path in plot_folder(args.folder, writable_dir(args.out or args.folder)):
        print(path)
    return 0


#: The most frames per second of run time ``animate`` draws: one every 10 ms, the run's step
#: and the finest delay between a GIF's frames (at 1000 fps a GIF's delays were 0).
MAX_FPS = 100


def _cmd_animate(args) -> int:
    from eoam_sumo.plotting.animate import animate_cli

    if args.fps > MAX_FPS:
        raise InputError(
            f"--fps {args.fps}: at most {MAX_FPS} (a frame every 10 ms, the run's step and a "
            "GIF's finest delay)"
        )
    print(animate_cli(args.run_dir, args.out, args.fps, args.labels, args.at_s))
    return 0


def _cmd_bench(args) -> int:
    from eoam_sumo.bench import run_against_cli, run_bench_cli

    if args.against is not None:
        return run_against_cli(writable_dir(args.out), args.against, args.quick, args.pairs)
    if args.studies or args.study:
        from eoam_sumo.bench import check_studies, run_studies_cli

        studies = check_studies(args.study)
        steps = tuple(check_sumo_step_s(s, "--sumo-steps") for s in args.sumo_steps)
        return run_studies_cli(writable_dir(args.out), steps, args.jobs, args.quick, studies)
    return run_bench_cli(writable_dir(args.out), quick=args.quick)


def _cmd_protocol(args) -> int:
    from eoam_sumo.protocols.command import run

    return run(args)


_COMMANDS = {
    "tables": _cmd_tables,
    "run": _cmd_run,
    "batch": _cmd_batch,
    "plot": _cmd_plot,
    "animate": _cmd_animate,
    "bench": _cmd_bench,
    "vehicle-test": vehicle_test_command.run,
    "protocol": _cmd_protocol,
    "scenario": cmd_scenario,
    "r157-study": _cmd_r157,
}


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return _COMMANDS[args.command](args)
    except InputError as exc:
        print(f"eoam-sumo: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except UnicodeDecodeError as exc:  # a reader that does not name its file: still one line
        print(f"eoam-sumo: error: an input file is not UTF-8 text: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except RuntimeError as exc:  # a SUMO failure, an optimiser that did not converge
        print(f"eoam-sumo: failed: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("eoam-sumo: interrupted", file=sys.stderr)
        return 130
