"""``eoam-sumo protocol NAME``: every test point of a protocol as a SUMO scenario, run as one
batch, scored into ``results.csv``, ``scorecard.md`` and ``scorecard.png``
(docs/protocols.md)."""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

from eoam_sumo.arguments import sumo_step_argument
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import vehicle_params as matrix_vehicle_params
from eoam_sumo.outputs.staging import OutputKind, output_folder
from eoam_sumo.params import MU_MAX, VehicleParams
from eoam_sumo.protocols.points import PROTOCOLS, TestPoint, protocol_points
from eoam_sumo.sim.settings import STUDY_SUMO_STEP_S, check_sumo_step_s

#: Runs end at this simulated time after the ego's departure [s]: the slowest approach
#: (CCRm 30 km/h behind 20 km/h, 41.7 m at 2.8 m/s) meets the target after 15 s.
MAX_TIME_S = 40.0
POLICIES = ("paper", "safe")
#: --system: aeb (the EOAM braking only, what the protocol scores) or eoam (with its lane change)
SYSTEMS = ("aeb", "eoam")


#: What shows a folder holds a protocol's output (``protocols.runner``'s files and folders).
PROTOCOL_OUTPUT = OutputKind(
    "protocol",
    ("results.csv", "scorecard.md", "scorecard.png", "scenarios", "batch"),
    foreign=("runs", "cases", "table2.md", "outcome_probabilities.csv"),
)

#: the equipment switches, --abs and --esc
EQUIPMENT = ("abs", "esc")
ON_OFF = ("on", "off")


def vehicle_params(
    name: str, abs_mode: str | None = None, esc_mode: str | None = None
) -> VehicleParams:
    """The VUT's ``VehicleParams``: ``--vehicle`` NAME (a catalogue name or a vehicle file),
    with ABS/ESC on or off as asked (None: the vehicle's own). InputError for an unknown NAME."""
    for option, mode in (("abs", abs_mode), ("esc", esc_mode)):
        if mode is not None and mode not in ON_OFF:
            raise InputError(f"--{option} {mode!r} is not one of on, off")
    return matrix_vehicle_params(
        name,
        None if abs_mode is None else abs_mode == "on",
        None if esc_mode is None else esc_mode == "on",
    )


def vehicle_label(args) -> str:
    """The VUT as the scorecard names it: NAME, and ABS/ESC where asked."""
    extra = [f"{o.upper()} {getattr(args, o)}" for o in EQUIPMENT if getattr(args, o)]
    return ", ".join([args.vehicle, *extra])


def add_arguments(subparsers) -> None:
    """The ``protocol`` sub-command's arguments."""
    p = subparsers.add_parser(
        "protocol",
        help="run a test protocol (Euro NCAP AEB C2C, UN R152) and score it",
        description="Run every test point of a protocol as one batch and score it "
        "(docs/protocols.md). Exit status: 0 every point ran; 1 a point failed; 2 bad input.",
    )
    p.add_argument("name", choices=PROTOCOLS, help="the protocol")
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument("--jobs", type=int, default=1, help="parallel processes")
    p.add_argument("--scheduler", help="Dask scheduler address, or 'local'")
    p.add_argument(
        "--vehicle", default="sedan", help="the VUT: a catalogue name or a vehicle file (sedan)"
    )
    p.add_argument("--policy", choices=POLICIES, default="paper", help="decision policy")
    p.add_argument(
        "--system",
        choices=SYSTEMS,
        default="aeb",
        help="aeb: the EOAM with its lane change inhibited, what the protocol scores (default); "
        "eoam: with its lane change (our extension, reported beside aeb)",
    )
    p.add_argument("--abs", choices=ON_OFF, help="ABS fitted or not (default: the vehicle's)")
    p.add_argument("--esc", choices=ON_OFF, help="ESC fitted or not (default: the vehicle's)")
    p.add_argument("--mu", type=float, default=1.0, help="friction of every lane (1.0)")
    p.add_argument("--points", help="run only the points whose id matches this regex")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    sumo_step_argument(p, study=True)


def selected_points(args) -> list[TestPoint]:
    """The protocol's points, filtered by ``--points``."""
    if not 0.0 < args.mu <= MU_MAX:
        raise InputError(f"--mu {args.mu:g} is outside (0, {MU_MAX:g}]")
    if args.jobs < 1:
        raise InputError(f"--jobs {args.jobs} must be >= 1")
    _sumo_step_s(args)
    params = vehicle_params(args.vehicle, args.abs, args.esc)
    _check_mu_in_tables(args, params)
    points = protocol_points(args.name, params.width_m)
    if args.points:
        try:
            pattern = re.compile(args.points)
        except re.error as exc:
            raise InputError(
                f"--points {args.points!r} is not a regular expression: {exc}"
            ) from None
        points = [p for p in points if pattern.search(p.point_id) or pattern.search(named(p))]
        if not points:
            raise InputError(f"--points {args.points!r} matches no test point of {args.name}")
    return points


def named(point) -> str:
    """A point's id with its test's own name (``R152-stationary_v10...``: the id writes the
    name's "-" as "m"), for ``--points``."""
    coded = point.test.replace("-", "m").replace(".", "p")
    return point.test + point.point_id.removeprefix(coded)


def _check_mu_in_tables(args, params: VehicleParams) -> None:
    """InputError for a ``--mu`` below the VUT's lookup tables (every point would fail)."""
    from eoam_sumo.sim.vehicle import vehicle_tables

    tables = vehicle_tables(args.vehicle, params, cached=False)
    try:
        tables.check_run(args.mu, tables.speed_grid_mps[0])
    except InputError as exc:
        raise InputError(f"--mu {args.mu:g}: {exc}") from None


def run(args) -> int:
    """Run the protocol; 0 when every point ran, 1 when one failed. The output folder is
    written by this process alone; a re-run over an earlier one writes a staging folder that
    replaces it once complete (:mod:`eoam_sumo.outputs.staging`)."""
    from eoam_sumo.batch.case import PRELOAD
    from eoam_sumo.batch.pool import warm_workers

    points = selected_points(args)
    local = args.scheduler is None  # its workers import while the scenarios are written
    with (
        warm_workers(args.jobs, PRELOAD, len(points)) if local else contextlib.nullcontext(),
        output_folder(Path(args.out), PROTOCOL_OUTPUT, keep_partial=False) as out,
    ):
        summary = run_points(args, points, out)
    print(summary.line(Path(args.out)))
    return 1 if summary.failed else 0


def run_points(args, points: list[TestPoint], out: Path):
    """Run and score ``points`` (:func:`selected_points`) into the folder ``out`` with the
    ``protocol`` options ``args``; the run's ``ProtocolSummary``."""
    from eoam_sumo.protocols.runner import run_protocol

    return run_protocol(
        args.name,
        points,
        out,
        jobs=args.jobs,
        scheduler=args.scheduler,
        policy=args.policy,
        system=args.system,
        mu=args.mu,
        vehicle=vehicle_label(args),
        vehicle_id=args.vehicle,
        params=vehicle_params(args.vehicle, args.abs, args.esc),
        progress=not args.no_progress,
        max_time_s=MAX_TIME_S,
        sumo_step_s=_sumo_step_s(args),
    )


def _sumo_step_s(args) -> float:
    """``--sumo-step-s`` checked, else the studies' default step."""
    if args.sumo_step_s is None:
        return STUDY_SUMO_STEP_S
    return check_sumo_step_s(args.sumo_step_s, "--sumo-step-s")
