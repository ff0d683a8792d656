"""CCFhol's oncoming lane change: the Global Vehicle Target's path as a polyline. Pure.

Source: Vector's encoding of Euro NCAP's AEB C2C 2023 CCFhol,
github.com/vectorgrp/OSC-NCAP-scenarios@ee7aa11 (MPL-2.0),
``OpenSCENARIO/NCAP/Catalogs/Trajectories/TrajectoryCatalog.xosc`` trajectories
``GVT_CCFhol_50`` and ``GVT_CCFhol_70`` (clothoid splines of constant-curvature segments, the
protocol's lane change distance L 44 and 60 m) followed by ``NCAP_AEB_C2C_CCFhol_2023.xosc``
(``FollowTrajectoryAction``, position mode, the target at the VUT's speed).

Ours: a target faster than 70 km/h (the 2026 rows at 90 and 100 km/h) follows the 70 km/h path
stretched by v / 70 along its length with its curvature times (70 / v)^2: the same lateral
shift and the same peak lateral acceleration v^2 kappa (1.5 m/s^2). Each path's lateral shift
is scaled to the protocol's lateral distance O (3.45-3.46 m as integrated -> 3.5 m).
"""

from __future__ import annotations

import math

#: (curvature [1/m], length [m]) of each segment, in the GVT's frame (positive: to its left)
VECTOR_PATHS: dict[float, tuple[tuple[float, float], ...]] = {
    50.0: (
        (0.008, 15.0),
        (0.006, 1.0),
        (0.001, 1.0),
        (0.0, 10.0),
        (-0.006, 1.0),
        (-0.008, 15.0),
    ),
    70.0: ((0.004, 24.0), (0.001, 1.0), (0.0, 10.0), (-0.001, 1.0), (-0.004, 24.0)),
}
PATH_STEP_M = 1.0


def segments(target_speed_kmh: float) -> tuple[tuple[float, float], ...]:
    """The path's segments for a target speed: Vector's at 50 and 70 km/h, the 70 km/h one
    stretched above it (module docstring); ValueError below 50 or between the two."""
    if target_speed_kmh in VECTOR_PATHS:
        return VECTOR_PATHS[target_speed_kmh]
    if target_speed_kmh > 70.0:
        k = target_speed_kmh / 70.0
        return tuple((c / k**2, length * k) for c, length in VECTOR_PATHS[70.0])
    raise ValueError(f"no CCFhol lane change path for a target at {target_speed_kmh:g} km/h")


def path_length_m(target_speed_kmh: float) -> float:
    """The lane change's length along its path (the protocol's L) [m]."""
    return sum(length for _, length in segments(target_speed_kmh))


def _integrate(segs: tuple[tuple[float, float], ...]) -> list[tuple[float, float]]:
    """(along, left) points of the path every ``PATH_STEP_M`` or less, exact on each arc."""
    x = y = heading = 0.0
    out = [(0.0, 0.0)]
    for curvature, length in segs:
        n = max(1, math.ceil(length / PATH_STEP_M - 1e-9))
        ds = length / n
        for _ in range(n):
            end = heading + curvature * ds
            if curvature:
                x += (math.sin(end) - math.sin(heading)) / curvature
                y += (math.cos(heading) - math.cos(end)) / curvature
            else:
                x += math.cos(heading) * ds
                y += math.sin(heading) * ds
            heading = end
            out.append((x, y))
    return out


def path_points(target_speed_kmh: float, shift_m: float) -> list[tuple[float, float]]:
    """The path in the target's frame: (distance along its travel, shift to its left) [m],
    from (0, 0) to (extent, ``shift_m``)."""
    points = _integrate(segments(target_speed_kmh))
    scale = shift_m / points[-1][1]
    return [(a, b * scale) for a, b in points]


def path_extent_m(target_speed_kmh: float) -> float:
    """How far along the road the lane change reaches [m] (a little under its length)."""
    return _integrate(segments(target_speed_kmh))[-1][0]
