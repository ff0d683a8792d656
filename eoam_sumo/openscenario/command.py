"""The ``run`` command's OpenSCENARIO options: ``--param NAME=VALUE`` (repeatable)."""

from __future__ import annotations

import sys
from dataclasses import replace
from typing import TYPE_CHECKING

from eoam_sumo.errors import InputError

if TYPE_CHECKING:
    from eoam_sumo.openscenario.runner import Loaded


def xosc_arguments(p) -> None:
    """Add ``--param`` to the ``run`` parser."""
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="an .xosc parameter's value (repeatable)",
    )
    p.add_argument(
        "--system",
        choices=("eoam", "aeb"),
        default=None,
        help="of an .xosc: eoam (default) or aeb (braking only, as `protocol --system aeb`)",
    )


def is_xosc(args) -> bool:
    """Whether ``run`` was given an OpenSCENARIO file (.xosc, .xosp, or any file whose root
    is ``<OpenSCENARIO>``; a folder is not one)."""
    from eoam_sumo.openscenario.reader import is_openscenario

    return not args.cfg.is_dir() and is_openscenario(args.cfg)


def parse_params(items: list[str]) -> dict[str, str]:
    """``NAME=VALUE`` items as a dict; InputError naming a malformed one."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise InputError(f"--param {item!r}: expected NAME=VALUE")
        out[name.strip()] = value.strip()
    return out


def prepare_command(args) -> Loaded:
    """Check the options an .xosc run takes and load the scenario (refusals before output)."""
    given = (
        ("--speed-kmh", args.speed_kmh),
        ("--oncoming-m", args.oncoming_m),
        ("--aro-hold-s", getattr(args, "aro_hold_s", None)),
        ("--aro-decel-mps2", getattr(args, "aro_decel_mps2", None)),
    )
    for flag, value in given:
        if value is not None:
            raise InputError(f"{flag} does not apply to an .xosc (set its parameters: --param)")
    from eoam_sumo.openscenario.runner import load  # the engine: only for an .xosc

    return load(args.cfg, parse_params(args.param), args.ego, _ego_speed_range(args))


def _ego_speed_range(args) -> tuple[float, float]:
    """The ego's departure speeds the run's tables cover (``--vehicle``, ``--tables``)."""
    from eoam_sumo.openscenario.runner import ego_speed_range_mps
    from eoam_sumo.sim.settings import RunSettings
    from eoam_sumo.sim.vehicle import load_vehicle  # via sim (tests/test_layers.py)

    settings = RunSettings(tables_dir=args.tables)
    if args.vehicle is not None:
        settings = replace(
            settings, vehicle=load_vehicle(args.vehicle), vehicle_id=str(args.vehicle)
        )
    return ego_speed_range_mps(settings)


def run_xosc_command(args, loaded: Loaded, out, settings) -> dict:
    """Run the loaded scenario; notes on what was not applied go to stderr, one line each."""
    for note in dict.fromkeys(loaded.plan.notes):
        print(f"eoam-sumo: {args.cfg.name}: {note}", file=sys.stderr)
    if args.system == "aeb":
        settings = replace(settings, eoam=replace(settings.eoam, steering_inhibited=True))
    from eoam_sumo.openscenario.runner import run_loaded

    return run_loaded(loaded, out, settings, args.mu)


def refuse_params_for_sumocfg(args) -> None:
    """``--param`` only applies to an .xosc."""
    if (args.param or args.system) and not is_xosc(args):
        raise InputError("--param and --system apply to an .xosc scenario only")
