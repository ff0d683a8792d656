"""``eoam-sumo vehicle-test TEST --vehicle NAME [--abs on|off] [--esc on|off] [--speed-kmh V]
[--mu M] --out DIR``: one standard test into ``DIR`` (time series, summary.json, a PNG).

Bad input raises ``InputError`` (the command line prints it on one line, exit status 2). A test
that fails its standard is a result, not an error: the status is 0 and the summary says FAIL.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from eoam_sumo.arguments import finite
from eoam_sumo.fileio import writable_dir
from eoam_sumo.params import MU_MAX
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.clauses import TEST_MU_MIN, TEST_SPEED_RANGE_KMH

TEST_NAMES = (
    "brake",
    "brake-in-turn",
    "brake-ramp",
    "ramp-steer",
    "sine-with-dwell",
    "step-steer",
)
"""The tests (``procedures.TESTS``; named here so the command line starts without the plant)."""


def vehicle_test_mu(text: str) -> float:
    """A road friction in [``TEST_MU_MIN``, ``MU_MAX``]."""
    value = finite(text)
    if not TEST_MU_MIN <= value <= MU_MAX:
        raise argparse.ArgumentTypeError(f"mu {text} is outside [{TEST_MU_MIN:g}, {MU_MAX:g}]")
    return value


def vehicle_test_speed_kmh(text: str) -> float:
    """A test speed [km/h] within ``TEST_SPEED_RANGE_KMH``."""
    value = finite(text)
    low, high = TEST_SPEED_RANGE_KMH
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"speed {text} km/h is outside [{low:g}, {high:g}]")
    return value


def add_arguments(subparsers) -> None:
    """Register ``vehicle-test`` on the command line's sub-parsers."""
    p = subparsers.add_parser("vehicle-test", help="a standard vehicle test of the plant")
    p.add_argument("test", choices=TEST_NAMES, help="the test")
    p.add_argument(
        "--vehicle", default="sedan", help="a catalogue name or a vehicle file (default: sedan)"
    )
    p.add_argument("--abs", choices=("on", "off"), help="ABS (default: the vehicle's own)")
    p.add_argument("--esc", choices=("on", "off"), help="ESC (default: the vehicle's own)")
    p.add_argument(
        "--speed-kmh",
        type=vehicle_test_speed_kmh,
        help="test speed, 1-300 km/h (default: the standard's)",
    )
    p.add_argument(
        "--mu", type=vehicle_test_mu, default=1.0, help="road friction, 0.05-1.2 (default 1.0)"
    )
    p.add_argument("--out", type=Path, required=True, help="output folder")


def run(args) -> int:
    """Run the test, write its files and figure, print the verdict (with its reasons) and
    where they are."""
    from eoam_sumo.plotting.vehicle_tests import plot_vehicle_test
    from eoam_sumo.vehicle_tests.common import verdict_text
    from eoam_sumo.vehicle_tests.equipment import equipped
    from eoam_sumo.vehicle_tests.output import write_result
    from eoam_sumo.vehicle_tests.procedures import TESTS, VehicleTestOptions

    vehicle = load_vehicle(args.vehicle)
    params = equipped(
        vehicle,
        vehicle.abs_fitted if args.abs is None else args.abs == "on",
        vehicle.esc_fitted if args.esc is None else args.esc == "on",
    )
    out = writable_dir(args.out)
    result = TESTS[args.test](params, VehicleTestOptions(speed_kmh=args.speed_kmh, mu=args.mu))
    summary = write_result(result, out)
    runs = [(r.label, r.columns) for r in result.runs]
    png = plot_vehicle_test(summary, runs, out / f"{args.test}.png")
    print(f"{args.test}: {verdict_text(summary)}; {out / 'summary.json'}, {png}")
    return 0
