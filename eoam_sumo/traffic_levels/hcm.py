"""Levels of service of the Highway Capacity Manual, and the traffic that meets them.

Motorways (basic freeway segments): the service measure is the density, passenger cars per
mile per lane, with the bands A <= 11, B <= 18, C <= 26, D <= 35, E <= 45 (HCM 6th ed., 2016,
Chapter 12, Exhibit 12-15; unchanged in the 7th ed., 2022). The average speed at each band's
upper density is that of the exhibit's speed-flow curves (FFS 75 mi/h: 75.0, 73.9, 68.3, 60.9,
53.3 mi/h); here as shares of the free-flow speed.

Two-lane (rural) highways: the service measure of the HCM 7th ed. (2022, Chapter 15) is the
follower density, followers per mile per lane: the share of vehicles following (time headway
2.5 s or less) times the density (Eq. 15-35). Bands for posted speeds of 50 mi/h and more:
A <= 2.0, B <= 4.0, C <= 8.0, D <= 12.0, E > 12.0 (below 50 mi/h: 2.5, 5.0, 10.0, 15.0),
as the NCHRP 08-135 implementation of the HCM 7th ed. method codes them
(HCM-Functions-TwoLaneHwy.R, TwoLaneLOSfcn). Capacity of one direction: 1700 veh/h (Exhibit
15-5, not a passing lane). E has no upper bound; here it ends at capacity.

The traffic generated aims at the middle of each band: all passenger cars (one passenger car
equivalent each), arrivals at random (exponential headways) so that the share of followers
of a flow q is 1 - exp(-q h), h = 2.5 s.
"""

from __future__ import annotations

import math

LEVELS = ("A", "B", "C", "D", "E")
MPH_PER_MPS = 3600.0 / 1609.344
KM_PER_MI = 1.609344

#: Basic freeway segments: the upper density of each level [pc/mi/ln] (HCM 6th ed., Exh. 12-15).
FREEWAY_DENSITY_PCMILN = {"A": 11.0, "B": 18.0, "C": 26.0, "D": 35.0, "E": 45.0}
#: The average speed at each level's upper density as a share of the free-flow speed
#: (Exh. 12-15, FFS 75 mi/h: 75.0, 73.9, 68.3, 60.9, 53.3 mi/h).
FREEWAY_SPEED_SHARE = {"A": 1.0, "B": 73.9 / 75, "C": 68.3 / 75, "D": 60.9 / 75, "E": 53.3 / 75}
#: Two-lane highways: the upper follower density of each level [followers/mi/ln], posted
#: speed 50 mi/h and more, and below (HCM 7th ed., Chapter 15); E ends at capacity here.
TWO_LANE_FD_HIGH = {"A": 2.0, "B": 4.0, "C": 8.0, "D": 12.0, "E": 16.0}
TWO_LANE_FD_LOW = {"A": 2.5, "B": 5.0, "C": 10.0, "D": 15.0, "E": 20.0}
TWO_LANE_CAPACITY_VPH = 1700.0  # one direction (Exh. 15-5)
FOLLOWER_HEADWAY_S = 2.5  # a vehicle this close behind its leader or closer is a follower
HIGH_SPEED_MPH = 50.0  # the two-lane bands for posted speeds from this


def band(bounds: dict[str, float], level: str) -> tuple[float, float]:
    """(lower, upper) of a level's band: the upper of the level below, its own upper."""
    i = LEVELS.index(level)
    return (0.0 if i == 0 else bounds[LEVELS[i - 1]]), bounds[level]


def two_lane_bounds(speed_limit_kmh: float) -> dict[str, float]:
    """The two-lane follower-density bands for a posted speed."""
    high = speed_limit_kmh / KM_PER_MI >= HIGH_SPEED_MPH - 1e-9
    return TWO_LANE_FD_HIGH if high else TWO_LANE_FD_LOW


def freeway_target(level: str, speed_limit_kmh: float) -> tuple[float, float]:
    """(density [veh/km/ln], speed [m/s]) at the middle of a freeway level: the band's middle
    density and the speed between those at its ends (free-flow speed: the speed limit)."""
    low, high = band(FREEWAY_DENSITY_PCMILN, level)
    i = LEVELS.index(level)
    share_low = 1.0 if i == 0 else FREEWAY_SPEED_SHARE[LEVELS[i - 1]]
    share = 0.5 * (share_low + FREEWAY_SPEED_SHARE[level])
    return 0.5 * (low + high) / KM_PER_MI, share * speed_limit_kmh / 3.6


def follower_density(flow_vph: float, speed_mps: float) -> float:
    """Follower density [followers/mi/ln] of random arrivals at ``flow_vph`` moving at
    ``speed_mps``: (1 - exp(-q h)) q / S."""
    followers = 1.0 - math.exp(-flow_vph / 3600.0 * FOLLOWER_HEADWAY_S)
    return followers * flow_vph / (speed_mps * MPH_PER_MPS)


def two_lane_target(level: str, speed_limit_kmh: float) -> tuple[float, float]:
    """(density [veh/km/ln], speed [m/s]) of the flow whose follower density is the middle of
    a two-lane level (bisection: the follower density grows with the flow), at the speed
    limit."""
    low, high = band(two_lane_bounds(speed_limit_kmh), level)
    goal = 0.5 * (low + high)
    speed_mps = speed_limit_kmh / 3.6
    q_low, q_high = 0.0, TWO_LANE_CAPACITY_VPH
    for _ in range(60):
        q = 0.5 * (q_low + q_high)
        if follower_density(q, speed_mps) < goal:
            q_low = q
        else:
            q_high = q
    q = 0.5 * (q_low + q_high)
    return q / (speed_mps * 3.6), speed_mps


def level_of(road: str, measure: float, speed_limit_kmh: float) -> str:
    """The level of a measured density (motorway, pc/mi/ln) or follower density (rural,
    followers/mi/ln); "F" beyond E's band."""
    bounds = FREEWAY_DENSITY_PCMILN if road == "motorway" else two_lane_bounds(speed_limit_kmh)
    for level in LEVELS:
        if measure <= bounds[level]:
            return level
    return "F"
