"""R157 Appendix 3 scenarios as SUMO files on one straight motorway (two lanes eastwards,
3.5 m wide, the ego in the right lane, centre y = -1.75 m).

Another vehicle's lateral motion is geometry, as ``protocols.scenario`` places its targets:
it drives on an edge of its own whose shape leaves one lane centre for the other along a
straight diagonal (lateral speed = its speed x the slope), so SUMO moves it exactly as
scripted; the radar and the contact test see its box where it is, never its lane.

* cut-in: a car in the left lane at ``ego - relative`` speed moves into the ego's lane at a
  lateral speed, starting when the gap (ego front to its rear) is ``gap_m``;
* cut-out: a car ahead at the ego's speed moves into the left lane at a lateral speed,
  starting ``gap_m`` before a stopped car in the ego's lane, revealing it;
* deceleration: a car ahead at the ego's speed, ``gap_m`` ahead, brakes at ``decel_mps2`` to
  a standstill (a scripted stop, ``eoam.aro_*``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.fileio import write_atomic
from eoam_sumo.netbuild import build_network, sumocfg_text

ROAD_M = 3000.0
LANE_W_M = 3.5
EGO_Y_M, LEFT_Y_M = -1.75, 1.75
EGO_FRONT_X_M = 100.0
DEPART_S = 1.0
LEAD_IN_S = 2.0  # the event begins this long after the departure
CAR_LENGTH_M, CAR_WIDTH_M = 4.70, 1.82  # the other cars (scenarios/vtypes.add.xml oncoming)
TYPES = ("cut-in", "cut-out", "deceleration")


@dataclass(frozen=True)
class R157Point:
    """One scenario of a study (SI units)."""

    kind: str  # cut-in, cut-out, deceleration
    ego_kmh: float
    gap_m: float  # cut-in: to the cutting-in car; cut-out: to the stopped car; decel: lead
    lateral_mps: float = 0.0  # cut-in and cut-out
    relative_kmh: float = 0.0  # cut-in: how much slower the cutting-in car is
    decel_mps2: float = 0.0  # deceleration: the lead's

    @property
    def point_id(self) -> str:
        return (
            f"{self.kind}_v{self.ego_kmh:g}_g{self.gap_m:g}_y{self.lateral_mps:g}"
            f"_r{self.relative_kmh:g}_d{self.decel_mps2:g}"
        )


def _network(folder: Path, shapes: dict[str, list[tuple[float, float]]]) -> Path:
    nodes = ['<node id="w" x="0" y="0"/>', f'<node id="e" x="{ROAD_M:g}" y="0"/>']
    edges = [
        '<edge id="E0" from="w" to="e" numLanes="2" speed="40" width="3.50" spreadType="center"/>'
    ]
    for k, (eid, pts) in enumerate(shapes.items()):
        (x0, y0), (x1, y1) = pts[0], pts[-1]
        nodes += [f'<node id="a{k}" x="{x0:.3f}" y="{y0:.3f}"/>']
        nodes += [f'<node id="b{k}" x="{x1:.3f}" y="{y1:.3f}"/>']
        shape = " ".join(f"{x:.3f},{y:.3f}" for x, y in pts)
        edges.append(
            f'<edge id="{eid}" from="a{k}" to="b{k}" numLanes="1" speed="40" width="2.00"'
            f' spreadType="center" shape="{shape}"/>'
        )
    head = '<?xml version="1.0" encoding="UTF-8"?>\n'
    write_atomic(folder / "r157.nod.xml", head + "<nodes>\n" + "\n".join(nodes) + "\n</nodes>\n")
    write_atomic(folder / "r157.edg.xml", head + "<edges>\n" + "\n".join(edges) + "\n</edges>\n")
    return build_network(folder / "r157.nod.xml")


def _shift(x_start: float, y_from: float, y_to: float, speed: float, lateral: float):
    """A lane centre left for another along a diagonal for a car whose front is at
    ``x_start`` when its lateral move begins. SUMO moves a car's front along its lane and
    turns it after its front: its centre leaves the lane at half the lateral speed until its
    back reaches the bend, a car length later. The bend lies half a car length before
    ``x_start``, so that the centre moves as a car translated at ``lateral`` from then on
    (R157's lateral speed; the 0.375 m wandering threshold crossed ``0.375 / lateral`` after
    the move began, 0.22 s later with the bend at ``x_start``)."""
    length = speed * abs(y_to - y_from) / lateral
    bend = x_start - 0.5 * CAR_LENGTH_M
    return [(0.0, y_from), (bend, y_from), (bend + length, y_to), (ROAD_M, y_to)]


def _car(vid: str, edge: str, pos: float, speed: float, hold: float, decel: float) -> str:
    """A car moved by a scripted stop (``eoam.aro_*``): its speed held exactly for ``hold``
    s after departing, then braking at ``decel`` to a standstill."""
    return (
        f'    <route id="{vid}_r" edges="{edge}"/>\n'
        f'    <vehicle id="{vid}" type="car" route="{vid}_r" depart="{DEPART_S:.2f}"'
        f' departLane="0" departPos="{pos:.3f}" departSpeed="{speed:.6f}"'
        ' insertionChecks="none">\n'
        f'        <param key="eoam.aro_hold_s" value="{hold:g}"/>\n'
        f'        <param key="eoam.aro_decel_mps2" value="{decel:g}"/>\n'
        "    </vehicle>\n"
    )


HOLD_ALL_S = 1.0e6  # a hold outlasting every run: constant speed
STOPPED_DECEL_MPS2 = 10.0  # a standing car's script (and a decel never reached)
CUT_OUT_HEADWAY_S = 1.6  # cut-out: the lead's time gap to the ego before it leaves (assumed)


def _others(point: R157Point) -> tuple[str, dict[str, list[tuple[float, float]]]]:
    """The other cars' XML and the shapes of their own edges."""
    ve = point.ego_kmh / 3.6
    ego_front_t0 = EGO_FRONT_X_M + ve * LEAD_IN_S
    if point.kind == "cut-in":
        vc = (point.ego_kmh - point.relative_kmh) / 3.6
        x_s = ego_front_t0 + point.gap_m + CAR_LENGTH_M  # its front when the cut-in begins
        shape = _shift(x_s, LEFT_Y_M, EGO_Y_M, vc, point.lateral_mps)
        car = _car("cutter", "C0", x_s - vc * LEAD_IN_S, vc, HOLD_ALL_S, STOPPED_DECEL_MPS2)
        return car, {"C0": shape}
    if point.kind == "cut-out":
        x_s = ego_front_t0 + CUT_OUT_HEADWAY_S * ve + CAR_LENGTH_M
        shape = _shift(x_s, EGO_Y_M, LEFT_Y_M, ve, point.lateral_mps)
        lead = _car("lead", "C0", x_s - ve * LEAD_IN_S, ve, HOLD_ALL_S, STOPPED_DECEL_MPS2)
        stop_front = x_s + point.gap_m + CAR_LENGTH_M
        stopped = _car("stopped", "E0", stop_front, 0.0, 0.0, STOPPED_DECEL_MPS2)
        return lead + stopped, {"C0": shape}
    front = EGO_FRONT_X_M + point.gap_m + CAR_LENGTH_M
    return _car("lead", "E0", front, ve, LEAD_IN_S, point.decel_mps2), {}


VTYPES = """<?xml version="1.0" encoding="UTF-8"?>
<!-- ego: the sedan (scenarios/vtypes.add.xml); car: the other cars, 4.70 x 1.82 m -->
<additional>
    <vType id="ego" vClass="passenger" length="4.92" width="1.85" minGap="2.00" maxSpeed="60.00"
           accel="4.00" decel="9.00" emergencyDecel="12.00" sigma="0" speedDev="0"/>
    <vType id="car" vClass="passenger" length="4.70" width="1.82" minGap="1.00" maxSpeed="60.00"
           accel="2.60" decel="10.00" emergencyDecel="12.00" sigma="0" speedDev="0"/>
</additional>
"""


def write_scenario(point: R157Point, folder: Path) -> Path:
    """The network, routes and sumocfg of one point in ``folder`` (its own); the sumocfg."""
    folder.mkdir(parents=True, exist_ok=True)
    others, shapes = _others(point)
    net = _network(folder, shapes)
    ve = point.ego_kmh / 3.6
    routes = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f"<!-- UN R157 Annex 4 App. 3 {point.kind}: {point.point_id} -->\n<routes>\n"
        '    <route id="ego_r" edges="E0"/>\n'
        f'    <vehicle id="ego" type="ego" route="ego_r" depart="{DEPART_S:.2f}" departLane="0"'
        f' departPos="{EGO_FRONT_X_M:.2f}" departSpeed="{ve:.6f}" insertionChecks="none"/>\n'
        + others
        + "</routes>\n"
    )
    write_atomic(folder / "r157.rou.xml", routes)
    write_atomic(folder / "r157_vtypes.add.xml", VTYPES)
    cfg = sumocfg_text(net.name, "r157.rou.xml", "r157_vtypes.add.xml")
    return write_atomic(folder / "r157.sumocfg", cfg)
