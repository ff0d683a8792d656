"""The paper's rules and ours, one class each, chosen once from ``EoamSettings`` (``parts``).

======================== ================================= ====================================
choice (setting)         the paper                         ours (the default)
======================== ================================= ====================================
DMM placement            ``PaperPlacement``: (range,       ``BrakingObstaclePlacement``: also
(obstacle_decel_in_dmm)  closing speed) as if the          where its measured braking stops it
                         obstacle held its speed
point of no return       ``OffsetPonr``: the offset        ``LateralStopPonr``: where the
(ponr_at_lateral_stop)   reached (sec. 8.1)                lateral motion stops if arrested now
commit on oncoming       ``PonrCommit``: the point of no   ``CompareOutcomes``: the lower
(compare_outcomes)       return                            predicted delta-v (decision.oncoming)
escapes (min_time_       ``QuinticEscapes``: quintics,     ``ArrestFirst``: time-optimal shifts
escapes, arrest_first)   mode 3 stops the lateral motion   (``MinTimeEscapes``), mode 3 first
                         and holds, then back              arrests at the envelope edge
early return             ``TimerReturn``: the manoeuvre    ``StableReturn``: also once stable
(return_when_stable)     timer alone                       in the next lane and clear
next lane (policy)       ``NextLaneGate``: oncoming        ``SafeGate``: the safe policy's
                         traffic only                      sight and tie-breaker checks
======================== ================================= ====================================
"""

from __future__ import annotations

import math

from eoam_sumo.control.steering import SteeringController
from eoam_sumo.decision.dmm import SECTOR_ORDER, BoundaryCurve, Sector
from eoam_sumo.decision.modes import ONCOMING_STEER_BRAKE, UPDATE_STEER_BRAKE
from eoam_sumo.decision.obstacle import (
    ObstacleTrack,
    speed_match_factor,
    stopping_range_m,
    travel_m,
)
from eoam_sumo.decision.oncoming import Budget, commit_choice, return_clears
from eoam_sumo.decision.policy import SafePolicy, SightNeed, follower_keeps_distance
from eoam_sumo.eoam.shifts import lateral_stop, min_time_shift, quintic_shift
from eoam_sumo.eoam.state import ControllerState
from eoam_sumo.eoam_messages import EgoMeasurement, Perception
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.manoeuvre.angles import wrap_angle
from eoam_sumo.manoeuvre.lateral_state import lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.manoeuvre.path_reference import PathReference
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift
from eoam_sumo.params import G_MPS2, VehicleParams


# ---------------------------------------------------------------------------- DMM placement
class PaperPlacement:
    """The paper's DMM (sec. 5-6): the sector of (range, closing speed), as if the obstacle
    held its speed."""

    def track_decel_mps2(self, filtered_mps2: float) -> float:
        """The braking the obstacle's track predicts with: none."""
        return 0.0

    def place(
        self,
        curve: BoundaryCurve,
        range_m: float,
        closing_mps: float,
        speed_mps: float,
        decel: float,
        ego_decel_mps2: float,
    ) -> tuple[Sector, float]:
        """(sector, range to where the obstacle will stand: unknown, inf); ``ego_decel_mps2``
        the deceleration limit braking delivers."""
        return curve.sector(range_m, closing_mps), math.inf


class BrakingObstaclePlacement(PaperPlacement):
    """The most urgent of the paper's sector, the sector of the obstacle standing where its
    measured braking stops it, approached at the ego's speed, and, when it brakes more gently
    than the ego and is still moving as their speeds match, the paper's sector at the closing
    speed whose stopping distance is that of the relative motion (``decision.obstacle``)."""

    def track_decel_mps2(self, filtered_mps2: float) -> float:
        return max(filtered_mps2, 0.0)

    def place(
        self,
        curve: BoundaryCurve,
        range_m: float,
        closing_mps: float,
        speed_mps: float,
        decel: float,
        ego_decel_mps2: float,
    ) -> tuple[Sector, float]:
        v = speed_mps
        factor = speed_match_factor(closing_mps, v - closing_mps, decel, ego_decel_mps2)
        sector = curve.sector(range_m, closing_mps * math.sqrt(factor))
        stop_range = stopping_range_m(range_m, v - closing_mps, decel)
        if stop_range < math.inf and (stop_range != range_m or v != closing_mps):  # else same
            standing = curve.sector(stop_range, v)
            if SECTOR_ORDER.index(standing) < SECTOR_ORDER.index(sector):  # more urgent
                sector = standing
        return sector, stop_range


# ---------------------------------------------------------------------- point of no return
class OffsetPonr:
    """The paper's point of no return (sec. 8.1): the lateral travel since the trigger reaches
    ``ponr_fraction`` of the lane change's."""

    def __init__(self, settings: EoamSettings):
        self.settings = settings

    def past(
        self, state: ControllerState, meas: EgoMeasurement, travel_m: float, height_m: float
    ) -> bool:
        state.stop_path = None
        return travel_m >= self.settings.ponr_fraction * height_m


class LateralStopPonr(OffsetPonr):
    """The travel judged where the lateral motion will stop if it is arrested now (the
    lateral stop is kept for mode 3)."""

    def past(
        self, state: ControllerState, meas: EgoMeasurement, travel_m: float, height_m: float
    ) -> bool:
        state.stop_path = stop = lateral_stop(self.settings, meas)
        travel_m += stop.y1_m - meas.d_m
        return travel_m >= self.settings.ponr_fraction * height_m


# ----------------------------------------------------------------------- commit on oncoming
def return_time_s(settings: EoamSettings, meas: EgoMeasurement) -> float:
    """Duration of a quintic return from the ego's offset to its lane centre at the
    return's peak lateral acceleration ``return_lateral_g`` mu g (a quintic's peak is
    10 sqrt(3) / 3 h / T^2)."""
    a_lat = settings.return_lateral_g * max(meas.mu, 0.05) * G_MPS2
    return math.sqrt(10.0 * math.sqrt(3.0) / 3.0 * abs(meas.d_m) / a_lat)


def beside_obstacle(settings: EoamSettings, params: VehicleParams, state, meas) -> bool:
    """The ego overlaps lengthwise, within ``pass_margin_m``, the tracked obstacle in the lane
    it would return into (its box predicted to now), or is ahead of it but a return begun now
    would leave it too close behind (:func:`passed_keeps_distance`): no return may begin."""
    obstacle = state.obstacle
    if obstacle is None:
        return False
    front_s = obstacle.at(meas.time_s)[0]
    margin = settings.pass_margin_m
    ego_rear = meas.s_m - params.cg_to_rear_bumper_m
    ego_front = meas.s_m + params.cg_to_front_bumper_m
    if ego_front <= front_s - obstacle.length_m - margin:
        return False  # still wholly behind it
    return ego_rear < front_s + margin or not passed_keeps_distance(
        settings, params, obstacle, meas
    )


def passed_keeps_distance(
    settings: EoamSettings, params: VehicleParams, obstacle: ObstacleTrack, meas: EgoMeasurement
) -> bool:
    """The road user passed, behind the ego once it is back in its lane, keeps its distance
    over a return begun now (``return_time_s``): the car-behind rule of the policy
    (:func:`~eoam_sumo.decision.policy.follower_keeps_distance`: it holds its speed and
    braking for 0.4 s, then may brake at 3 m/s^2, and keeps 1 s of its travel and
    ``pass_margin_m``), the ego at its own braking."""
    t_ret = return_time_s(settings, meas)
    front_s, speed = obstacle.at(meas.time_s)
    gap = meas.s_m - params.cg_to_rear_bumper_m - front_s
    v_end = max(meas.vx_mps - max(-meas.ax_mps2, 0.0) * t_ret, 0.0)
    plan = SightNeed(
        0.0, 0.0, t_ret, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5 * (meas.vx_mps + v_end) * t_ret, v_end
    )
    return follower_keeps_distance(
        plan,
        gap,
        speed,
        t_ret,
        settings.pass_margin_m,
        -obstacle.decel_mps2 if speed > 0.0 else 0.0,
    )


class PonrCommit:
    """Oncoming traffic seen in mode 2: pass on (mode 4) past the point of no return, else
    abort (mode 3); mode 4 returns once the ego's rear is ``pass_margin_m`` past the
    obstacle's predicted front."""

    def __init__(self, params: VehicleParams, settings: EoamSettings, ponr: OffsetPonr):
        self.params = params
        self.settings = settings
        self.ponr = ponr

    def commits(
        self,
        state: ControllerState,
        meas: EgoMeasurement,
        perception: Perception,
        travel_m: float,
        height_m: float,
    ) -> bool:
        """Pass on (True) or abort."""
        return self.ponr.past(state, meas, travel_m, height_m)

    def passed(self, state: ControllerState, meas: EgoMeasurement, obstacle: ObstacleTrack) -> bool:
        """Mode 2 or 4 clear of the tracked obstacle: the ego's rear ``pass_margin_m`` past
        its front now and over the return begun now (``return_time_s``), the obstacle at its
        speed and braking (to its stop), the ego at its own acceleration (a braking ego must
        not return in front of a car it has only just passed); in mode 2 the obstacle also
        keeps its distance behind the ego (:func:`passed_keeps_distance`)."""
        ego_rear_s = meas.s_m - self.params.cg_to_rear_bumper_m
        t_ret = return_time_s(self.settings, meas)
        for dt in (0.0, 0.5 * t_ret, t_ret):
            ego_decel = max(-meas.ax_mps2, 0.0) if dt > 0.0 else 0.0
            ego_s = ego_rear_s + travel_m(meas.vx_mps, ego_decel, dt)
            if ego_s - obstacle.at(meas.time_s + dt)[0] < self.settings.pass_margin_m:
                return False
        if state.mode is ONCOMING_STEER_BRAKE:
            return True  # passing oncoming traffic: back as soon as clear
        return passed_keeps_distance(self.settings, self.params, obstacle, meas)

    def budget(self, state: ControllerState, meas: EgoMeasurement) -> Budget:
        """What the ego can do at the sensed friction (``decision.oncoming``)."""
        brake_n = state.friction_now().brake_limit_n
        return Budget.of(self.params, self.settings, meas.mu, brake_n / self.params.mass_kg)


class CompareOutcomes(PonrCommit):
    """With tracks of the oncoming road user and of the obstacle, the option of lower
    predicted delta-v; mode 4 returns once the time-optimal return begun now clears the
    obstacle (``decision.oncoming``). Without both tracks, the point of no return."""

    def commits(
        self,
        state: ControllerState,
        meas: EgoMeasurement,
        perception: Perception,
        travel_m: float,
        height_m: float,
    ) -> bool:
        oncoming, obstacle = perception.oncoming_object, state.obstacle
        if oncoming is None or obstacle is None:
            return self.ponr.past(state, meas, travel_m, height_m)
        state.stop_path = None
        state.oncoming_choice = choice = commit_choice(
            meas, oncoming, obstacle, self.budget(state, meas)
        )
        return choice.pass_on

    def passed(self, state: ControllerState, meas: EgoMeasurement, obstacle: ObstacleTrack) -> bool:
        if state.mode is ONCOMING_STEER_BRAKE:
            return return_clears(meas, obstacle, self.budget(state, meas))
        return super().passed(state, meas, obstacle)


# ------------------------------------------------------------------------------- escapes
class QuinticEscapes:
    """Modes 3, 4 and the urgent return shift along the shortest quintics; mode 3 arrests
    the lateral motion (the lateral stop), then shifts back to the lane centre."""

    def __init__(self, settings: EoamSettings):
        self.settings = settings

    def shift(
        self, target_m: float, meas: EgoMeasurement, lateral_g: float
    ) -> QuinticShift | MinTimeShift:
        """An evasive shift to ``target_m`` within ``lateral_g`` mu g."""
        return quintic_shift(self.settings, target_m, meas, lateral_g)

    def abort_path(
        self, state: ControllerState, meas: EgoMeasurement
    ) -> QuinticShift | MinTimeShift | None:
        """Mode 3's path at its entry (None: no path, the lateral motion is arrested)."""
        if state.stop_path is None:
            state.stop_path = lateral_stop(self.settings, meas)
        return state.stop_path

    def abort_next(
        self, state: ControllerState, meas: EgoMeasurement, path: PathReference | None, dx_m: float
    ) -> QuinticShift | MinTimeShift | None:
        """In mode 3: the next path once the current one has done its part (None: keep)."""
        if path is not None and dx_m >= path.length_m and state.stop_path is not None:
            state.stop_path = None  # lateral motion arrested: back to the lane centre
            return quintic_shift(self.settings, 0.0, meas, self.settings.evasive_lateral_g)
        return None


class MinTimeEscapes(QuinticEscapes):
    """Jerk-limited time-optimal shifts (``MinTimeShift``); mode 3 shifts back at once."""

    def shift(
        self, target_m: float, meas: EgoMeasurement, lateral_g: float
    ) -> QuinticShift | MinTimeShift:
        return min_time_shift(self.settings, target_m, meas, lateral_g)

    def abort_path(
        self, state: ControllerState, meas: EgoMeasurement
    ) -> QuinticShift | MinTimeShift | None:
        state.stop_path = None
        return self.shift(0.0, meas, self.settings.evasive_lateral_g)

    def abort_next(
        self, state: ControllerState, meas: EgoMeasurement, path: PathReference | None, dx_m: float
    ) -> QuinticShift | MinTimeShift | None:
        if state.arrest and lateral_state(meas)[0] * state.arrest <= 0.0:
            state.arrest = 0.0  # lateral motion arrested: back to the lane centre or held
            return self.shift(abort_target_m(state, meas), meas, self.settings.arrest_return_g)
        return None


class ArrestFirst(MinTimeEscapes):
    """Mode 3 entered moving away from the lane centre at least ``arrest_min_speed_mps``
    fast: the motion is first arrested at the front tyre's slip envelope (no path; the brake
    gets what the friction ellipse leaves), then the time-optimal shift back."""

    def abort_path(
        self, state: ControllerState, meas: EgoMeasurement
    ) -> QuinticShift | MinTimeShift | None:
        state.stop_path = None
        v_lat = lateral_state(meas)[0]
        if v_lat * meas.d_m > 0.0 and abs(v_lat) >= self.settings.arrest_min_speed_mps:
            state.arrest = math.copysign(1.0, v_lat)
            return None
        return self.shift(abort_target_m(state, meas), meas, self.settings.evasive_lateral_g)


def abort_target_m(state: ControllerState, meas: EgoMeasurement) -> float:
    """Mode 3's lateral target: the lane centre, or the offset reached when the commit/abort
    decision chose to brake in place (``decision.oncoming.Choice.hold_in_place``)."""
    choice = state.oncoming_choice
    return meas.d_m if choice is not None and choice.hold_in_place else 0.0


# --------------------------------------------------------------------------- early return
class TimerReturn:
    """The paper's runs: mode 2 returns when the manoeuvre timer expires."""

    def __init__(self, settings: EoamSettings):
        self.settings = settings

    def stable_in_next_lane(
        self, state: ControllerState, meas: EgoMeasurement, path: PathReference, dx_m: float
    ) -> bool:
        return False


class StableReturn(TimerReturn):
    """Also earlier, once the lane change's path has ended with the ego within
    ``arrive_tolerance_m`` of the next lane's centre and its heading settled
    (``heading_settled``; the timer's purpose, sec. 3.1 step 5)."""

    def __init__(self, settings: EoamSettings, steering: SteeringController):
        super().__init__(settings)
        self.steering = steering

    def stable_in_next_lane(
        self, state: ControllerState, meas: EgoMeasurement, path: PathReference, dx_m: float
    ) -> bool:
        st = self.settings
        return (
            state.mode is UPDATE_STEER_BRAKE
            and dx_m >= path.length_m
            and abs(meas.d_m - path.start_offset_m - state.height_m) <= st.arrive_tolerance_m
            and heading_settled(st, self.steering, meas)
        )


def heading_settled(
    settings: EoamSettings, steering: SteeringController, meas: EgoMeasurement
) -> bool:
    """The body's heading within ``settle_heading_rad`` of the one steady cornering keeps on
    the road's curvature: off the road's heading by minus the steady sideslip
    (``SteeringController.steady_sideslip``; nothing on a straight road). On a 300 m curve at
    150 km/h that is 0.03 rad, more than the 0.02 rad tolerance itself."""
    sideslip_rad = steering.steady_sideslip(meas.vx_mps, meas.road_curvature_1pm)
    return abs(wrap_angle(meas.e_yaw_rad) + sideslip_rad) <= settings.settle_heading_rad


# ------------------------------------------------------------------------------ next lane
class NextLaneGate:
    """The paper's policy: oncoming traffic (and a standing car) closes the next lane; at a
    commit also a road user of the ego's direction in it, beside, behind or ahead
    (``SafePolicy.occupied_reason``; the paper is silent on such traffic)."""

    policy: SafePolicy | None = None

    def __init__(self, judge: SafePolicy | None = None):
        self._judge = judge
        self.reason = ""  # why the lane was found occupied (the first time)

    def blocks(
        self,
        meas: EgoMeasurement,
        perception: Perception,
        committing: bool,
        watching: bool,
        obstacle_decel_mps2: float = 0.0,
    ) -> bool:
        """The next lane is closed to the lane change (treated as oncoming traffic)."""
        if not committing or self._judge is None:
            return False
        reason = self._judge.occupied_reason(
            meas, perception, perception.next_lane, obstacle_decel_mps2
        )
        self.reason = self.reason or reason
        return bool(reason)

    def prefer_braking(self, meas: EgoMeasurement, perception: Perception) -> bool:
        """Past the point of no return: braking in lane is predicted to end softer."""
        return False

    def reset(self) -> None:
        """Forget the run."""
        self.reason = ""


class SafeGate(NextLaneGate):
    """The safe policy (``decision.policy``): the sight-distance gate at a commit, the next
    lane watched during the lane change and the return, the severity tie-breaker."""

    def __init__(self, policy: SafePolicy):
        super().__init__(policy)
        self.policy = policy
        self._policy = policy

    def blocks(
        self,
        meas: EgoMeasurement,
        perception: Perception,
        committing: bool,
        watching: bool,
        obstacle_decel_mps2: float = 0.0,
    ) -> bool:
        return self._policy.blocks(meas, perception, committing, watching, obstacle_decel_mps2)

    def prefer_braking(self, meas: EgoMeasurement, perception: Perception) -> bool:
        return self._policy.prefer_braking(meas, perception)

    def reset(self) -> None:
        self._policy.reset()
