"""Seeds: one range wherever a seed is taken (command line, matrices, generated scenarios)."""

from __future__ import annotations

import argparse

from eoam_sumo.errors import InputError

SEED_MAX = 2**31 - 1
"""The largest seed: SUMO reads ``--seed`` and ``<seed value=...>`` as a C ``int`` and refuses
2147483648 ("Could not parse commandline options"); the random models share its range."""


def check_seed(value, where: str) -> int:
    """``value`` as a seed; ``InputError`` naming ``where`` and the value unless it is an
    integer in [0, ``SEED_MAX``]."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= SEED_MAX:
        raise InputError(f"{where} = {value!r} must be an integer in [0, {SEED_MAX}]")
    return value


def sumo_seed(seed: int, offset: int) -> int:
    """SUMO's seed for attempt ``offset`` of a seed: ``seed + offset`` within SUMO's range."""
    return (seed + offset) % (SEED_MAX + 1)


def seed_argument(text: str) -> int:
    """``--seed``'s type: a seed, or ``argparse.ArgumentTypeError`` naming the text."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed {text!r} is not an integer") from None
    try:
        return check_seed(value, "seed")
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
