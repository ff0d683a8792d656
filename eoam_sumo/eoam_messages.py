"""The per-step messages into and out of the EOAM module (``eoam.EoamController.step``):
named tuples (immutable), and ``NextLaneView``, what sensing (``sensing.next_lane``) knows of the
next lane for the decision policy (``decision.policy``), carried in ``Perception.next_lane``."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

#: The motion classes of a road user in the lane a lane change would take
#: (:func:`next_lane_motion`), shared by the radar's classes and the decision policy's checks.
STANDING, ONCOMING, WITH = "standing", "oncoming", "with"
#: ... standing below this road speed either way [m/s]
NEXT_LANE_STANDING_MPS = 0.5


def next_lane_motion(road_speed_mps: float, stationary_mps: float = NEXT_LANE_STANDING_MPS) -> str:
    """The motion class of a road user in the lane a lane change would take, by its road speed:
    ``ONCOMING`` towards the ego at ``stationary_mps`` or more, ``STANDING`` below it either
    way, ``WITH`` the ego's way at it or more. The classes meet: a van creeping towards the ego
    at 1.5 m/s is oncoming (the radar's and the paper's rules judge the first two, the paper
    policy's commit check ``WITH``)."""
    if road_speed_mps <= -stationary_mps:
        return ONCOMING
    if road_speed_mps < stationary_mps:
        return STANDING
    return WITH


class EgoMeasurement(NamedTuple):
    """Ego state in the road frame of its original lane (s along, d left of its centre)."""

    time_s: float
    vx_mps: float
    vy_mps: float
    yaw_rate_radps: float
    ax_mps2: float
    ay_mps2: float
    s_m: float
    d_m: float
    e_yaw_rad: float
    road_curvature_1pm: float
    mu: float
    lane_width_m: float
    left_lane_available: bool = True  # map: a lane (either direction) left of the ego's lane
    # the friction believed for a lane change to the right (``mu``: to the left); 0: ``mu``
    mu_right: float = 0.0
    # the friction believed under the ego, for braking in its lane (``mu`` is the lower of it
    # and the lane a lane change takes, for planning one); 0: ``mu``
    mu_lane: float = 0.0


class ObjectState(NamedTuple):
    """A tracked object in the road frame of the ego's original lane (a sensor's object list)."""

    s_m: float  # station of its centre
    d_m: float  # lateral offset of its centre, left positive
    speed_mps: float  # along the road
    length_m: float
    width_m: float
    time_s: float | None = None  # when this state held (a sensor's latency; None: now)


class Perception(NamedTuple):
    """Radar-derived view: the in-path obstacle (None when nothing) and oncoming traffic."""

    aro_range_m: float | None = None
    aro_range_rate_mps: float | None = None
    oncoming_detected: bool = False
    aro_object: ObjectState | None = None  # the in-path obstacle as an object, when tracked
    next_lane_obstacle_range_m: float | None = None  # nearest standing object in the next lane
    next_lane: NextLaneView | None = None  # what is known of the next lane (safe policy)
    # an in-path object the radar lost from view at close range, predicted at its last
    # velocity (a coasted track): its range and range rate now, or None
    coasted_range_m: float | None = None
    coasted_range_rate_mps: float = 0.0
    oncoming_object: ObjectState | None = None  # the nearest oncoming road user, when tracked
    # what is known of the lane right of the ego's, when it has one its class may use (the
    # EOAM may then evade right: ``next_lane`` is the left one)
    right_lane: NextLaneView | None = None


class Command(NamedTuple):
    """Actuator commands for the next step plus what the controller decided, for logging."""

    steer_cmd_rad: float
    drive_force_cmd_n: float
    brake_force_cmd_n: float
    mode: int
    fcw: bool
    sector: str
    ax_target_mps2: float
    y_target_m: float
    dx_m: float
    lateral_error_m: float
    lookahead_error_m: float
    steer_ff_rad: float
    steer_fb_rad: float
    steer_yd_rad: float
    speed_target_mps: float


class NextLaneView:
    """What the sensors know of a lane beside the ego's original lane, the target of a lane
    change (road frame of the original lane; distances along the road from the ego's front
    bumper, or from its rear behind it).

    The covered length is worked out only when read (``coverage`` a function returning it):
    the policy needs it at a commit, and its geometry is the costly part."""

    __slots__ = (
        "_coverage",
        "_coverage_m",
        "accel_ahead_mps2",
        "ahead",
        "coverage_behind_m",
        "lane_width_m",
        "nearest_ahead_m",
        "nearest_ahead_speed_mps",
        "nearest_behind_accel_mps2",
        "nearest_behind_m",
        "nearest_behind_speed_mps",
        "opposing",
        "side",
        "speed_limit_mps",
    )

    def __init__(
        self,
        opposing: bool,
        speed_limit_mps: float,
        *,
        coverage_ahead_m: float | None = None,
        coverage: Callable[[], float] | None = None,
        nearest_ahead_m: float | None = None,
        nearest_ahead_speed_mps: float | None = None,
        nearest_behind_m: float | None = None,
        nearest_behind_speed_mps: float | None = None,
        ahead: tuple[tuple[float, float], ...] | None = None,
        coverage_behind_m: float | None = None,
        side: int = 1,
        lane_width_m: float = 0.0,
        accel_ahead_mps2: tuple[float, ...] | None = None,
        nearest_behind_accel_mps2: float = 0.0,
    ):
        self.opposing = opposing  # the lane carries opposing traffic
        self.speed_limit_mps = speed_limit_mps  # its speed limit (net file)
        self._coverage_m = coverage_ahead_m
        self._coverage = coverage
        self.nearest_ahead_m = nearest_ahead_m  # gap to the nearest road user in it ahead
        self.nearest_ahead_speed_mps = nearest_ahead_speed_mps  # its road speed (< 0: towards)
        self.nearest_behind_m = nearest_behind_m  # gap to the nearest road user in it behind
        self.nearest_behind_speed_mps = nearest_behind_speed_mps
        self.ahead = ahead  # (gap, road speed) of every road user in it ahead, nearest first
        self.coverage_behind_m = coverage_behind_m  # length behind the rear seen (None: unknown)
        self.side = side  # +1: the lane left of the ego's, -1: the lane right of it
        self.lane_width_m = lane_width_m  # its width (0: as the ego's lane)
        # the road users' accelerations along the road where known (0: taken as constant
        # speed): of each one in ``ahead``, in its order, and of the nearest behind
        self.accel_ahead_mps2 = accel_ahead_mps2
        self.nearest_behind_accel_mps2 = nearest_behind_accel_mps2

    @property
    def coverage_ahead_m(self) -> float:
        """Length ahead covered by the sensors without a gap."""
        if self._coverage_m is None:
            self._coverage_m = self._coverage() if self._coverage is not None else 0.0
        return self._coverage_m

    @property
    def known_free_ahead_m(self) -> float:
        """Covered and empty: the covered length or the gap to the nearest road user ahead."""
        cover = self.coverage_ahead_m
        return cover if self.nearest_ahead_m is None else min(cover, self.nearest_ahead_m)

    def users_ahead(self) -> tuple[tuple[float, float], ...]:
        """(gap, road speed) of the road users ahead in the lane, nearest first."""
        if self.ahead is not None:
            return self.ahead
        if self.nearest_ahead_m is None:
            return ()
        return ((self.nearest_ahead_m, self.nearest_ahead_speed_mps or 0.0),)

    def users_ahead_accel(self) -> tuple[tuple[float, float, float], ...]:
        """(gap, road speed, acceleration along the road; 0 where unknown) of the road users
        ahead in the lane, nearest first."""
        users = self.users_ahead()
        accel = self.accel_ahead_mps2
        if accel is None or len(accel) != len(users):
            return tuple((gap, speed, 0.0) for gap, speed in users)
        return tuple((gap, speed, a) for (gap, speed), a in zip(users, accel))
