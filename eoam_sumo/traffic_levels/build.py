"""Write a generated scenario: the road, traffic at a level of service, the ego placed in a
gap of that traffic and the vehicle ahead of it made the obstacle.

1. The road (``network.py``) and, for a warm-up run, each lane filled at the level's target
   density (``hcm.py``; spacings at random, speeds the level's speed times each driver's
   speed factor) with flows entering at the same rate.
2. SUMO runs the warm-up (``WARMUP_S``, seeded), so that the drivers settle into their own
   gaps and speeds.
3. At its end, in the ego's lane (the rightmost) in the window ``GAP_WINDOW_M``, the vehicle
   with the longest gap behind it becomes the obstacle, and the ego is placed in that gap
   (``OBSTACLE_GAP_M`` behind the obstacle at most, midway in a shorter gap).
4. The scenario's route file starts every vehicle where the warm-up left it (lane, position,
   speed, speed factor), the ego and the obstacle among them, with the flows entering on: a
   plain SUMO scenario whose traffic no longer depends on SUMO's random numbers for its
   first state. ``scenario.json`` records the spec, the measured level and the placement.

Everything is deterministic: the same spec and seed give the same files, byte for byte.
"""

from __future__ import annotations

import json
import math
import tempfile
from dataclasses import asdict, dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.seeds import sumo_seed
from eoam_sumo.traffic_levels import hcm
from eoam_sumo.traffic_levels.network import BACKWARD, FORWARD, ROAD_M, write_network
from eoam_sumo.traffic_levels.spec import TrafficSpec

WARMUP_S = 60.0  # the warm-up's simulated time [s]
WARMUP_STEP_S = 0.1
GAP_WINDOW_M = (2000.0, 2500.0)  # where along the ego's lane the gap is looked for [m]
OBSTACLE_GAP_M = 120.0  # the ego's front to the obstacle's rear at most (the paper's) [m]
MIN_CLEAR_M = 5.0  # the least clearance behind the ego's rear [m]
MEASURE_M = (1000.0, 4000.0)  # where the level is measured [m]
ATTEMPTS = 4  # warm-ups at most, the density scaled until the measured level is the spec's
OBSTACLE_HOLD_S, OBSTACLE_DECEL_MPS2 = 2.0, 8.0  # the obstacle's scripted stop
SPEED_FACTOR_SD, SPEED_FACTOR_CLIP = 0.1, (0.8, 1.2)  # the drivers' desired speeds
CAR_LENGTH_M, CAR_MIN_GAP_M = 4.7, 2.5  # the traffic's cars (vType "car")
EGO_LENGTH_M = 4.92
VTYPES = (
    '    <vType id="ego" vClass="passenger" length="4.92" width="1.85" minGap="2.00" '
    'maxSpeed="60.00" accel="4.00" decel="9.00" emergencyDecel="12.00" sigma="0" '
    'speedDev="0" color="0,128,255"/>\n'
    '    <vType id="car" vClass="passenger" length="4.70" width="1.82" minGap="2.50" '
    'maxSpeed="60.00" accel="2.60" decel="4.50" emergencyDecel="9.00" sigma="0.5" '
    'speedDev="0.1" color="200,200,200"/>\n'
)


@dataclass(frozen=True)
class Vehicle:
    """A vehicle of the warm-up's end: id, edge, lane index, front position, speed, factor."""

    vid: str
    edge: str
    lane: int
    pos_m: float
    speed_mps: float
    speed_factor: float


def lanes_of(spec: TrafficSpec) -> list[tuple[str, int]]:
    """(edge, lane index) of every lane with traffic."""
    if spec.road == "motorway":
        return [(FORWARD, i) for i in range(spec.lanes or 1)]
    return [(FORWARD, 0), (BACKWARD, 0)]


def target(spec: TrafficSpec, scale: float = 1.0) -> tuple[float, float]:
    """(density [veh/km/ln], speed [m/s]) of the spec's level, the density times ``scale``."""
    limit = spec.speed_limit_kmh or 0.0
    if spec.road == "motorway":
        density, speed = hcm.freeway_target(spec.los, limit)
    else:
        density, speed = hcm.two_lane_target(spec.los, limit)
    return scale * density, speed


def _initial_vehicles(spec: TrafficSpec, rng: np.random.Generator, scale: float) -> list[Vehicle]:
    """Each lane filled at the target density: spacings at least a car's length, its gap and
    half a second at its speed, the rest exponential; speeds the level's speed times each
    driver's factor, below the speed limit times it."""
    density_per_km, speed_mps = target(spec, scale)
    mean_spacing_m = 1000.0 / density_per_km
    limit_mps = (spec.speed_limit_kmh or 0.0) / 3.6
    out = []
    for edge, lane in lanes_of(spec):
        pos = ROAD_M - 10.0
        k = 0
        while True:
            factor = float(np.clip(rng.normal(1.0, SPEED_FACTOR_SD), *SPEED_FACTOR_CLIP))
            speed = min(speed_mps, limit_mps * factor)
            least = CAR_LENGTH_M + CAR_MIN_GAP_M + 0.5 * speed
            pos -= least + rng.exponential(max(mean_spacing_m - least, 1e-3))
            if pos < CAR_LENGTH_M + 1.0:
                break
            out.append(Vehicle(f"w_{edge}{lane}_{k}", edge, lane, pos, speed, factor))
            k += 1
    return out


def _flows(spec: TrafficSpec, end_s: float, scale: float) -> str:
    """Flows entering each lane at the target flow (density x speed), random arrivals."""
    density_per_km, speed_mps = target(spec, scale)
    per_s = density_per_km * speed_mps / 1000.0
    return "".join(
        f'    <flow id="f_{edge}{lane}" type="car" route="{edge}" begin="0" end="{end_s:g}" '
        f'probability="{min(per_s, 1.0):.6f}" departLane="{lane}" departSpeed="desired"/>\n'
        for edge, lane in lanes_of(spec)
    )


def _vehicle_line(v: Vehicle, extra: str = "", vtype: str = "car", inner: str = "") -> str:
    head = (
        f'    <vehicle id="{v.vid}" type="{vtype}" route="{v.edge}" depart="0" '
        f'departLane="{v.lane}" departPos="{v.pos_m:.2f}" departSpeed="{v.speed_mps:.3f}" '
        f'{extra}insertionChecks="none"'
    )
    return f"{head}>\n{inner}    </vehicle>\n" if inner else f"{head}/>\n"


def _routes(
    spec: TrafficSpec, vehicles: list[Vehicle], tail: str, end_s: float, scale: float
) -> str:
    routes = "".join(
        f'    <route id="{e}" edges="{e}"/>\n' for e in sorted({e for e, _ in lanes_of(spec)})
    )
    body = "".join(_vehicle_line(v, f'speedFactor="{v.speed_factor:.4f}" ') for v in vehicles)
    return f"<routes>\n{VTYPES}{routes}{body}{tail}{_flows(spec, end_s, scale)}</routes>\n"


def _sumocfg(net: str, routes: str, seed: int, step_s: float, end_s: float) -> str:
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<configuration>\n'
        f'    <input>\n        <net-file value="{net}"/>\n'
        f'        <route-files value="{routes}"/>\n    </input>\n'
        f'    <time>\n        <begin value="0"/>\n        <end value="{end_s:g}"/>\n'
        f'        <step-length value="{step_s:g}"/>\n    </time>\n'
        '    <processing>\n        <collision.action value="none"/>\n'
        '        <time-to-teleport value="-1"/>\n    </processing>\n'
        f'    <random_number>\n        <seed value="{seed}"/>\n    </random_number>\n'
        '    <report>\n        <no-step-log value="true"/>\n'
        '        <no-warnings value="true"/>\n    </report>\n</configuration>\n'
    )


def warm_up(spec: TrafficSpec, net: Path, scale: float, attempt: int) -> list[Vehicle]:
    """Run a warm-up in SUMO (libsumo) at the target density times ``scale``; every vehicle
    at its end, ordered by edge, lane and position."""
    import libsumo

    rng = np.random.default_rng([spec.seed, attempt])
    with tempfile.TemporaryDirectory(prefix="eoam-warmup-") as scratch:
        work = Path(scratch)
        (work / "warmup.rou.xml").write_text(
            _routes(spec, _initial_vehicles(spec, rng, scale), "", WARMUP_S, scale),
            encoding="utf-8",
        )
        cfg = work / "warmup.sumocfg"
        cfg.write_text(
            _sumocfg(
                str(net.resolve()),
                "warmup.rou.xml",
                sumo_seed(spec.seed, attempt),
                WARMUP_STEP_S,
                WARMUP_S,
            ),
            encoding="utf-8",
        )
        libsumo.start(["sumo", "-c", str(cfg), "--no-step-log", "true"])
        try:
            libsumo.simulationStep(WARMUP_S)
            found = [_vehicle_now(libsumo.vehicle, vid) for vid in libsumo.vehicle.getIDList()]
        finally:
            libsumo.close()
    return sorted(found, key=lambda v: (v.edge, v.lane, v.pos_m))


def _vehicle_now(api, vid: str) -> Vehicle:
    lane_id = api.getLaneID(vid)
    edge, _, index = lane_id.rpartition("_")
    return Vehicle(
        vid.replace(".", "_"),
        edge,
        int(index),
        round(float(api.getLanePosition(vid)), 2),
        round(max(float(api.getSpeed(vid)), 0.0), 3),
        round(float(api.getSpeedFactor(vid)), 4),
    )


def choose_gap(vehicles: list[Vehicle]) -> tuple[Vehicle, float]:
    """(the obstacle, the ego's front position) in the ego's lane (forward, lane 0): of the
    vehicles whose rear is in ``GAP_WINDOW_M``, the one with the longest gap behind it (the
    first ahead of the window when none is in it); the ego ``OBSTACLE_GAP_M`` behind it, or
    midway in a shorter gap. InputError when no gap holds the ego."""
    lane = [v for v in vehicles if v.edge == FORWARD and v.lane == 0]
    if not lane:
        raise InputError("the warm-up left no vehicle in the ego's lane to be the obstacle")
    lo, hi = GAP_WINDOW_M
    best: tuple[float, Vehicle, float] | None = None
    for i, v in enumerate(lane):
        rear = v.pos_m - CAR_LENGTH_M
        behind = lane[i - 1].pos_m if i > 0 else 0.0
        gap = rear - behind
        candidate = lo <= rear <= hi or (rear > hi and best is None)
        if candidate and (best is None or gap > best[0]):
            best = (gap, v, behind)
        if rear > hi and best is not None:
            break
    if best is None:
        raise InputError("the warm-up left no vehicle ahead of the ego's window")
    gap, obstacle, behind = best
    if gap < EGO_LENGTH_M + 2.0 * MIN_CLEAR_M:
        raise InputError(f"no gap for the ego in its lane (the longest is {gap:.1f} m)")
    ahead_m = min(OBSTACLE_GAP_M, 0.5 * (gap - EGO_LENGTH_M))
    return obstacle, obstacle.pos_m - CAR_LENGTH_M - ahead_m


def measured_level(spec: TrafficSpec, vehicles: list[Vehicle]) -> dict:
    """The level measured at the warm-up's end over ``MEASURE_M`` of the ego's direction:
    the density [pc/mi/ln] (motorway) or follower density (rural: the share of vehicles
    within ``hcm.FOLLOWER_HEADWAY_S`` of their leader, times the density)."""
    lo, hi = MEASURE_M
    lanes = [ln for e, ln in lanes_of(spec) if e == FORWARD]
    inside = [v for v in vehicles if v.edge == FORWARD and lo <= v.pos_m <= hi]
    density = len(inside) / ((hi - lo) / 1000.0 * len(lanes)) * hcm.KM_PER_MI
    if spec.road == "motorway":
        measure = density
    else:
        ordered = sorted(inside, key=lambda v: v.pos_m)
        followers = sum(
            1
            for back, front in pairwise(ordered)
            if front.pos_m - back.pos_m <= hcm.FOLLOWER_HEADWAY_S * max(back.speed_mps, 0.1)
        )
        measure = followers / max(len(ordered), 1) * density
    limit = spec.speed_limit_kmh or 0.0
    return {
        "measure": "density_pc_mi_ln" if spec.road == "motorway" else "follower_density_mi_ln",
        "value": round(measure, 3),
        "level": hcm.level_of(spec.road, measure, limit),
        "density_pc_mi_ln": round(density, 3),
    }


def settled_traffic(spec: TrafficSpec, net: Path) -> tuple[list[Vehicle], float, dict]:
    """(vehicles, density scale, measured level) of the first warm-up whose measured level
    is the spec's, of at most ``ATTEMPTS``: the next starts from the density scaled by the
    ratio of the band's middle to the measure (its square root for a follower density,
    which grows about as the square of the density)."""
    limit = spec.speed_limit_kmh or 0.0
    bounds = hcm.FREEWAY_DENSITY_PCMILN if spec.road == "motorway" else hcm.two_lane_bounds(limit)
    low, high = hcm.band(bounds, spec.los)
    power = 1.0 if spec.road == "motorway" else 0.5
    scale = 1.0
    for attempt in range(ATTEMPTS):
        vehicles = warm_up(spec, net, scale, attempt)
        measured = measured_level(spec, vehicles)
        if measured["level"] == spec.los or attempt == ATTEMPTS - 1:
            break
        ratio = 0.5 * (low + high) / max(measured["value"], 0.05)
        scale = min(max(scale * ratio**power, 0.2), 3.0)
    measured["attempts"] = attempt + 1
    return vehicles, scale, measured


def write_scenario(spec: TrafficSpec, out_dir: Path) -> Path:
    """Write the scenario of ``spec`` into ``out_dir``; the path of its ``scenario.sumocfg``."""
    spec = spec.checked()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    net = write_network(spec, out_dir)
    vehicles, scale, measured = settled_traffic(spec, net)
    obstacle, ego_front_m = choose_gap(vehicles)
    ego = Vehicle("ego", FORWARD, 0, ego_front_m, (spec.speed_limit_kmh or 0.0) / 3.6, 1.0)
    others = [v for v in vehicles if v.vid != obstacle.vid]
    tail = _vehicle_line(
        obstacle,
        inner='        <param key="eoam.role" value="aro"/>\n'
        f'        <param key="eoam.aro_hold_s" value="{OBSTACLE_HOLD_S:g}"/>\n'
        f'        <param key="eoam.aro_decel_mps2" value="{OBSTACLE_DECEL_MPS2:g}"/>\n',
    ) + _vehicle_line(ego, vtype="ego")
    end_s = 600.0
    (out_dir / "scenario.rou.xml").write_text(
        _routes(spec, others, tail, end_s, scale), encoding="utf-8"
    )
    (out_dir / "scenario.sumocfg").write_text(
        _sumocfg(net.name, "scenario.rou.xml", spec.seed, 0.01, end_s), encoding="utf-8"
    )
    record = {
        "spec": asdict(spec),
        "hcm_target": dict(zip(("density_veh_km_ln", "speed_mps"), map(_r3, target(spec)))),
        "density_scale": round(scale, 4),
        "measured": measured,
        "obstacle": {"id": obstacle.vid, "front_pos_m": obstacle.pos_m},
        "ego": {"front_pos_m": round(ego_front_m, 2), "lane": f"{FORWARD}_0"},
        "vehicles": len(vehicles),
    }
    (out_dir / "scenario.json").write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    return out_dir / "scenario.sumocfg"


def _r3(value: float) -> float:
    return round(value, 3) if math.isfinite(value) else value
