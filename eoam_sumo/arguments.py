"""Command-line value types shared by the sub-commands: each returns the value or raises
``argparse.ArgumentTypeError`` naming it (argparse then prints one line, exit status 2)."""

from __future__ import annotations

import argparse
import math

from eoam_sumo.params import MU_MAX


def finite(text: str) -> float:
    """A finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def mu(text: str) -> float:
    """A tyre-road friction in (0, MU_MAX]."""
    value = finite(text)
    if not 0.0 < value <= MU_MAX:
        raise argparse.ArgumentTypeError(f"mu {text} is outside (0, {MU_MAX:g}]")
    return value


def speed_kmh(text: str) -> float:
    """A speed [km/h] above zero."""
    value = finite(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"speed {text} km/h must be > 0")
    return value


def sumo_step_argument(p: argparse.ArgumentParser, study: bool = False) -> None:
    """``run``, ``batch`` and ``protocol``: SUMO's step in a multi-rate co-simulation (a
    ``study``'s default is ``STUDY_SUMO_STEP_S``, a run's the 10 ms reference)."""
    default = "0.05 for a study" if study else "0.01, the reference"
    p.add_argument(
        "--sumo-step-s",
        type=finite,
        metavar="S",
        help=f"SUMO's step, 0.01 to 0.1 s (default {default}): road users "
        "interpolated between SUMO's steps, control at 100 Hz, plant at 1 kHz",
    )
