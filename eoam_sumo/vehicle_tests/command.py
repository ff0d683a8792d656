"""``eoam-sumo vehicle-test TEST --vehicle NAME [--abs on|off] [--esc on|off] [--speed-kmh V]
[--mu M] --out DIR``: one standard test into ``DIR`` (time series, summary.json, a PNG).

Bad input raises ``InputError`` (the command line prints it on one line, exit status 2). A test
that fails its standard is a result, not an error: the status is 0 and the summary says FAIL.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.params import MU_MAX, VehicleParams, ego_e_class_sedan

TEST_NAMES = ("brake", "brake-ramp", "ramp-steer", "sine-with-dwell", "step-steer")
"""The tests (``procedures.TESTS``; named here so the command line starts without the plant)."""

VEHICLES = {"sedan": ego_e_class_sedan}
"""The vehicles a test can drive, by name."""


def vehicle(name: str) -> VehicleParams:
    """The parameters of the vehicle called ``name``; ``InputError`` naming it if unknown."""
    try:
        return VEHICLES[name]()
    except KeyError:
        known = ", ".join(sorted(VEHICLES))
        raise InputError(f"--vehicle {name!r}: unknown vehicle (known: {known})") from None


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def _speed_kmh(text: str) -> float:
    value = _number(text)
    if not 0.0 < value <= 250.0:
        raise argparse.ArgumentTypeError(f"speed {text} km/h is outside (0, 250]")
    return value


def _mu(text: str) -> float:
    value = _number(text)
    if not 0.0 < value <= MU_MAX:
        raise argparse.ArgumentTypeError(f"mu {text} is outside (0, {MU_MAX:g}]")
    return value


def add_arguments(subparsers) -> None:
    """Register ``vehicle-test`` on the command line's sub-parsers."""
    p = subparsers.add_parser("vehicle-test", help="a standard vehicle test of the plant")
    p.add_argument("test", choices=TEST_NAMES, help="the test")
    p.add_argument("--vehicle", default="sedan", help="the vehicle (default: sedan)")
    p.add_argument("--abs", choices=("on", "off"), default="off", help="ABS (default off)")
    p.add_argument("--esc", choices=("on", "off"), default="off", help="ESC (default off)")
    p.add_argument("--speed-kmh", type=_speed_kmh, help="test speed (default: the standard's)")
    p.add_argument("--mu", type=_mu, default=1.0, help="road friction (default 1.0)")
    p.add_argument("--out", type=Path, required=True, help="output folder")


def run(args) -> int:
    """Run the test, write its files and figure, print where and the verdict."""
    from eoam_sumo.plotting.vehicle_tests import plot_vehicle_test
    from eoam_sumo.vehicle_tests.equipment import equipped
    from eoam_sumo.vehicle_tests.output import writable_dir, write_result
    from eoam_sumo.vehicle_tests.procedures import TESTS, VehicleTestOptions

    params = equipped(vehicle(args.vehicle), args.abs == "on", args.esc == "on")
    out = writable_dir(args.out)
    result = TESTS[args.test](params, VehicleTestOptions(speed_kmh=args.speed_kmh, mu=args.mu))
    summary = write_result(result, out)
    runs = [(r.label, r.columns) for r in result.runs]
    png = plot_vehicle_test(summary, runs, out / f"{args.test}.png")
    verdict = {True: "PASS", False: "FAIL", None: "figures only"}[summary["passed"]]
    print(f"{args.test}: {verdict}; {out / 'summary.json'}, {png}")
    return 0
