"""The one place that touches chassis features today's plant does not have yet.

TODO(chassis branch): the rebuilt plant adds ``VehicleParams.abs_fitted``,
``VehicleParams.esc_fitted`` and the outputs ``wheel_speed_front_mps``,
``wheel_speed_rear_mps``. Both functions below already use them when they exist; at the merge
drop the fallbacks (the ``hasattr`` branch and the lock-flag wheel speeds).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from eoam_sumo.errors import InputError
from eoam_sumo.params import VehicleParams
from eoam_sumo.plant import OUTPUT_NAMES

_OUTPUT_INDEX = {name: i for i, name in enumerate(OUTPUT_NAMES)}


def equipped(params: VehicleParams, abs_on: bool, esc_on: bool) -> VehicleParams:
    """``params`` with ABS and ESC switched on or off; ``InputError`` when a system is asked
    for and the plant has none (today's plant: no ABS, no ESC, so "off" is the car as is)."""
    changes: dict[str, bool] = {}
    for wanted, field, system in ((abs_on, "abs_fitted", "ABS"), (esc_on, "esc_fitted", "ESC")):
        if hasattr(params, field):
            changes[field] = wanted
        elif wanted:
            raise InputError(f"--{system.lower()} on: this plant has no {system}")
    return dataclasses.replace(params, **changes) if changes else params  # type: ignore[arg-type]


def abs_fitted(params: VehicleParams) -> bool:
    """Is ABS fitted and on (False on today's plant, which has none)?"""
    return bool(getattr(params, "abs_fitted", False))


def esc_fitted(params: VehicleParams) -> bool:
    """Is ESC fitted and on (False on today's plant, which has none)?"""
    return bool(getattr(params, "esc_fitted", False))


def wheel_speeds(outputs: Sequence[float], vx_mps: float) -> tuple[float, float]:
    """Front and rear wheel circumferential speeds [m/s] from the plant's outputs.

    Until the plant has wheel-spin states (TODO chassis branch) an axle's wheel speed is the
    body speed ``vx_mps`` (not below zero) while it rolls and 0 while its lock flag is set.
    """
    if "wheel_speed_front_mps" in _OUTPUT_INDEX:
        return (
            outputs[_OUTPUT_INDEX["wheel_speed_front_mps"]],
            outputs[_OUTPUT_INDEX["wheel_speed_rear_mps"]],
        )
    rolling_mps = max(vx_mps, 0.0)
    front = 0.0 if outputs[_OUTPUT_INDEX["front_locked"]] > 0.5 else rolling_mps
    rear = 0.0 if outputs[_OUTPUT_INDEX["rear_locked"]] > 0.5 else rolling_mps
    return front, rear
