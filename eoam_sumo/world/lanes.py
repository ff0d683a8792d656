"""The ego's lane band and the motion classes of road users: one home for the thresholds the
radar's classes, the ground-truth roles of the outcome, the margins and the traffic log share.

The lane band is the ego's original lane widened by ``LANE_MARGIN_M`` beyond each marker, on
a road user's centre offset d in the road frame of that lane (:class:`RoadProjection`, d
positive to the left). A road user's road speed is its speed times the cosine of its heading
relative to the road: below ``-ONCOMING_SPEED_MPS`` it is oncoming traffic to the radar, and
under ``STATIONARY_SPEED_MPS`` (in absolute value) it is standing. In the lane a lane change
would take the two classes meet (:func:`eoam_sumo.eoam_messages.next_lane_motion`): there
every road user is standing, oncoming, or moving the ego's way.
"""

from __future__ import annotations

import math
from typing import Protocol

#: Below this speed a road user counts as standing [m/s]: SUMO reports exactly 0 for parked
#: and stopped vehicles, and automotive radars resolve Doppler to about 0.1-0.3 m/s.
STATIONARY_SPEED_MPS = 0.5
#: Moving against the road direction faster than this is oncoming traffic [m/s] (7 km/h,
#: well above the stationary threshold, far below the 20 m/s oncoming ARO of sec. 10.2).
ONCOMING_SPEED_MPS = 2.0
#: The ego lane band reaches this far beyond each lane marker [m]: a 1.8 m wide car whose
#: centre is 0.5 m outside the marker still covers 0.4 m of the lane; a parked car 1.5 m
#: beyond the marker (centre ~2.4 m beyond) and an oncoming car centred in the next lane
#: (1.75 m beyond) are outside.
LANE_MARGIN_M = 0.5
#: A road user heading more than this off the road's direction, moving faster than
#: ``ONCOMING_SPEED_MPS``, crosses the ego's lane (cross traffic at a junction) [rad].
CROSSING_ANGLE_RAD = math.radians(45.0)


class RoadProjection(Protocol):
    """Road frame of the ego's original lane (``eoam_sumo.sim.roadframe.RoadFrame``)."""

    def project(self, x: float, y: float) -> tuple[float, float, float]:
        """(s_m, d_m, road_yaw_rad) of a network point; d positive to the left."""
        ...


def lane_band_m(lane_width_m: float, margin_m: float = LANE_MARGIN_M) -> float:
    """Half-width [m] of the band around a lane's centre line that counts as in the lane."""
    return 0.5 * lane_width_m + margin_m


#: The width of the car ``LANE_MARGIN_M`` is set for: its centre at the band's edge puts 0.4 m
#: of it in the lane [m].
MARGIN_CAR_WIDTH_M = 1.8


def body_band_m(band_m: float, width_m: float) -> float:
    """The band for a road user ``width_m`` wide: one narrower than ``MARGIN_CAR_WIDTH_M`` (a
    person, a bicycle) counts as in the lane only as far into it as that car (a person on the
    pavement beside the lane, 0.1 m over its marker, is not in it); a wider one as the car."""
    return band_m - 0.5 * max(MARGIN_CAR_WIDTH_M - width_m, 0.0)


def crosses_lane(speed_mps: float, yaw_rad: float, road_yaw_rad: float) -> bool:
    """Whether a road user crosses the road rather than follows it: heading more than
    ``CROSSING_ANGLE_RAD`` off the road's direction (either way), faster than
    ``ONCOMING_SPEED_MPS`` (a person walking across at 1.5 m/s does not count)."""
    along = abs(math.cos(yaw_rad - road_yaw_rad))
    return abs(speed_mps) > ONCOMING_SPEED_MPS and along < math.cos(CROSSING_ANGLE_RAD)
