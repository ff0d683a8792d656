"""Commit or abort: the options when an oncoming road user is seen during a lane change.

The paper (sec. 8.1) commits to the lane change past a point of no return, 0.3 x the lane
width of lateral travel, and brakes in lane before it. What matters is whether each option
ends against the oncoming road user, so both are predicted here from the radar's track of it
(station, offset, speed, size) and of the obstacle being avoided, and the least severe one is
taken:

* **abort** (mode 3): arrest the lateral motion and steer back into the own lane at once: a
  time-optimal shift to the lane centre within the evasive budget
  (``manoeuvre.min_time_shift.MinTimeShift``) up to where the lateral motion away from it
  stops, and from there one within the (gentler) budget of the shift back after an arrest;
  braking at the limit with what the friction ellipse leaves during the shifts and at the
  full limit after them;
* **brake in place** (mode 3, ``predict_hold``): the same arrest, then the offset held where it
  ends and limit braking; taken over the abort only when it is predicted out of the oncoming
  road user's path and of lower delta-v (it hits the obstacle slower, or passes beside it);
* **pass** (mode 4): go on to just past the obstacle's side (its left edge + half the ego +
  the side clearance), hold the speed until the ego's rear is past the obstacle's front, then
  the same time-optimal shift back from there.

Geometry, in the road frame of the ego's lane (d left): the ego is out of the oncoming road
user's path while its centre is at most ``d_onc - w_onc / 2 - w_ego / 2 - margin_m`` (its
left side short of the other's right side; 1.67 m with 3.5 m lanes, a 1.85 m ego and a
1.82 m car centred in its lane, less the margin). The fronts meet after
``gap / (v_ego + v_onc)``. An option ends in a head-on unless the ego is out of the path from
``margin_s`` before that until the other has passed. Severity is the ego's delta-v in a
plastic impact with a body of equal mass, half the closing speed (``policy``'s tie-breaker):
a head-on at the closing speed then (less what braking took off), a hit on the obstacle at the
relative speed left after braking over the gap (both bodies braking to their stops).
No contact comes first; a side contact with the obstacle counts as a front one, by the
relative speed. Ties go to aborting (the paper's choice before its point of no return), then
to braking in place. Where every option ends in contact with ``margin_s``, the one clear with
the smaller ``margin_min_s`` is taken, if any (``choose``; on exact states only).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.manoeuvre.lateral_state import lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.params import G_MPS2

_DT_S = 0.01  # time step of the braking prediction [s]
_HORIZON_S = 20.0


class Lateral(NamedTuple):
    """The ego's lateral motion in the road frame (left positive)."""

    d_m: float
    v_mps: float
    a_mps2: float


class Tracked(NamedTuple):
    """A tracked road user, relative to the ego, along the road (ahead positive)."""

    gap_m: float  # from the ego's front bumper to its nearest end (rear or front) [m]
    speed_mps: float  # its speed along the road (negative: towards the ego)
    decel_mps2: float  # its braking (to its stop; 0: holds its speed)
    length_m: float
    near_edge_m: float  # its side facing the other lane: left edge of the obstacle, right
    # edge of the oncoming road user [m]


class Budget(NamedTuple):
    """What the ego can do: lateral budget, jerk ramp, braking and sizes."""

    lateral_mps2: float  # evasive lateral acceleration, k mu g
    ramp_s: float  # time from no lateral acceleration to the full budget
    lag_s: float  # the closed loop follows a new shift as if its lateral acceleration held
    # this long first
    brake_mps2: float  # limit braking on its own
    mu_g_mps2: float  # friction limit, mu g
    width_m: float  # ego
    length_m: float
    cg_to_front_m: float
    side_clearance_m: float  # lateral gap kept to the obstacle's side when passing
    pass_margin_m: float  # the ego's rear this far past the obstacle's front ends the pass
    margin_m: float  # lateral margin to the oncoming path
    margin_s: float  # time margin before the fronts meet
    return_mps2: float  # lateral budget of the shift back after an arrest
    arrest_min_mps: float  # the least lateral speed away from the lane centre arrested
    margin_min_s: float = 0.1  # the time margin where every option with ``margin_s`` ends
    # in contact

    @classmethod
    def of(cls, params, settings, mu: float, brake_mps2: float) -> Budget:
        """From the ego's ``VehicleParams``, the ``EoamSettings`` and the friction."""
        mu_g, st = mu * G_MPS2, settings
        arrest_min = st.arrest_min_speed_mps if st.arrest_first else math.inf
        return cls(
            st.evasive_lateral_g * mu_g,
            st.escape_ramp_s,
            st.escape_lag_s,
            brake_mps2,
            mu_g,
            params.width_m,
            params.length_m,
            params.cg_to_front_bumper_m,
            st.side_clearance_m,
            st.pass_margin_m,
            st.oncoming_margin_m,
            st.oncoming_margin_s,
            st.arrest_return_g * mu_g,
            arrest_min,
            st.oncoming_margin_min_s,
        )


class Option(NamedTuple):
    """One option's predicted outcome."""

    head_on: bool
    delta_v_mps: float  # the ego's predicted delta-v (0: no contact)
    out_s: float  # when the ego is out of the oncoming path for good (inf: never)
    meet_s: float  # when the fronts meet


class Choice(NamedTuple):
    """The option taken and the predictions."""

    pass_on: bool
    abort: Option
    passing: Option
    hold: Option | None = None  # braking in place (None: not predicted)
    hold_in_place: bool = False  # the abort holds the offset where its arrest ends
    least_margin: bool = False  # taken with ``margin_min_s``, not ``margin_s`` (``choose``)


def _out_line_m(oncoming: Tracked, b: Budget) -> float:
    return oncoming.near_edge_m - 0.5 * b.width_m - b.margin_m


def _braking(
    v_mps: float, decel_of, obstacle: Tracked | None, oncoming: Tracked
) -> tuple[float, float, float]:
    """(when the fronts meet, closing speed then, impact speed on the obstacle or 0) for the
    ego braking at ``decel_of(t)`` to its stop, the obstacle braking to its stop, the
    oncoming road user holding its speed."""
    t, x, v = 0.0, 0.0, v_mps
    x_obs, v_obs = (obstacle.gap_m, max(obstacle.speed_mps, 0.0)) if obstacle else (0.0, 0.0)
    onc_speed = -oncoming.speed_mps
    meet = closing = math.nan
    impact = 0.0
    while t < _HORIZON_S:
        if math.isnan(meet) and x >= oncoming.gap_m - onc_speed * t:
            meet, closing = t, v + onc_speed
        if obstacle is not None and impact == 0.0 and x >= x_obs:
            impact = max(v - v_obs, 0.0)
            obstacle = None
        if not math.isnan(meet) and (obstacle is None or v <= v_obs):
            break
        dv = min(decel_of(t) * _DT_S, v)
        x += (v - 0.5 * dv) * _DT_S
        v -= dv
        if obstacle is not None:
            dvo = min(obstacle.decel_mps2 * _DT_S, v_obs)
            x_obs += (v_obs - 0.5 * dvo) * _DT_S
            v_obs -= dvo
        t += _DT_S
    if math.isnan(meet):  # the ego stopped first: the other arrives at its own speed
        meet, closing = (oncoming.gap_m - x) / max(onc_speed, 1e-6), onc_speed
    return meet, closing, impact


def _lagged(lat: Lateral, lag_s: float) -> Lateral:
    """The lateral motion ``lag_s`` on at its present acceleration."""
    t = lag_s
    return Lateral(
        lat.d_m + t * (lat.v_mps + 0.5 * t * lat.a_mps2), lat.v_mps + t * lat.a_mps2, lat.a_mps2
    )


def _escape(lat: Lateral, target_m: float, v_mps: float, b: Budget) -> MinTimeShift:
    """The time-optimal shift from the lateral motion ``b.lag_s`` on (it starts then)."""
    lat = _lagged(lat, b.lag_s)
    return MinTimeShift(lat.d_m, lat.v_mps, lat.a_mps2, target_m, v_mps, b.lateral_mps2, b.ramp_s)


def _head_on(
    escape: MinTimeShift, start_s: float, line_m: float, meet_s: float, b: Budget
) -> tuple[bool, float]:
    """(whether the ego is still in the oncoming path when the fronts meet, when it is out
    for good)."""
    out = start_s + escape.time_within_s(line_m)
    return out + b.margin_s > meet_s, out


def predict_abort(
    lat: Lateral, v_mps: float, obstacle: Tracked | None, oncoming: Tracked, b: Budget
) -> Option:
    """Abort: the time-optimal shift to the lane centre up to where the lateral motion away
    from it stops, then one from rest there within ``return_mps2``; braking with what the
    friction ellipse leaves during them and at the limit after them."""
    escape = _escape(lat, 0.0, v_mps, b)
    start = b.lag_s
    turn = escape.turn_s()
    if turn > 0.0 and abs(lat.v_mps) >= b.arrest_min_mps:  # arrested first, as mode 3 does
        start += turn
        escape = MinTimeShift(
            escape.state_at(turn)[0], 0.0, 0.0, 0.0, v_mps, b.return_mps2, b.ramp_s
        )
    share = math.sqrt(max(1.0 - (b.lateral_mps2 / b.mu_g_mps2) ** 2, 0.0))
    t_lat = start + escape.duration_s if escape.duration_s > 1e-6 else 0.0

    def decel(t: float) -> float:
        return b.brake_mps2 * (share if t < t_lat else 1.0)

    meet, closing, impact = _braking(v_mps, decel, obstacle, oncoming)
    head_on, out = _head_on(escape, start, _out_line_m(oncoming, b), meet, b)
    if head_on:
        return Option(True, 0.5 * closing, out, meet)
    return Option(False, 0.5 * impact, out, meet)


def _arrest(lat: Lateral, v_mps: float, b: Budget) -> tuple[float, float]:
    """(offset where an arrest of the lateral motion away from the lane centre ends, when)
    as ``predict_abort`` has it; the offset now and 0 when nothing is arrested."""
    escape = _escape(lat, 0.0, v_mps, b)
    turn = escape.turn_s()
    if turn > 0.0 and abs(lat.v_mps) >= b.arrest_min_mps:
        return escape.state_at(turn)[0], b.lag_s + turn
    return lat.d_m, 0.0


def predict_hold(
    lat: Lateral, v_mps: float, obstacle: Tracked | None, oncoming: Tracked, b: Budget
) -> Option:
    """Brake in place: the arrest of ``predict_abort``, then the offset held where it ends
    and limit braking (with what the friction ellipse leaves during the arrest). The ego hits
    the obstacle (front or side: counted alike, by the relative speed) while its side is
    inside the obstacle's; it meets the oncoming road user while inside its path."""
    d_hold, t_lat = _arrest(lat, v_mps, b)
    share = math.sqrt(max(1.0 - (b.lateral_mps2 / b.mu_g_mps2) ** 2, 0.0))

    def decel(t: float) -> float:
        return b.brake_mps2 * (share if t < t_lat else 1.0)

    beside = obstacle is not None and d_hold - 0.5 * b.width_m >= obstacle.near_edge_m
    meet, closing, impact = _braking(v_mps, decel, None if beside else obstacle, oncoming)
    if max(d_hold, lat.d_m) > _out_line_m(oncoming, b):
        return Option(True, 0.5 * closing, math.inf, meet)
    if beside and obstacle is not None:  # passes beside it: the oncoming road user decides
        return Option(False, 0.0, 0.0, meet)
    return Option(False, 0.5 * impact, 0.0, meet)


def predict_pass(
    lat: Lateral, v_mps: float, obstacle: Tracked | None, oncoming: Tracked, b: Budget
) -> Option:
    """Pass: beside the obstacle at its side until the ego's rear is past its front, at the
    present speed, then the time-optimal shift back to the lane centre."""
    meet, closing, _ = _braking(v_mps, lambda t: 0.0, None, oncoming)
    line = _out_line_m(oncoming, b)
    if obstacle is None:  # nothing left to pass: escape from where the ego is
        head_on, out = _head_on(_escape(lat, 0.0, v_mps, b), b.lag_s, line, meet, b)
    else:
        # the shift back to the lane centre at once, held back (at its peak) as long as it
        # would come within the side clearance of the obstacle before the ego is past it
        to_pass = obstacle.gap_m + obstacle.length_m + b.length_m + b.pass_margin_m
        clear_s = time_to_pass_s(v_mps, to_pass, obstacle)
        side = obstacle.near_edge_m + 0.5 * b.width_m + b.side_clearance_m
        escape = _escape(lat, 0.0, v_mps, b)
        if escape.max_offset_m() < side:  # it must go out to the side first
            escape = MinTimeShift(side, 0.0, 0.0, 0.0, v_mps, b.lateral_mps2, b.ramp_s)
            start = max(clear_s, b.lag_s + _escape(lat, side, v_mps, b).duration_s)
        else:
            start = b.lag_s + max(clear_s - b.lag_s - escape.time_within_s(side), 0.0)
        head_on, out = _head_on(escape, start, line, meet, b)
    return Option(head_on, 0.5 * closing if head_on else 0.0, out, meet)


def time_to_pass_s(v_mps: float, to_pass_m: float, obstacle: Tracked) -> float:
    """Time for the ego at constant speed to gain ``to_pass_m`` on the obstacle braking to
    its stop (inf when it is as fast)."""
    v_obs, a = max(obstacle.speed_mps, 0.0), obstacle.decel_mps2
    rel = v_mps - v_obs
    if a > 0.0:
        t_stop = v_obs / a
        gained = rel * t_stop + 0.5 * a * t_stop * t_stop
        if gained < to_pass_m:
            return t_stop + (to_pass_m - gained) / v_mps
        # rel t + a t^2 / 2 = to_pass within the obstacle's stop
        return (-rel + math.sqrt(rel * rel + 2.0 * a * to_pass_m)) / a
    return to_pass_m / rel if rel > 1e-6 else math.inf


def choose(
    lat: Lateral, v_mps: float, obstacle: Tracked | None, oncoming: Tracked, b: Budget, passed: bool
) -> Choice:
    """The option of lower predicted delta-v (``weigh``). The time margin ``margin_s`` covers
    the prediction's error where it keeps some option clear of contact. Where every option
    ends in contact with it, an option clear of contact with the smaller ``margin_min_s``
    is taken instead, if any (``Choice.least_margin``): the margin would otherwise only rank
    contacts that are certain against one the predictions give a margin to."""
    choice = weigh(lat, v_mps, obstacle, oncoming, b, passed)
    if passed or b.margin_s <= b.margin_min_s or _clear(choice):
        return choice
    least = weigh(lat, v_mps, obstacle, oncoming, b._replace(margin_s=b.margin_min_s), passed)
    return least._replace(least_margin=True) if _clear(least) else choice


def _clear(choice: Choice) -> bool:
    """Whether the option taken is predicted to end without contact."""
    if choice.pass_on:
        taken = choice.passing
    elif choice.hold_in_place and choice.hold is not None:
        taken = choice.hold
    else:
        taken = choice.abort
    return not taken.head_on and taken.delta_v_mps <= 0.0


def weigh(
    lat: Lateral, v_mps: float, obstacle: Tracked | None, oncoming: Tracked, b: Budget, passed: bool
) -> Choice:
    """Abort back into the lane, brake in place or pass on, by the lower predicted delta-v
    (no contact first; ties in that order: the paper aborts before its point of no return).
    ``passed``: the ego's rear is already past the obstacle's front, so passing on is the
    escape alone (taken)."""
    ahead = None if passed else obstacle
    abort = predict_abort(lat, v_mps, ahead, oncoming, b)
    passing = predict_pass(lat, v_mps, ahead, oncoming, b)
    hold = predict_hold(lat, v_mps, ahead, oncoming, b)
    pass_on = passed or passing.delta_v_mps < min(abort.delta_v_mps, hold.delta_v_mps)
    # never held in the oncoming road user's path: an abort at least leaves it
    hold_in_place = not (pass_on or hold.head_on) and hold.delta_v_mps < abort.delta_v_mps
    return Choice(pass_on, abort, passing, hold, hold_in_place)


def commit_choice(meas, oncoming, obstacle: ObstacleTrack, b: Budget) -> Choice:
    """``choose`` from an ``EgoMeasurement``, the oncoming road user as an ``ObjectState``
    (a sensor's object) and the obstacle's track. A state of an earlier time (a tracked
    sensor's, ``ObjectState.time_s``) is carried on to now, and its noise is not in the
    prediction, so the least time margin is not taken on it (``Budget.margin_min_s``, sized
    on exact states)."""
    v_lat, a_lat, along = lateral_state(meas)
    front = meas.s_m + b.cg_to_front_m
    obs_front, obs_speed = obstacle.at(meas.time_s)
    length = obstacle.length_m
    obs = Tracked(
        obs_front - length - front, obs_speed, obstacle.decel_mps2, length, obstacle.left_edge_m
    )
    onc = Tracked(
        _station_now_m(oncoming, meas.time_s) - 0.5 * oncoming.length_m - front,
        oncoming.speed_mps,
        0.0,
        oncoming.length_m,
        oncoming.d_m - 0.5 * oncoming.width_m,
    )
    passed = front - b.length_m - obs_front >= b.pass_margin_m
    if oncoming.time_s is not None:  # a tracked sensor's state: the full margin only
        b = b._replace(margin_min_s=b.margin_s)
    return choose(Lateral(meas.d_m, v_lat, a_lat), along, obs, onc, b, passed)


def _station_now_m(obj, time_s: float) -> float:
    """An object's station at ``time_s``: a sensor's state of an earlier time (its latency,
    ``ObjectState.time_s``) carried on at its speed."""
    if obj.time_s is None or not time_s > obj.time_s:
        return obj.s_m
    return obj.s_m + obj.speed_mps * (time_s - obj.time_s)


def return_clears(meas, obstacle: ObstacleTrack, b: Budget) -> bool:
    """Passing: whether the time-optimal return begun now keeps the ego's side
    ``side_clearance_m`` from the obstacle's until its rear is ``pass_margin_m`` past the
    obstacle's front (steering back in ahead of it)."""
    v_lat, a_lat, along = lateral_state(meas)
    obs_front, obs_speed = obstacle.at(meas.time_s)
    to_pass = obs_front + b.pass_margin_m - (meas.s_m + b.cg_to_front_m - b.length_m)
    if to_pass <= 0.0:
        return True
    side = obstacle.left_edge_m + 0.5 * b.width_m + b.side_clearance_m
    if meas.d_m < side:  # not yet out beside it
        return False
    escape = MinTimeShift(meas.d_m, v_lat, a_lat, 0.0, along, b.lateral_mps2, b.ramp_s)
    track = Tracked(0.0, obs_speed, obstacle.decel_mps2, obstacle.length_m, side)
    return escape.time_within_s(side) >= time_to_pass_s(along, to_pass, track)
