"""Following the road users SUMO has, cheaply: vehicles of every class and persons.

From :meth:`RoadUsers.start` on, the vehicles around the ego are found through one context
subscription on the ego (SUMO collects those whose front is within the range, parked ones
included; one ``getContextSubscriptionResults`` a step), its range the sensing radius plus the
largest diagonal of the vehicles SUMO has had since (each departing vehicle's type is read),
so that every vehicle some part of which may be within the radius is in it. (The largest
diagonal of every type SUMO knows would count SUMO's 135 m default rail type, widening the
range, and with it the vehicles SUMO collects and the binding converts each step, far beyond
the radius. A vehicle switched to a longer type after it departed, through
TraCI's ``setType``, is counted with its departure type: it is found once its front is within
the range.) Persons are subscribed one by one (a person riding in a vehicle is not a road user
of its own). A road user whose values did not change since the last step is the same
:class:`Body` object as then; a body is built only for a road user within reach.

Through libsumo the context subscription carries the position only; the type of each vehicle
in it (its reach) and the angle, speed and stop state of those within reach are read with
getters: a subscribed value costs SUMO's step and the binding's conversion more than a getter
does, and the vehicles beyond reach are not read further. Through TraCI every getter is a
round trip, so all five values are subscribed.

The context subscription, with bodies built only within reach, is used rather than a variable
subscription on every vehicle because the work of a step then grows with the road users near
the ego, not with every vehicle SUMO has (docs/performance.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from eoam_sumo.sim.session.calls import StepCalls
from eoam_sumo.world.bodies import PEDESTRIAN, Body

PARKING_BIT = 2  # bit of VAR_STOPSTATE set while a vehicle is parked
RANGE_MARGIN_M = 1.0  # added to the context subscription's range (rounding in SUMO) [m]


def _reach2(radius_m: float, body: Body) -> float:
    """Square of the largest front distance at which some point of ``body`` can be within
    ``radius_m``: radius plus the box's diagonal (twice its bounding radius)."""
    reach_m = radius_m + 2.0 * body.box.radius_m
    return reach_m * reach_m


class RoadUsers:
    """The road users other than the ego, followed through SUMO's subscriptions."""

    def __init__(self, api, calls: StepCalls, constants, ego_id: str, scripted: Mapping) -> None:
        self._api, self._calls, self._tc, self.ego_id = api, calls, constants, ego_id
        self._veh, self._person = api.vehicle, api.person
        self._scripted = scripted  # vid -> its running scripted stop (needs speed and lane)
        self.tracking = False  # the road users are followed (from ``start``)
        self._bodies: dict[str, tuple] = {}  # vid -> (values, Body) of the last step's near
        self._context_radius_m: float | None = None  # radius the context range was set for
        self._context_diagonal_m = 0.0  # the vehicles' largest diagonal it was set for
        # vehicles placed by moveToXY anywhere, lanes or not (puppets): read by id if need be
        self.placed: set[str] = set()
        self._diagonal_m = 0.0  # largest diagonal of the vehicles SUMO has had (``start`` on)
        self._persons: dict[str, tuple | None] = {}  # pid -> (results, front, Body) once read
        # type -> length, width, vClass, diagonal (twice the box's bounding radius)
        self._types: dict[str, tuple[float, float, str, float]] = {}
        tc = constants
        self._getters = bool(getattr(api, "isLibsumo", lambda: False)())  # module doc
        self._sense_vars = [tc.VAR_POSITION]
        if not self._getters:
            self._sense_vars += [tc.VAR_TYPE, tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_STOPSTATE]
        self._person_vars = [
            tc.VAR_POSITION,
            tc.VAR_ANGLE,
            tc.VAR_SPEED,
            tc.VAR_TYPE,
            tc.VAR_VEHICLE,
        ]
        self.ego_vars = [tc.VAR_LANE_ID]  # every step (friction); the pose once tracking
        self._results: dict | None = None  # vehicle subscription results of this step, once read
        self._person_results: dict | None = None

    # ------------------------------------------------------------------------- subscriptions
    def new_step(self) -> None:
        """SUMO made a step: the subscription results are to be read again."""
        self._results = None
        self._person_results = None

    def step_results(self) -> dict:
        """Vehicle id -> its variable-subscription results at this step (the ego and the
        vehicles of running scripted stops; one read a step)."""
        if self._results is None:
            self._results = self._calls.vehicle_results()
        return self._results

    def watch(self, vid: str) -> None:
        """Subscribe to what a scripted stop reads of vehicle ``vid`` (speed and lane) while it
        runs, else unsubscribe."""
        if vid in self._scripted:
            self._veh.subscribe(vid, [self._tc.VAR_SPEED, self._tc.VAR_LANE_ID])
        else:
            self._veh.unsubscribe(vid)
        self._results = None

    def start(self) -> None:
        """Follow every road user from now on (the ego's position too)."""
        self.tracking = True
        self._veh.subscribe(self.ego_id, [*self.ego_vars, self._tc.VAR_POSITION])
        self._results = None  # re-read: this step's cached results lack the ego's position
        self._vehicles_in(self._veh.getIDList())
        for pid in self._person.getIDList():
            self._follow_person(pid)

    def _vehicles_in(self, vids) -> None:
        """Vehicles ``vids`` are in SUMO now: the largest diagonal of the types of the
        vehicles SUMO has had since following began grows with theirs."""
        type_id = self._veh.getTypeID
        for vid in vids:
            self._diagonal_m = max(self._diagonal_m, self.type_of(type_id(vid))[3])

    def _follow_person(self, pid: str) -> None:
        self._persons[pid] = None
        self._person.subscribe(pid, self._person_vars)
        self._person_results = None

    def track(self, departed) -> None:
        """Vehicles ``departed`` in this step (:meth:`_vehicles_in`); follow the persons that
        departed, drop those that arrived."""
        if departed:
            self._vehicles_in(departed)
        calls = self._calls
        for pid in calls.arrived_person_ids():
            self._persons.pop(pid, None)
        for pid in calls.departed_person_ids():
            self._follow_person(pid)

    def _context(self, radius_m: float) -> dict:
        """This step's context subscription results (vid -> values; the ego's among them),
        its range ``radius_m`` plus the largest diagonal of the vehicles SUMO has had (set
        anew when either changes: a longer vehicle may depart)."""
        diagonal = self._diagonal_m
        if radius_m != self._context_radius_m or diagonal != self._context_diagonal_m:
            range_m = radius_m + diagonal + RANGE_MARGIN_M
            if self._context_radius_m is not None:
                self._veh.unsubscribeContext(self.ego_id, self._tc.CMD_GET_VEHICLE_VARIABLE, 0.0)
            self._veh.subscribeContext(
                self.ego_id, self._tc.CMD_GET_VEHICLE_VARIABLE, range_m, self._sense_vars
            )
            self._context_radius_m, self._context_diagonal_m = radius_m, diagonal
        return self._calls.context_results(self.ego_id)

    # ------------------------------------------------------------------------- bodies
    def type_of(self, type_id: str) -> tuple[float, float, str, float]:
        """(length, width, vClass, diagonal) of a vehicle or person type (cached); the
        diagonal is twice the bounding radius of its box, computed as the box does."""
        known = self._types.get(type_id)
        if known is None:
            types = self._api.vehicletype
            length, width = types.getLength(type_id), types.getWidth(type_id)
            known = self._types[type_id] = (
                length,
                width,
                types.getVehicleClass(type_id),
                2.0 * math.hypot(0.5 * length, 0.5 * width),
            )
        return known

    def vehicle_body(
        self, vid: str, front: tuple, angle_deg: float, speed: float, type_id: str, stop_state: int
    ) -> Body:
        """Body of a vehicle from SUMO's front position, angle, speed, type and stop state."""
        length, width, vclass, _ = self.type_of(type_id)
        return Body.from_front(
            vid,
            vclass,
            front[0],
            front[1],
            angle_deg,
            speed,
            length,
            width,
            bool(stop_state & PARKING_BIT),
        )

    def person_body(
        self, pid: str, front: tuple, angle_deg: float, speed: float, type_id: str
    ) -> Body:
        """Body of a person (vClass ``pedestrian``; SUMO's position is its front too)."""
        length, width, _, _ = self.type_of(type_id)
        return Body.from_front(pid, PEDESTRIAN, front[0], front[1], angle_deg, speed, length, width)

    def near(self, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the road users some part of which may be within ``radius_m`` of
        (ex, ey) (the ego's position): their SUMO position (front) within ``radius_m`` plus
        their diagonal (no point of a box is farther from its front), so that a long vehicle
        is found as soon as its nearest point can be in reach."""
        results = self._context(radius_m)
        if self.placed:
            results = self._with_placed(results)
        near = self._vehicles_near(results, ex, ey, radius_m)
        if self._persons:
            near += self._persons_near(ex, ey, radius_m)
        return near

    def _with_placed(self, results: dict[str, dict[int, Any]]) -> dict[str, dict[int, Any]]:
        """The context's results and the placed vehicles (``placed``: puppets) it lacks, read
        by id: SUMO's context holds the vehicles on its lanes, and a puppet placed off every
        lane (beyond the road's edge, in a median) is on none."""
        missing = [vid for vid in self.placed if vid not in results]
        if not missing:
            return results
        veh, tc = self._veh, self._tc
        present = set(veh.getIDList())
        extra: dict[str, dict[int, Any]] = {}
        for vid in missing:
            if vid in present:
                extra[vid] = {
                    tc.VAR_POSITION: veh.getPosition(vid),
                    tc.VAR_TYPE: veh.getTypeID(vid),
                    tc.VAR_ANGLE: veh.getAngle(vid),
                    tc.VAR_SPEED: veh.getSpeed(vid),
                    tc.VAR_STOPSTATE: veh.getStopState(vid),
                }
        return {**results, **extra}

    def everyone(self) -> list:
        """Bodies of all road users, wherever they are (getters: not for the step loop)."""
        bodies = [self.vehicle_now(vid) for vid in self._veh.getIDList() if vid != self.ego_id]
        return bodies + self._persons_near(0.0, 0.0, math.inf)

    def vehicle_now(self, vid: str) -> Body:
        """One vehicle's body read with getters (not for the step loop)."""
        veh = self._veh
        return self.vehicle_body(
            vid,
            veh.getPosition(vid),
            veh.getAngle(vid),
            veh.getSpeed(vid),
            veh.getTypeID(vid),
            veh.getStopState(vid),
        )

    def _vehicles_near(
        self, results: dict[str, dict[int, Any]], ex: float, ey: float, radius_m: float
    ) -> list:
        """Bodies of the vehicles of ``results`` (this step's context) within reach of
        (ex, ey); a vehicle whose values did not change keeps its body. (The values are typed
        so that the compiled module works out the reach in floats.)"""
        near: list[Body] = []
        bodies, kept = self._bodies, {}
        types, type_of, tc, calls = self._types, self.type_of, self._tc, self._calls
        pos_k: int = tc.VAR_POSITION
        type_k: int = tc.VAR_TYPE
        angle_k, speed_k, stop_k = tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_STOPSTATE
        getters, ego_id = self._getters, self.ego_id
        for vid, r in results.items():
            if vid == ego_id:
                continue
            front: tuple[float, float] = r[pos_k]
            fx, fy = front
            type_id: str = calls.type_id(vid) if getters else r[type_k]
            t = types.get(type_id) or type_of(type_id)
            reach_m = radius_m + t[3]
            if (fx - ex) * (fx - ex) + (fy - ey) * (fy - ey) > reach_m * reach_m:
                continue
            if getters:
                values = (front, calls.angle(vid), calls.speed(vid), type_id, calls.stop_state(vid))
            else:
                values = (front, r[angle_k], r[speed_k], type_id, r[stop_k])
            known = bodies.get(vid)
            if known is None or known[0] != values:
                known = (values, self.vehicle_body(vid, *values))
            kept[vid] = known
            near.append(known[1])
        self._bodies = kept
        return near

    def _persons_near(self, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the persons on foot within reach (as in :meth:`near`) of (ex, ey)."""
        if self._person_results is None:
            self._person_results = self._calls.person_results()
        results, tc = self._person_results, self._tc
        near = []
        for pid, known in self._persons.items():
            r = results.get(pid)
            if not r or r[tc.VAR_VEHICLE]:  # gone, or riding in a vehicle
                continue
            if known is None or known[0] != r:
                body = self.person_body(
                    pid, r[tc.VAR_POSITION], r[tc.VAR_ANGLE], r[tc.VAR_SPEED], r[tc.VAR_TYPE]
                )
                known = self._persons[pid] = (r, r[tc.VAR_POSITION], body)  # noqa: PLW2901
            (fx, fy), body = known[1], known[2]
            if (fx - ex) * (fx - ex) + (fy - ey) * (fy - ey) <= _reach2(radius_m, body):
                near.append(body)
        return near
