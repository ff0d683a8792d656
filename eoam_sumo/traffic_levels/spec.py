"""What a generated traffic scenario is: the road, its level of service, its lanes, speed
limit and curve, and the seed; checked values with the road's defaults."""

from __future__ import annotations

import math
from dataclasses import dataclass

from eoam_sumo.errors import InputError
from eoam_sumo.offline.tables import LookupTables
from eoam_sumo.seeds import check_seed
from eoam_sumo.traffic_levels.hcm import LEVELS

ROADS = ("rural", "motorway")
#: Defaults per road: lanes of the ego's direction, speed limit [km/h].
DEFAULT_LANES = {"rural": 1, "motorway": 3}
DEFAULT_SPEED_LIMIT_KMH = {"rural": 100.0, "motorway": 120.0}
MAX_LANES = 6
#: The tightest curve accepted [m]: the EOAM's tables are built on a straight road; 150 m is
#: a design radius for about 70 km/h (any tighter is a bend for walking speeds here).
MIN_CURVE_RADIUS_M = 150.0
#: The lowest speed limit accepted [km/h]; the highest is the top of the default tables'
#: speed grid (``max_speed_limit_kmh``): the ego departs at the speed limit.
MIN_SPEED_LIMIT_KMH = 30.0


def max_speed_limit_kmh() -> float:
    """The highest speed limit a generated scenario may have [km/h]: the top entry speed
    ``run`` accepts on the default tables (``LookupTables.check_run``)."""
    return LookupTables.cached().entry_speed_range_mps()[1] * 3.6


@dataclass(frozen=True)
class TrafficSpec:
    """A generated scenario's road and traffic (``check`` gives the defaults and checks)."""

    road: str
    los: str
    lanes: int | None = None  # motorway: lanes of its carriageway (rural: 1 each way)
    speed_limit_kmh: float | None = None
    curve_radius_m: float | None = None  # None: straight (rural only)
    seed: int = 0

    def checked(self) -> TrafficSpec:
        """The spec with its road's defaults filled in; InputError naming a bad value."""
        if self.road not in ROADS:
            raise InputError(f"road {self.road!r} is not one of {', '.join(ROADS)}")
        if self.los not in LEVELS:
            raise InputError(f"level of service {self.los!r} is not one of {', '.join(LEVELS)}")
        lanes = DEFAULT_LANES[self.road] if self.lanes is None else self.lanes
        if self.road == "rural" and lanes != 1:
            raise InputError(f"lanes {lanes}: a rural road has one lane each way")
        if self.road == "motorway" and not 2 <= lanes <= MAX_LANES:
            raise InputError(f"lanes {lanes}: a motorway has 2 to {MAX_LANES} lanes")
        limit = self.speed_limit_kmh
        limit = DEFAULT_SPEED_LIMIT_KMH[self.road] if limit is None else float(limit)
        low, high = MIN_SPEED_LIMIT_KMH, max_speed_limit_kmh()
        if not (math.isfinite(limit) and low <= limit <= high + 1e-9):
            raise InputError(f"speed limit {limit:g} km/h is outside [{low:g}, {high:g}]")
        radius = self.curve_radius_m
        if radius is not None:
            if self.road != "rural":
                raise InputError("a curve radius applies to a rural road only")
            if not (math.isfinite(radius) and radius >= MIN_CURVE_RADIUS_M):
                raise InputError(f"curve radius {radius:g} m must be >= {MIN_CURVE_RADIUS_M:g}")
            radius = float(radius)
        check_seed(self.seed, "seed")
        return TrafficSpec(self.road, self.los, lanes, limit, radius, self.seed)
