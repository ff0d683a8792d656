"""Road users moved by an outside storyboard (OpenSCENARIO): :class:`Puppets`.

A puppet is placed at each step where its storyboard says (``moveToXY`` of its front bumper,
``keepRoute=2`` as the ego, so that it may stand between lanes) at the speed it says
(``setSpeed``); SUMO's own speed and lane-change models are off for it (speed mode 0: no safe
speed, no bounds; lane-change mode 0).
"""

from __future__ import annotations

from eoam_sumo.sim.session.calls import StepCalls

FREE_SPEED_MODE = 0
NO_LANE_CHANGES = 0


class Puppets:
    """The puppets of a session and the ego's place on its lane (for the storyboard)."""

    def __init__(self, api, calls: StepCalls, ego_id: str, pending: list, placed: set[str]) -> None:
        self._veh, self._calls, self._ego = api.vehicle, calls, ego_id
        self._pending = pending  # the session's: applied just before its next step
        self._placed = placed  # the road users' tracking's: read by id, on a lane or not

    def take(self, vid: str) -> None:
        """From now on only :meth:`place` moves ``vid`` (placed off every lane, SUMO's context
        of the ego no longer holds it: the tracking reads it by id)."""
        self._placed.add(vid)
        self._veh.setSpeedMode(vid, FREE_SPEED_MODE)
        self._veh.setLaneChangeMode(vid, NO_LANE_CHANGES)

    def place(
        self, vid: str, x_m: float, y_m: float, angle_nav_deg: float, speed_mps: float
    ) -> None:
        """``vid``'s front bumper at (x, y) after the next step, heading and speed as given
        (handed to SUMO just before that step: a move still pending when a libsumo session
        closes would be carried into the next one)."""
        self._pending.append((vid, x_m, y_m, angle_nav_deg, speed_mps))

    def apply(self) -> None:
        """Hand the pending placements to SUMO (the session, before its step)."""
        move, set_speed = self._calls.move_to_xy, self._calls.set_speed
        for vid, x_m, y_m, angle_nav_deg, speed_mps in self._pending:
            move(vid, "", -1, x_m, y_m, angle_nav_deg, 2)
            set_speed(vid, speed_mps)
        self._pending.clear()

    def ego_lane(self) -> tuple[str, float]:
        """(SUMO lane id, position of the front bumper along it) of the ego; ("", 0) off lanes."""
        lane = self._veh.getLaneID(self._ego)
        return (lane, float(self._veh.getLanePosition(self._ego))) if lane else ("", 0.0)
