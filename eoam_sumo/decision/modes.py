"""EOAM discrete modes of operation 0-5 (paper sec. 3.2, Figure 2) and their transitions.

``next_mode`` is the whole mode machine as a pure function of the current mode and the events
the controller derives from perception and ego motion in one step:

* 0 NORMAL -> 1 on a BRAKE or LIMIT_BRAKE sector; -> 2 on a STEER sector, or -> 3 when an
  oncoming vehicle is seen at the moment the steer is asked.
* 1 UPDATE BRAKE -> 3 when an oncoming vehicle is seen; -> 2 on a STEER sector; -> 0 when the
  threat is gone (no obstacle in the path, or it clearly pulls away).
* 2 UPDATE STEER+BRAKE -> 3 (oncoming before the point of no return, sec. 8.1) or 4 (after
  it); -> 5 when the manoeuvre timer expires, or earlier once the ego is stable in the next
  lane and clear of the obstacle (the timer's purpose, sec. 3.1 step 5).
* 3 ONCOMING BRAKE: terminal (limit braking in lane to standstill).
* 4 ONCOMING STEER+BRAKE -> 5 once the desired position in the next lane is reached: the ego
  is clear of the obstacle it steers around, so that the return cannot meet it.
* 5 RETURN -> 3 when the DMM asks for more than a warning (sectors A-D) on another obstacle
  than the one steered around, a second one in the lane the ego returns to (ours: the paper's
  mode 5 has no exit but the hand-back): limit braking while the return ends on its path;
  -> 0 once settled in the original lane (hand-back to the high-level system). Mode 4
  reaches it through 5 once clear (one step later).
"""

from __future__ import annotations

from enum import IntEnum

from eoam_sumo.decision.dmm import BRAKE, LIMIT_BRAKE, STEER, Action


class Mode(IntEnum):
    """Modes of operation of the EOAM module (paper sec. 3.2)."""

    NORMAL = 0
    UPDATE_BRAKE = 1
    UPDATE_STEER_BRAKE = 2
    ONCOMING_BRAKE = 3
    ONCOMING_STEER_BRAKE = 4
    RETURN = 5


# The members as module names, as the step's code reads them
NORMAL, UPDATE_BRAKE, UPDATE_STEER_BRAKE, ONCOMING_BRAKE, ONCOMING_STEER_BRAKE, RETURN = Mode

_BRAKING = (BRAKE, LIMIT_BRAKE)
#: The DMM's actions beyond a warning (sectors A-D): in mode 5 each is limit braking in lane
_ACTING = (BRAKE, LIMIT_BRAKE, STEER)


def next_mode(
    mode: Mode,
    action: Action,
    *,
    oncoming: bool,
    past_ponr: bool,
    timer_expired: bool,
    stable_in_next_lane: bool,
    clear_of_obstacle: bool,
    settled: bool,
    threat_gone: bool,
    another_obstacle: bool = False,
) -> Mode:
    """The mode after one step; at most one transition per call (``another_obstacle``: in
    mode 5, the DMM's obstacle is not the one the lane change steered around)."""
    if mode is NORMAL:
        if action is STEER:
            return ONCOMING_BRAKE if oncoming else UPDATE_STEER_BRAKE
        if action in _BRAKING:
            return UPDATE_BRAKE
        return mode
    if mode is UPDATE_BRAKE:
        if oncoming:
            return ONCOMING_BRAKE
        if action is STEER:
            return UPDATE_STEER_BRAKE
        if threat_gone:
            return NORMAL
        return mode
    if mode is UPDATE_STEER_BRAKE:
        if oncoming:
            return ONCOMING_STEER_BRAKE if past_ponr else ONCOMING_BRAKE
        if timer_expired or stable_in_next_lane:
            return RETURN
        return mode
    if mode is ONCOMING_STEER_BRAKE:
        return RETURN if clear_of_obstacle else mode
    if mode is RETURN:
        if another_obstacle and action in _ACTING:
            return ONCOMING_BRAKE  # a second obstacle in the lane the ego returns to
        return NORMAL if settled else mode
    if mode is ONCOMING_BRAKE and threat_gone and not oncoming:
        return NORMAL  # the obstacle drives away: follow it (mode 0, 1), do not stop for it
    return mode
