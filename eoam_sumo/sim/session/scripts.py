"""Carrying out the scripted emergency stops (paper sec. 10.1, Figure 19) during a run.

Each vehicle of ``scenario.scripted_stops`` keeps its departure speed for ``hold_s`` after
departing, then its speed is commanded down at ``min(decel_mps2, mu_lane * g)`` per second to
standstill, mu_lane the friction of the lane under it, and stays there.
"""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.params import G_MPS2
from eoam_sumo.sim.session.calls import StepCalls

SCRIPTED_SPEED_MODE = 25  # safe speed, right of way, red lights; no accel/decel bound


@dataclass
class _Script:
    """Run-time state of a scripted emergency stop."""

    hold_end_s: float
    decel_mps2: float
    hold_speed_mps: float
    mu: float = 1.0
    last_cmd_mps: float = -1.0


class StopScripts:
    """The scripted stops of a run: waiting for their vehicle's departure, then running."""

    def __init__(self, api, calls: StepCalls, constants, stops: dict) -> None:
        self._veh, self._calls, self._tc = api.vehicle, calls, constants
        self._stops = stops  # vid -> (hold_s, decel_mps2)
        self.pending = set(stops)  # not yet departed
        self.running: dict[str, _Script] = {}

    def start(self, vid: str, watch) -> None:
        """``vid`` departed: its stop runs from now on (``watch(vid)`` subscribes it)."""
        hold, decel = self._stops[vid]
        self.pending.discard(vid)
        self.running[vid] = _Script(
            self._veh.getDeparture(vid) + hold, decel, self._veh.getSpeed(vid)
        )
        self._veh.setSpeedMode(vid, SCRIPTED_SPEED_MODE)
        watch(vid)

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
