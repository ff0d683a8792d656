"""Tunable values of the EOAM module (``eoam.EoamController``), the paper's where it gives them."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

from eoam_sumo.control.longitudinal import LongitudinalGains
from eoam_sumo.control.steering import SteeringGains
from eoam_sumo.decision.policy import PolicySettings
from eoam_sumo.params import PONR_FRACTION


@dataclass(frozen=True)
class EoamSettings:
    """Tunable values of the EOAM logic (the paper's defaults where it gives them)."""

    ponr_fraction: float = PONR_FRACTION  # point of no return / lane-change height
    manoeuvre_time_s: float = 8.0  # steering manoeuvre timer before RETURN (sec. 3.1 step 5)
    arrive_tolerance_m: float = 0.3  # 2 -> 5 early: within this of the next lane's centre ...
    pass_margin_m: float = 1.0  # mode 4 -> 5: ego rear this far past the obstacle's front
    side_clearance_m: float = 0.5  # mode 4: lateral gap kept to the obstacle's side
    unknown_obstacle_length_m: float = 12.0  # assumed without an object track (a truck)
    track_gate_m: float = 5.0  # modes 2, 4: a sensed object further off the track is another
    settle_offset_m: float = 0.1  # mode 5 -> 0: |d| below this ...
    settle_heading_rad: float = 0.02  # ... and |e_yaw| below this ...
    settle_dwell_s: float = 0.5  # ... for this long after the return path ended
    release_opening_speed_mps: float = 0.5  # mode 1 -> 0: obstacle pulls away faster than this
    follow_after_brake: bool = True  # mode 1 -> 0: the object ahead sets the speed while
    # sensed (False: the set speed, a plain cruise control; mode 3 -> 0 follows either way)
    coasted_margin_m: float = 2.0  # modes 0, 1: a coasted object within the stopping distance
    # plus this brakes (a standstill gap, as adaptive cruise keeps)
    min_steer_speed_mps: float = 20.0 / 3.6  # below it a STEER sector brakes instead
    limit_brake_floor: float = 0.5  # mode 3 (not arresting): the brake keeps at least this share
    # of the limit, the steering the rest of the friction ellipse (eqs. 25, 28); 0: none
    limit_brake_floor_speed_mps: float = 2.0  # ... above walking speed
    reference_step_m: float = 0.25  # dx spacing of the sampled manoeuvre reference
    return_when_stable: bool = True  # ... heading within settle_heading_rad and clear of the
    # obstacle: 2 -> 5 before the timer (False: the timer alone, as in the paper's runs)
    obstacle_decel_in_dmm: bool = True  # also judge the obstacle where its measured braking
    # stops it (False: the paper's closing speed as if the obstacle held it)
    obstacle_decel_time_constant_s: float = 0.1  # low-pass of the obstacle's deceleration
    lateral_reaction_s: float = 0.3  # steering and yaw lag before the lateral motion turns
    ponr_at_lateral_stop: bool = True  # judge the point of no return where the lateral
    # motion stops if arrested now (False: on the offset reached, as in the paper)
    compare_outcomes: bool = True  # oncoming traffic seen in mode 2 with the oncoming road
    # user and the obstacle tracked: pass on or abort by the lower predicted delta-v
    # (decision.oncoming; False: the point of no return above)
    oncoming_margin_m: float = 0.2  # ... the ego's side this far short of the other's path
    oncoming_margin_s: float = 0.2  # ... that long before the fronts meet
    oncoming_margin_min_s: float = 0.1  # ... or this long where every option with the
    # margin above ends in contact (docs/control.md, the 165 km/h arrest)
    min_time_escapes: bool = True  # modes 3, 4 and the returns from oncoming traffic:
    # jerk-limited time-optimal shifts (manoeuvre.min_time_shift; False: the shortest quintics)
    arrest_first: bool = True  # mode 3 from a lane change: a lateral motion away from the
    # lane centre is first arrested at the front tyre's slip envelope, then the shift back
    arrest_lateral_g: float | None = None  # ... at the front slip envelope's edge (None),
    # or along a turn at this / (mu g), its yaw rate a_y / v within what the tyres sustain and
    # the brake given the friction ellipse's rest (docs/control.md, the 165 km/h arrest)
    arrest_min_speed_mps: float = 0.5  # ... when it is at least this fast (a lane change's,
    # not a lane-keeping drift: the arrest steers hard)
    arrest_return_g: float = 0.6  # ... within this / (mu g): the body leaves the arrest
    # sliding (Table 2: up to 10 deg of sideslip); at 0.75 the closed loop spun the car on mu 0.3
    escape_ramp_s: float = 0.15  # their time from no lateral acceleration to the full budget
    escape_lag_s: float = 0.1  # the commit/abort prediction: the closed loop follows a new
    # shift as if its lateral acceleration held this long first (Table 2: peaks 0.4-0.6 m
    # past the plan's after a lane change aborted at 1-3.5 m/s of lateral speed)
    return_lateral_g: float = 0.3  # mode 5 after 2: return's peak lateral acceleration / (mu g)
    evasive_lateral_g: float = 0.9  # modes 3, 4 and the return after 4 (oncoming traffic): the same
    return_min_length_m: float = 10.0  # mode 5: shortest return path
    steering_inhibited: bool = False  # braking only, an AEB (protocol --system aeb): a STEER
    # sector brakes at the limit in lane, as with no lane to change into; the FCW is its warning
    next_lane_clear_m: float = 50.0  # a standing object in the next lane closer than the
    # in-path obstacle's range plus this (room to pass it and return) blocks the lane change
    # as oncoming traffic does (modes 3, 4); the paper checks the next lane for oncoming only
    preview_time_s: float = 0.3  # feedforward curvature taken this far ahead on the path
    planned_preview_time_s: float = 0.15  # the table lane change's planned steering taken
    planned_preview_slope_s2pm: float = 0.003  # (this - slope * speed, >= 0) s ahead on the
    # path: the actuator's lag, and its rate limit where the plan steers fast (low speed)
    steering: SteeringGains = field(default_factory=SteeringGains)
    planned_steering: SteeringGains = field(  # the table lane change (plans keep 10 % of
        default_factory=lambda: SteeringGains(natural_freq_radps=9.0)
    )  # the friction for it)
    longitudinal: LongitudinalGains = field(default_factory=LongitudinalGains)
    policy: PolicySettings = field(default_factory=PolicySettings)  # paper or safe

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"EOAM setting {f.name}={v!r} must be finite and >= 0")
        g = self.arrest_lateral_g
        if g is not None and not 0.0 < g <= 1.0:
            raise ValueError(f"arrest_lateral_g={g!r} must be None or in (0, 1]")
        if not 0.0 < self.ponr_fraction < 1.0:
            raise ValueError(f"ponr_fraction={self.ponr_fraction} must be in (0, 1)")
        for name in (
            "manoeuvre_time_s",
            "reference_step_m",
            "return_lateral_g",
            "evasive_lateral_g",
            "return_min_length_m",
            "escape_ramp_s",
            "arrest_return_g",
            "settle_offset_m",
            "settle_heading_rad",
            "unknown_obstacle_length_m",
            "arrive_tolerance_m",
        ):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"EOAM setting {name} must be > 0")
