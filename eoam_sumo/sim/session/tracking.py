"""Following every road user SUMO has, cheaply: vehicles of every class and persons.

From :meth:`RoadUsers.start` on, a moving vehicle is read through a variable subscription
(one ``getAllSubscriptionResults`` a step for all), a parked one becomes a fixed body once it
was read parked twice with the same values, until SUMO reports its parking ended (a context
subscription would read every parked car at every step); persons are subscribed like moving
vehicles (a person riding in a vehicle is not a road user of its own). A road user whose
values did not change since the last read is the same :class:`Body` object as then.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from eoam_sumo.sim.bodies import PEDESTRIAN, Body

PARKING_BIT = 2  # bit of VAR_STOPSTATE set while a vehicle is parked


def _reach2(radius_m: float, body: Body) -> float:
    """Square of the largest front distance at which some point of ``body`` can be within
    ``radius_m``: radius plus the box's diagonal (twice its bounding radius)."""
    reach_m = radius_m + 2.0 * body.box.radius_m
    return reach_m * reach_m


class RoadUsers:
    """The road users other than the ego, followed through SUMO's subscriptions."""

    def __init__(self, api, constants, ego_id: str, scripted: Mapping) -> None:
        self._api, self._tc, self.ego_id = api, constants, ego_id
        self._veh, self._person, self._sim = api.vehicle, api.person, api.simulation
        self._scripted = scripted  # vid -> its running scripted stop (needs speed and lane)
        self.tracking = False  # the road users are followed (from ``start``)
        self._moving: dict[str, tuple | None] = {}  # vid -> (results, front, Body) once read
        self._parked: dict[str, tuple] = {}  # vid -> (front, Body), fixed while it stays parked
        self._parked_cache: tuple | None = None  # the last answer of _parked_near, see there
        self._persons: dict[str, tuple | None] = {}  # pid -> (results, front, Body) once read
        self._types: dict[str, tuple[float, float, str]] = {}  # type -> length, width, vClass
        tc = constants
        self._sense_vars = [tc.VAR_POSITION, tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_TYPE,
                            tc.VAR_STOPSTATE]
        self._person_vars = [tc.VAR_POSITION, tc.VAR_ANGLE, tc.VAR_SPEED, tc.VAR_TYPE,
                             tc.VAR_VEHICLE]
        self.ego_vars = [tc.VAR_LANE_ID]  # every step (friction); the pose once tracking
        self._results: dict | None = None  # vehicle subscription results of this step, once read
        self._person_results: dict | None = None

    # ------------------------------------------------------------------------- subscriptions
    def new_step(self) -> None:
        """SUMO made a step: the subscription results are to be read again."""
        self._results = None
        self._person_results = None

    def step_results(self) -> dict:
        """Vehicle id -> its variable-subscription results at this step (one read a step)."""
        if self._results is None:
            self._results = self._veh.getAllSubscriptionResults()
        return self._results

    def watch(self, vid: str) -> None:
        """Subscribe to what is read of vehicle ``vid`` (its body, its scripted stop), or
        unsubscribe when that is nothing."""
        wanted = list(self._sense_vars) if vid in self._moving else []
        if vid in self._scripted:
            wanted += [v for v in (self._tc.VAR_SPEED, self._tc.VAR_LANE_ID) if v not in wanted]
        if wanted:
            self._veh.subscribe(vid, wanted)
        else:
            self._veh.unsubscribe(vid)
        self._results = None

    def start(self) -> None:
        """Follow every road user from now on (the ego's position too)."""
        self.tracking = True
        self._veh.subscribe(self.ego_id, [*self.ego_vars, self._tc.VAR_POSITION])
        self._results = None  # re-read: this step's cached results lack the ego's position
        for vid in self._veh.getIDList():
            if vid != self.ego_id:
                self._moving[vid] = None
                self.watch(vid)
        for pid in self._person.getIDList():
            self._follow_person(pid)

    def _follow_person(self, pid: str) -> None:
        self._persons[pid] = None
        self._person.subscribe(pid, self._person_vars)
        self._person_results = None

    def track(self, departed) -> None:
        """Follow the road users that departed or ended parking in this step (``departed``:
        the vehicles), drop those that arrived."""
        sim = self._sim
        for vid in sim.getArrivedIDList():
            self._moving.pop(vid, None)
            if self._parked.pop(vid, None) is not None:
                self._parked_cache = None
        for vid in sim.getParkingEndingVehiclesIDList():
            if self._parked.pop(vid, None) is not None:
                self._parked_cache = None
                self._moving[vid] = None
                self.watch(vid)
        for vid in departed:
            if vid != self.ego_id:
                self._moving[vid] = None
                self.watch(vid)
        for pid in sim.getArrivedPersonIDList():
            self._persons.pop(pid, None)
        for pid in sim.getDepartedPersonIDList():
            self._follow_person(pid)

    # ------------------------------------------------------------------------- bodies
    def type_of(self, type_id: str) -> tuple[float, float, str]:
        """(length, width, vClass) of a vehicle or person type (cached)."""
        known = self._types.get(type_id)
        if known is None:
            types = self._api.vehicletype
            known = self._types[type_id] = (types.getLength(type_id), types.getWidth(type_id),
                                            types.getVehicleClass(type_id))
        return known

    def vehicle_body(self, vid: str, front: tuple, angle_deg: float, speed: float,
                     type_id: str, stop_state: int) -> Body:
        """Body of a vehicle from SUMO's front position, angle, speed, type and stop state."""
        length, width, vclass = self.type_of(type_id)
        return Body.from_front(vid, vclass, front[0], front[1], angle_deg, speed, length,
                               width, bool(stop_state & PARKING_BIT))

    def person_body(self, pid: str, front: tuple, angle_deg: float, speed: float,
                    type_id: str) -> Body:
        """Body of a person (vClass ``pedestrian``; SUMO's position is its front too)."""
        length, width, _ = self.type_of(type_id)
        return Body.from_front(pid, PEDESTRIAN, front[0], front[1], angle_deg, speed, length,
                               width)

    def near(self, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the road users some part of which may be within ``radius_m`` of
        (ex, ey): their SUMO position (front) within ``radius_m`` plus their diagonal (no
        point of a box is farther from its front), so that a long vehicle is found as soon
        as its nearest point can be in reach."""
        near = self._moving_near(self.step_results(), ex, ey, radius_m)
        near += self._parked_near(ex, ey, radius_m)
        if self._persons:
            near += self._persons_near(ex, ey, radius_m)
        return near

    def everyone(self) -> list:
        """Bodies of all road users followed (no cache touched but the moving ones')."""
        bodies = self._moving_near(self.step_results(), 0.0, 0.0, math.inf)
        bodies += [body for _, body in self._parked.values()]
        return bodies + self._persons_near(0.0, 0.0, math.inf)

    def _moving_near(self, results: dict, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the followed moving vehicles within ``radius_m`` of (ex, ey), from this
        step's ``results``; a vehicle found parked with settled values becomes fixed."""
        near: list[Body] = []
        settled: list[tuple[str, tuple | None]] = []
        tc = self._tc
        for vid, known in self._moving.items():
            r = results.get(vid)
            if not r:  # left without arriving (removed)
                settled.append((vid, None))
                continue
            if known is None or known[0] != r:
                body = self.vehicle_body(vid, r[tc.VAR_POSITION], r[tc.VAR_ANGLE],
                                         r[tc.VAR_SPEED], r[tc.VAR_TYPE], r[tc.VAR_STOPSTATE])
                known = self._moving[vid] = (r, r[tc.VAR_POSITION], body)  # noqa: PLW2901
            elif known[2].parked:  # parked, values settled: fixed until its parking ends
                settled.append((vid, known[1:]))
                continue
            (fx, fy), body = known[1], known[2]
            dist2 = (fx - ex) * (fx - ex) + (fy - ey) * (fy - ey)
            if dist2 <= _reach2(radius_m, body):
                near.append(body)
        for vid, fixed in settled:
            del self._moving[vid]
            if fixed is not None:
                self._parked[vid] = fixed
                self._parked_cache = None
                self.watch(vid)
        return near

    def _parked_near(self, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the parked vehicles within ``radius_m`` of (ex, ey). The answer is
        kept while the ego stays closer to where it was worked out than any parked front is
        to its reach (less 1e-6 m for rounding): no front can have crossed it."""
        cache = self._parked_cache
        if cache is not None:
            ax, ay, radius, slack_m, near = cache
            if radius == radius_m and slack_m > 0.0 and (
                    (ex - ax) * (ex - ax) + (ey - ay) * (ey - ay) < slack_m * slack_m):
                return near
        near, slack_m = [], math.inf
        for (fx, fy), body in self._parked.values():
            reach_m = radius_m + 2.0 * body.box.radius_m
            dist_m = math.hypot(fx - ex, fy - ey)
            if dist_m <= reach_m:
                near.append(body)
            slack_m = min(slack_m, abs(dist_m - reach_m))
        self._parked_cache = (ex, ey, radius_m, slack_m - 1e-6, near)
        return near

    def _persons_near(self, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the persons on foot within reach (as in :meth:`near`) of (ex, ey)."""
        if self._person_results is None:
            self._person_results = self._person.getAllSubscriptionResults()
        results, tc = self._person_results, self._tc
        near = []
        for pid, known in self._persons.items():
            r = results.get(pid)
            if not r or r[tc.VAR_VEHICLE]:  # gone, or riding in a vehicle
                continue
            if known is None or known[0] != r:
                body = self.person_body(pid, r[tc.VAR_POSITION], r[tc.VAR_ANGLE],
                                        r[tc.VAR_SPEED], r[tc.VAR_TYPE])
                known = self._persons[pid] = (r, r[tc.VAR_POSITION], body)  # noqa: PLW2901
            (fx, fy), body = known[1], known[2]
            if (fx - ex) * (fx - ex) + (fy - ey) * (fy - ey) <= _reach2(radius_m, body):
                near.append(body)
        return near
