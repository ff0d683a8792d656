"""ABS and ESC switched per test run, and the wheel speeds from the plant's outputs."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant import OUTPUT_NAMES

_FRONT = OUTPUT_NAMES.index("wheel_speed_front_mps")
_REAR = OUTPUT_NAMES.index("wheel_speed_rear_mps")


def equipped(params: VehicleParams, abs_on: bool, esc_on: bool) -> VehicleParams:
    """``params`` with ABS and ESC switched on or off."""
    return dataclasses.replace(params, abs_fitted=abs_on, esc_fitted=esc_on)


def wheel_speeds(outputs: Sequence[float]) -> tuple[float, float]:
    """Front and rear wheel circumferential speeds [m/s] (the wheel-spin states times the
    effective radius, from the plant's outputs)."""
    return outputs[_FRONT], outputs[_REAR]
