"""The summary of one co-simulation run: one typed record, the source of summary.json and of
the summary columns of a batch's results.csv.

Each field carries its meaning in its metadata (``doc``); units are in the names (SI).
``docs/verdicts.md`` lists the same fields (a test holds the two together).
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass, field


def _doc(text: str):
    return field(metadata={"doc": text})


@dataclass(frozen=True)
class RunSummary:
    """What one run came to (summary.json, in this order)."""

    outcome: str = _doc("outcome colour: none, green, yellow, orange, red or unfinished")
    collision_with: str = _doc("role of the road user hit: none, aro, oncoming, parked, other")
    impact_speed_mps: float = _doc("relative speed of the box centres at the first contact")
    contact_kind: str = _doc("none, head_on, oblique, rear_end or side")
    contact_time_s: float | None = _doc("SUMO time of the first contact (empty: none)")
    contact_x_m: float | None = _doc(
        "where the first contact was: the centroid of the boxes' overlap, network x (empty: none)"
    )
    contact_y_m: float | None = _doc("and its network y (empty: none)")
    collision_with_id: str | None = _doc("SUMO id of the road user hit")
    collision_with_class: str | None = _doc("its SUMO vClass (pedestrian for a person)")
    contact_overlap: float | None = _doc(
        "share of the ego's face hit that the other covers (front/rear: of its width)"
    )
    impact_angle_rad: float | None = _doc("angle between the headings: 0 same way, pi head-on")
    delta_v_ego_mps: float | None = _doc("the ego's change of velocity (plastic impact)")
    collision_with_mass_kg: float | None = _doc("mass of the road user hit, as used")
    reason: str = _doc("one sentence on why the run got its colour")
    modes_visited: tuple[int, ...] = _doc("EOAM modes 0-5 in order of first visit")
    fcw_raised: bool = _doc("the forward collision warning was raised")
    mu: float = _doc("friction under the ego at the start (results.csv: mu_at_start)")
    mu_belief: str | float = _doc("the friction the EOAM decided with: known, estimate or a number")
    trigger_time_s: float | None = _doc("when the EOAM first left normal driving (empty: never)")
    trigger_range_m: float | None = _doc("range to the obstacle then (empty: none seen)")
    mu_believed_at_trigger: float | None = _doc("the friction the EOAM believed then")
    driver: str = _doc("the ego's controller: eoam or a reference driver (r157-cc, fsm, rss)")
    policy: str = _doc("the decision policy: paper or safe")
    v2x_range_m: float = _doc("V2X range (0: no V2X)")
    v2x_latency_s: float = _doc("V2X message latency")
    v2x_loss: float = _doc("share of V2X messages lost")
    v2x_penetration: float = _doc("share of road users sending V2X")
    sight_gate: str = _doc("safe policy: passed or closed at the first lane-change request")
    sight_needed_m: float | None = _doc("passing sight distance the lane change needed")
    sight_known_free_m: float | None = _doc("length of the next lane known free then")
    sight_time_s: float | None = _doc("time the lane change and the escape would take")
    tie_break: str = _doc("safe policy: what the severity tie-breaker chose")
    radar_model: str = _doc("the radar model: ideal or automotive")
    seed: int = _doc("the seed of every random model of the run")
    vehicle: str = _doc("the ego's vehicle: its catalogue name or vehicle file")
    abs_fitted: bool = _doc("whether the ego's ABS was on")
    esc_fitted: bool = _doc("whether the ego's ESC was on")
    min_gap_aro_m: float | None = _doc(
        "smallest box-to-box gap to the in-lane obstacle within 20 m (empty: never that close)"
    )
    min_gap_oncoming_m: float | None = _doc(
        "smallest box gap to an opposite-direction road user in reach (empty: none)"
    )
    min_ttc_oncoming_s: float | None = _doc(
        "smallest time to collision with one, each moving on along its lane (empty: never "
        "on a collision course)"
    )
    time_in_opposite_lane_s: float = _doc(
        "time with the ego's centre in the opposite lane (left of its lane, where the lane "
        "there carries opposing traffic; 0 on a one-way road)"
    )
    near_miss: bool = _doc(
        "no contact, but within 0.5 m of a road user, a TTC along the lanes below 1.5 s "
        "(min_ttc_s), or a follower forced to brake at 6 m/s2 or more"
    )
    passed_obstacle: bool | None = _doc(
        "a lane change ended ahead of the obstacle it avoided (empty: no lane change)"
    )
    end_cause: str = _doc(
        "contact, rollover, left_road, settled, road_end, time_limit or storyboard (an "
        "OpenSCENARIO StopTrigger)"
    )
    rollover_time_s: float | None = _doc(
        "SUMO time both inner wheels had lifted or |ay| passed the static stability limit "
        "g track / (2 h) (empty: never)"
    )
    wheel_lift_time_s: float | None = _doc(
        "SUMO time one inner wheel first lifted, not a loss of control (empty: never)"
    )
    wheel_lift_tyre: str = _doc("the tyre that lifted first (front left, ...; empty: none)")
    wheel_lift_ay_mps2: float | None = _doc(
        "the load-transfer lateral acceleration at the first wheel lift (empty: none)"
    )
    min_tyre_load_n: float | None = _doc(
        "smallest normal load of any tyre under the plant's load transfer (0: a wheel lifted)"
    )
    max_abs_lat_accel_mps2: float = _doc("largest |lateral acceleration| of the ego")
    max_lateral_offset_m: float = _doc("largest |lateral offset| from the original lane centre")
    final_lateral_offset_m: float = _doc("lateral offset when the run ended (left +)")
    final_speed_mps: float = _doc("forward speed when the run ended, signed")
    min_speed_mps: float = _doc("lowest forward speed, signed (negative: went backwards)")
    max_abs_heading_error_rad: float = _doc("largest |heading - road heading|")
    left_road: bool = _doc("the ego's centre went more than 0.5 m beyond a road edge")
    ego_initial_speed_mps: float = _doc("ego speed at its departure")
    lane_width_m: float = _doc("width of the ego's start lane (the lane change's height)")
    oncoming_traffic: bool = _doc(
        "a road user within 250 m moved against the ego's lane direction (traffic.csv role)"
    )
    net_file: str = _doc("the scenario's network file (for eoam-sumo animate)")
    radar_range_m: float = _doc("the radar's range")
    radar_fov_deg: float = _doc("the radar's full horizontal field of view")
    sim_time_s: float = _doc("simulated time from the ego's departure")
    wall_time_s: float = _doc("wall time of the whole run, SUMO start-up included")
    realtime_factor: float = _doc("simulated seconds per wall second of the step loop")
    # mypy takes the _doc(...) calls above for defaults, and then this field() without one
    # for an error; neither has a default at run time
    sumo_overrides: dict = field(  # type: ignore[misc]
        metadata={"doc": "SUMO options the run set over the sumocfg, option -> value"}
    )
    time_in_next_lane_s: float = _doc(
        "time with the ego's centre out of its lane in the next lane, whatever its direction "
        "(left, or right where its class may use a lane there)"
    )
    min_ttc_s: float | None = _doc(
        "smallest time to collision along the lanes with any moving road user but the "
        "obstacle ahead in the ego's lane (same direction: within 10 s; empty: none)"
    )
    min_ttc_rear_s: float | None = _doc(
        "the same with road users behind the ego (empty: none within 10 s)"
    )
    min_gap_rear_m: float | None = _doc(
        "smallest gap along the road from the ego's follower (the nearest road user behind "
        "it overlapping its width, within 150 m) to the ego (empty: none)"
    )
    max_drac_rear_mps2: float = _doc(
        "largest deceleration the follower needed to avoid the ego while closing in, "
        "(v_f - v_ego)^2 / (2 gap) (DRAC)"
    )
    max_follower_decel_mps2: float = _doc(
        "largest deceleration the follower made while closing in on the ego"
    )
    follower_decel_id: str | None = _doc("SUMO id of that follower (empty: none)")

    def as_dict(self) -> dict:
        """The summary as summary.json writes it (lists for tuples)."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out


#: summary.json keys in order.
FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(RunSummary))
#: What each field means.
FIELD_DOCS: dict[str, str] = {f.name: f.metadata["doc"] for f in dataclasses.fields(RunSummary)}
#: Fields that measure the machine, not the physics: they differ between two runs.
TIMING_FIELDS = ("wall_time_s", "realtime_factor")


def _is_number(tp) -> bool:
    """A number, or a number or None (``str | float`` is not: text may be in it)."""
    args = typing.get_args(tp) if isinstance(tp, types.UnionType) else (tp,)
    return all(a in (float, int, types.NoneType) for a in args) and args != (types.NoneType,)


#: Fields that are numbers (or empty).
NUMERIC_FIELDS: tuple[str, ...] = tuple(
    name for name, tp in typing.get_type_hints(RunSummary).items() if _is_number(tp)
)


def rounded(value: float, digits: int = 6) -> float:
    """``value`` to ``digits`` decimals, -0.0 turned into 0.0."""
    return round(value, digits) + 0.0


def finite_or_none(value: float, digits: int = 6) -> float | None:
    """``rounded(value)``, or None for an infinite value (nothing measured)."""
    return None if math.isinf(value) else rounded(value, digits)
