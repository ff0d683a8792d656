"""Carrying out the scripted emergency stops (paper sec. 10.1, Figure 19) during a run.

Each vehicle of ``scenario.scripted_stops`` keeps its departure speed for ``hold_s`` after
departing, then its speed is commanded down at ``min(decel_mps2, mu_lane * g)`` per second to
standstill, mu_lane the friction of the lane under it, and stays there.

The hold is exact whatever the vehicle's type: its speed is commanded with SUMO's checks off
(``HOLD_SPEED_MODE``) and its lane changes off, so that neither the driver's imperfection
(``sigma``), its speed factor (``speedFactor``, ``speedDev``), a slower car ahead of it nor
the lane-change model's cooperative slowing moves it off the departure speed or out of its
lane. After the hold the stop keeps the safe speed (``SCRIPTED_SPEED_MODE``); its lane changes
stay off to the end, braking and standing (SUMO's lane-change model would otherwise move it a
whole lane sideways in one step: into the lane the ego evades into, or by keep-right once
standing).

SUMO inserts a vehicle one step after its departure time, and it moves from then on: at
SUMO's 10 ms reference step it moves ``hold_s - 0.01`` s before its stop begins. At a longer
SUMO step (a multi-rate run) the hold is lengthened by the later insertion, so that the
vehicle moves as long, and stops where, it does at the reference step.
"""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.params import G_MPS2
from eoam_sumo.sim.session.calls import StepCalls

SCRIPTED_SPEED_MODE = 25  # safe speed, right of way, red lights; no accel/decel bound
HOLD_SPEED_MODE = 32  # the commanded speed as it is: no safe speed, bounds or right of way
NO_LANE_CHANGES = 0
REFERENCE_STEP_S = 0.01  # the SUMO step whose insertion the holds are timed for [s]


@dataclass
class _Script:
    """Run-time state of a scripted emergency stop."""

    hold_end_s: float
    decel_mps2: float
    hold_speed_mps: float
    mu: float = 1.0
    last_cmd_mps: float = -1.0
    holding: bool = True


class StopScripts:
    """The scripted stops of a run: waiting for their vehicle's departure, then running."""

    def __init__(self, api, calls: StepCalls, constants, stops: dict, step_s: float) -> None:
        self._veh, self._calls, self._tc = api.vehicle, calls, constants
        # the later insertion at a longer SUMO step (0.0 at the reference step)
        self._insert_lag_s = max(0.0, step_s - REFERENCE_STEP_S)
        self._stops = stops  # vid -> (hold_s, decel_mps2)
        self.pending = set(stops)  # not yet departed
        self.running: dict[str, _Script] = {}

    @property
    def ids(self) -> frozenset[str]:
        """Every vehicle whose stop is scripted, departed or not."""
        return frozenset(self._stops)

    def start(self, vid: str, watch) -> None:
        """``vid`` departed: its stop runs from now on (``watch(vid)`` subscribes it)."""
        hold, decel = self._stops[vid]
        veh = self._veh
        self.pending.discard(vid)
        self.running[vid] = _Script(
            veh.getDeparture(vid) + hold + self._insert_lag_s,
            decel,
            veh.getSpeed(vid),
        )
        veh.setSpeedMode(vid, HOLD_SPEED_MODE)
        veh.setLaneChangeMode(vid, NO_LANE_CHANGES)
        watch(vid)

    def _release(self, vid: str, script: _Script) -> None:
        """The hold is over: the stop regards the safe speed; the lane changes stay off
        through the emergency stop (SUMO's lane-change model moved a braking obstacle a lane
        over in one 10 ms step, into the lane the ego was evading into)."""
        script.holding = False
        self._veh.setSpeedMode(vid, SCRIPTED_SPEED_MODE)

    def apply(self, t_next_s: float, dt_s: float, results: dict, friction, watch) -> None:
        """Command each running stop's speed at the end of the coming step, ending at
        ``t_next_s`` (``results``: this step's subscription results; ``friction(lane_id)``)."""
        tc, set_speed = self._tc, self._calls.set_speed
        for vid, script in list(self.running.items()):
            res = results.get(vid)
            if not res:
                del self.running[vid]
                continue
            if t_next_s <= script.hold_end_s + 1e-9:
                cmd = script.hold_speed_mps
            else:
                if script.holding:
                    self._release(vid, script)
                if res[tc.VAR_LANE_ID]:
                    script.mu = friction(res[tc.VAR_LANE_ID])
                decel = min(script.decel_mps2, script.mu * G_MPS2)
                cmd = max(0.0, res[tc.VAR_SPEED] - decel * min(dt_s, t_next_s - script.hold_end_s))
            if cmd != script.last_cmd_mps:
                set_speed(vid, cmd)
                script.last_cmd_mps = cmd
            elif cmd == 0.0 and res[tc.VAR_SPEED] == 0.0:
                # stopped under a standing zero command: every later command is zero too
                del self.running[vid]
                watch(vid)
