"""The plan as SUMO files: vehicle types from the bounding boxes, routes along the road.

Every vehicle departs at ``DEPART_S`` (scenario time 0), its front bumper where its
reference point plus the box's front lie (SUMO places vehicles by the front bumper), on its
lane's centre (the storyboard engine, :mod:`.engine`, moves the targets from the first step
on, lateral offsets included). The vehicle types
carry ``speedFactor=4`` so that the road's speed limits (OpenDRIVE ``<speed>``) never refuse
a departure: the scenario, not the road, gives the speeds.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

from eoam_sumo.fileio import write_atomic
from eoam_sumo.netbuild import sumocfg_text
from eoam_sumo.openscenario.geometry import LaneMap
from eoam_sumo.openscenario.model import Body, Plan
from eoam_sumo.openscenario.road import SumoLane, locate

DEPART_S = 1.0
SUMOCFG = "scenario.sumocfg"
MAX_SPEED_MPS = 70.0  # a target's SUMO type's maxSpeed, unless it departs faster
VCLASS = {"car": "passenger", "van": "delivery", "truck": "truck", "bus": "bus",
          "motorbike": "motorcycle", "bicycle": "bicycle"}  # fmt: skip
# the storyboard alone moves a target across lanes: SUMO's own lane changes (strategic,
# cooperative, speed gain, keep right) are off, also after a scripted stop's hold
NO_OWN_LANE_CHANGES = 'lcStrategic="-1" lcCooperative="-1" lcSpeedGain="0" lcKeepRight="0"'
EGO_VTYPE = (
    '<vType id="ego" vClass="passenger" length="4.92" width="1.85" minGap="2.00" '
    'maxSpeed="70.00" accel="4.00" decel="9.00" emergencyDecel="12.00" sigma="0" speedDev="0" '
    'speedFactor="4"/>'
)


def _vtype(body: Body, vid: str, speed_mps: float = 0.0) -> str:
    """A target's type (its ``maxSpeed`` at least its departure speed: SUMO refuses a
    departure above its type's)."""
    vclass = VCLASS.get(body.category, "passenger")
    top = max(MAX_SPEED_MPS, speed_mps)
    return (
        f'<vType id="t_{vid}" vClass="{vclass}" length="{body.length_m:g}" '
        f'width="{body.width_m:g}" minGap="1.00" maxSpeed="{top:.2f}" accel="2.50" decel="10.00" '
        f'emergencyDecel="12.00" sigma="0" speedDev="0" speedFactor="4" {NO_OWN_LANE_CHANGES}/>'
    )


def _route(net, lane: SumoLane) -> list[str]:
    """The lane's edge and its successors (first outgoing edge each), up to 50 edges."""
    edges = [lane.edge]
    edge = net.getEdge(lane.edge)
    while len(edges) < 50:
        nxt = [e for e in edge.getOutgoing() if e.getFunction() != "internal"]
        if not nxt or nxt[0].getID() in edges:
            break
        edge = nxt[0]
        edges.append(edge.getID())
    return edges


def _nearest_lane(lanes: LaneMap, place) -> int:
    """The lane whose centre is nearest the place's lateral offset (the departure lane: the
    storyboard engine puts the entity at its exact offset from the first step on)."""
    if abs(place.offset_m) < 1e-9:
        return place.lane
    side = [k for r, k in lanes.table if r == place.road and (k < 0) == (place.lane < 0)]

    def miss(k: int) -> float:
        return abs(lanes.shift_m(place.road, place.lane, k, place.s_m) - place.offset_m)

    return min(side, key=miss)


def ego_offset_notes(plan: Plan, lanes: LaneMap) -> list[str]:
    """The note on an ego placed off its lane's centre: the plant starts on the centre of
    its departure lane (the lane nearest the offset), the offset not applied."""
    place = plan.places.get(plan.ego)
    if place is None or abs(place.offset_m) < 1e-9:
        return []
    lane = _nearest_lane(lanes, place)
    where = f"lane {lane}'s centre" + ("" if lane == place.lane else ", the lane nearest it")
    return [
        f"the ego {plan.ego}'s lateral offset {place.offset_m:g} m from lane {place.lane} "
        f"(line {place.node.line}) not applied: it starts on {where}"
    ]


def _vehicle(plan: Plan, name: str, lanes: LaneMap, net) -> str:
    place, body = plan.places[name], plan.bodies[name]
    lane_id = _nearest_lane(lanes, place)
    lane, pos = locate(lanes.table, place.road, lane_id, place.s_m, place.node.where())
    pos = min(max(pos, 0.0), lane.length_m)  # a place in a junction's gap: the lane's end
    front = pos + body.front_ahead_m
    speed = plan.speeds_mps.get(name, 0.0)
    vid = plan.sumo_ids()[name]
    vtype = "ego" if name == plan.ego else f"t_{vid}"
    return (
        f'    <route id="r_{vid}" edges="{" ".join(_route(net, lane))}"/>\n'
        f'    <vehicle id={quoteattr(vid)} type={quoteattr(vtype)} route="r_{vid}" '
        f'depart="{DEPART_S:.2f}" departLane="{lane.index}" departPos="{front:.3f}" '
        f'departSpeed="{speed:.6f}" insertionChecks="none"/>'
    )


def write_sumo(plan: Plan, net_file: Path, lanes: LaneMap, folder: Path, source: Path) -> Path:
    """Write the scenario's SUMO files into ``folder``; the .sumocfg."""
    import sumolib

    from eoam_sumo import __version__

    folder.mkdir(parents=True, exist_ok=True)
    net = sumolib.net.readNet(str(net_file))
    others = [n for n in plan.bodies if n != plan.ego]
    ids = plan.sumo_ids()
    vtypes = [EGO_VTYPE] + [
        _vtype(plan.bodies[n], ids[n], plan.speeds_mps.get(n, 0.0)) for n in others
    ]
    head = f'<?xml version="1.0" encoding="UTF-8"?>\n<!-- from {source.name} -->\n'
    write_atomic(
        folder / "scenario_vtypes.add.xml",
        head + "<additional>\n    " + "\n    ".join(vtypes) + "\n</additional>\n",
    )
    vehicles = [_vehicle(plan, n, lanes, net) for n in [plan.ego, *others]]
    write_atomic(
        folder / "scenario.rou.xml", head + "<routes>\n" + "\n".join(vehicles) + "\n</routes>\n"
    )
    end = 3600.0  # the run ends by the storyboard, its own criteria or --max-time-s
    cfg = sumocfg_text(
        str(net_file),
        "scenario.rou.xml",
        "scenario_vtypes.add.xml",
        end_s=end,
        comment=f"from {source.name} by eoam_sumo {__version__}",
    )
    return write_atomic(folder / SUMOCFG, cfg)
