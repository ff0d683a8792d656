"""Angle wrapping."""

from __future__ import annotations

import math


def wrap_angle(angle_rad: float) -> float:
    """Angle wrapped to [-pi, pi) (one a rounding error below -pi comes out as pi)."""
    if -math.pi <= angle_rad < math.pi:
        return angle_rad
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi
