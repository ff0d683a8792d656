"""Points of a manoeuvre: a trajectory of the lookup tables and a sampled reference, each at
one differential x-position dx since the trigger (paper sec. 8.2)."""

from __future__ import annotations

import math
from typing import NamedTuple


class TrajectoryPoint(NamedTuple):
    """A manoeuvre trajectory at one differential x-position (the tables' columns)."""

    y_m: float  # lateral position of the path
    ax_mps2: float  # body longitudinal acceleration (the optimised profile)
    yaw_rad: float  # path direction of travel (course)
    curvature_1pm: float  # signed path curvature, left positive
    steer_rad: float  # road-wheel steering angle (planned with the plant's tyre)
    sideslip_rad: float = math.nan  # body sideslip (course less body yaw); NaN: not planned


class PathPoint(NamedTuple):
    """A sampled manoeuvre reference at one differential x-position."""

    y_m: float  # lateral position (road frame, left positive)
    yaw_rad: float  # path direction of travel relative to the road
    curvature_1pm: float  # signed path curvature, left positive; a planned lane change's
    # (planned sideslip) is its body's yaw per metre, the course's less the sideslip's rate
    ax_mps2: float  # planned longitudinal acceleration
    speed_mps: float  # planned speed
    steer_rad: float  # planned road-wheel angle (0: not planned)
    sideslip_rad: float  # planned body sideslip, course less body yaw (0: not planned)
