"""The one module that talks to Eclipse SUMO: libsumo for runs, TraCI only for the GUI.

A :class:`SumoSession` loads a ``.sumocfg`` after checking its files, applies the
:class:`ScenarioOverrides` (surface friction, an added oncoming car, the ARO's emergency stop),
advances SUMO to the ego's departure and makes the step that inserts the ego at the requested
speed (moveToXY before the insertion step, design sec. 6). It then answers the co-simulation's
queries: the ego's reference line, the bodies around the ego (variable subscriptions) and
the friction under the ego. The ego is re-inserted as a copy of its route-file vehicle (route,
type, departLane/departPos and ``<param>``s kept; other attributes and its stops dropped).

Scripted stop (paper sec. 10.1, Figure 19): a vehicle with the ``<param>`` ``eoam.aro_hold_s``
and ``eoam.aro_decel_mps2`` keeps its departure speed for ``aro_hold_s`` after departing, then
decelerates at ``min(aro_decel_mps2, mu_lane * g)`` to standstill and stays there, mu_lane
being the friction of the lane under it.

Frames: SUMO's network coordinates; SUMO reports a vehicle's FRONT bumper centre and its
navigation angle (degrees clockwise from north); :class:`Body` holds the body's centre and
the yaw counter-clockwise from +x in rad.
"""

from __future__ import annotations

import contextlib
import gzip
import math
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
import xml.etree.ElementTree as ET
from collections import namedtuple
from dataclasses import dataclass
from pathlib import Path
from typing import Self

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.params import G_MPS2, oncoming_sedan
from eoam_sumo.sim.geometry import OrientedBox

ROLE_KEY = "eoam.role"
HOLD_KEY = "eoam.aro_hold_s"
DECEL_KEY = "eoam.aro_decel_mps2"
MU_MAX = 1.2

EGO_SPEED_MODE = 32  # design sec. 6: SUMO applies setSpeed and moveToXY without checks
SCRIPTED_SPEED_MODE = 25  # safe speed, right of way, red lights; no accel/decel bound
ONCOMING_SPEED_MODE = 0  # constant speed even when the ego is mapped onto its lane
NO_LANE_CHANGES = 0
PARKING_BIT = 2  # bit of VAR_STOPSTATE set while a vehicle is parked
ENFORCED_OPTIONS = (
    ("--collision.action", "none"),
    ("--time-to-teleport", "-1"),
    ("--no-warnings", "true"),
    ("--no-step-log", "true"),
    # load every route at the start: by default SUMO may read a vehicle listed after another
    # with the same departure only in its departure step, too late to re-insert it as the ego
    ("--route-steps", "0"),
)
SPEED_LIMIT_WORDS = ("max", "desired", "speedLimit")
ERROR_LOG_STDERR = "sumo-stderr.log"  # SUMO's standard error while libsumo starts (workdir)
TRACI_RETRIES = 600  # x 50 ms: time SUMO may take to load before TraCI gives up
PROCESS_EXIT_S = 10.0  # time a closed SUMO server process gets to exit

_open_libsumo: list[SumoSession] = []  # libsumo runs one simulation per process


def _number(
    name: str, value, *, minimum: float, inclusive: bool = True, maximum: float | None = None
) -> float:
    """``value`` as a float; InputError naming ``name`` unless it is a finite number in range."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (value >= minimum if inclusive else value > minimum)
    ok = ok and (maximum is None or value <= maximum)
    if not ok:
        bound = f"{'>=' if inclusive else '>'} {minimum:g}"
        if maximum is not None:
            bound += f" and <= {maximum:g}"
        raise InputError(f"{name}={value!r} must be a finite number {bound}")
    return float(value)


@dataclass(frozen=True)
class ScenarioOverrides:
    """Changes applied to a scenario's SUMO files at the start of a run; None keeps the files'.

    ``mu`` sets the friction of every lane; ``oncoming_start_m`` adds one oncoming car in the lane
    opposite the ego's, its front bumper that far ahead of the ego's front bumper along the road,
    at the constant ``oncoming_speed_mps``; ``aro_*`` replace the stop parameters of the vehicles
    tagged ``eoam.role=aro``.
    """

    ego_speed_mps: float | None = None
    mu: float | None = None
    oncoming_start_m: float | None = None
    oncoming_speed_mps: float = 20.0
    aro_hold_s: float | None = None
    aro_decel_mps2: float | None = None

    def __post_init__(self) -> None:
        if self.ego_speed_mps is not None:
            _number("ego_speed_mps", self.ego_speed_mps, minimum=0.0)
        if self.mu is not None:
            _number("mu", self.mu, minimum=0.0, inclusive=False, maximum=MU_MAX)
        if self.oncoming_start_m is not None:
            _number("oncoming_start_m", self.oncoming_start_m, minimum=0.0)
        _number("oncoming_speed_mps", self.oncoming_speed_mps, minimum=0.0)
        if self.aro_hold_s is not None:
            _number("aro_hold_s", self.aro_hold_s, minimum=0.0)
        if self.aro_decel_mps2 is not None:
            _number("aro_decel_mps2", self.aro_decel_mps2, minimum=0.0, inclusive=False)


_BodyFields = namedtuple(
    "_BodyFields", "vid x_m y_m yaw_rad speed_mps length_m width_m parked box"
)  # untyped: introspection sees Body's own constructor, without ``box``


def _reach2(radius_m: float, body: Body) -> float:
    """Square of the largest front-bumper distance at which some point of ``body`` can be
    within ``radius_m``: radius plus the box's diagonal (twice its bounding radius)."""
    reach_m = radius_m + 2.0 * body.box.radius_m
    return reach_m * reach_m


class Body(_BodyFields):
    """A road user as SUMO sees it: centre (x_m, y_m), yaw CCW from +x, footprint, and its
    oriented box (for the radar and the contact test).

    ``Body(vid, x_m, y_m, yaw_rad, speed_mps, length_m, width_m, parked)``; an immutable
    tuple subclass, built for every moving vehicle at every step."""

    __slots__ = ()

    def __new__(cls, vid: str, x_m: float, y_m: float, yaw_rad: float, speed_mps: float,
                length_m: float, width_m: float, parked: bool):
        box = OrientedBox(x_m, y_m, yaw_rad, length_m, width_m)
        return tuple.__new__(cls, (vid, x_m, y_m, yaw_rad, speed_mps, length_m, width_m,
                                   parked, box))

    def __getnewargs__(self):
        return self[:8]

    def __repr__(self) -> str:
        return (f"Body(vid={self.vid!r}, x_m={self.x_m!r}, y_m={self.y_m!r}, "
                f"yaw_rad={self.yaw_rad!r}, speed_mps={self.speed_mps!r}, "
                f"length_m={self.length_m!r}, width_m={self.width_m!r}, parked={self.parked!r})")


@dataclass(frozen=True)
class VehicleSpec:
    """A ``<vehicle>``/``<trip>`` as written in a route or additional file."""

    vid: str
    source: Path
    attrs: dict
    params: dict
    routed: bool = True  # False for a trip (from/to, no route): SUMO routes it at insertion


@dataclass(frozen=True)
class ScenarioFiles:
    """The checked files of a ``.sumocfg`` and what the adapter needs from them."""

    cfg: Path
    net_file: Path
    route_files: tuple[Path, ...]
    additional_files: tuple[Path, ...]
    vehicles: dict  # vid -> VehicleSpec
    opposite_lanes: dict  # lane id -> id of its <neigh> (opposite-direction) lane


def _xml_source(path: Path):
    """The file to parse: SUMO reads gzip-compressed XML (``*.gz``) too."""
    return gzip.open(path) if path.suffix == ".gz" else path


def _parse_xml(path: Path, what: str) -> ET.Element:
    if not path.is_file():
        raise InputError(f"{what} {path} not found")
    try:
        return ET.parse(_xml_source(path)).getroot()
    except (ET.ParseError, OSError) as exc:
        raise InputError(f"{path}: malformed XML: {exc}") from exc


def _read_net(path: Path) -> dict:
    """Lane id -> opposite lane id, streaming through the network file: each ``<neigh>``, and
    for a two-way road built without them the leftmost lanes of an edge and its reverse edge
    (swapped junctions) when they lie side by side (``_side_by_side``)."""
    if not path.is_file():
        raise InputError(f"net-file {path} not found")
    opposite, lane_id, first = {}, None, True
    edges = {}  # normal edge id -> (from, to, leftmost lane (index, id, width, shape))
    edge_id = None
    try:
        for event, elem in ET.iterparse(_xml_source(path), events=("start", "end")):
            if first:
                if elem.tag != "net":
                    raise InputError(f"{path}: not a SUMO network (root element <{elem.tag}>)")
                if elem.get("lefthand") in ("true", "1"):
                    raise InputError(
                        f"{path}: a left-hand-traffic network: the EOAM changes lanes to the "
                        "left, where right-hand traffic has the opposite lane; not supported"
                    )
                first = False
            if event == "start" and elem.tag == "edge":
                edge_id = elem.get("id") if elem.get("function") in (None, "normal") else None
                if edge_id is not None:
                    edges[edge_id] = (elem.get("from"), elem.get("to"), None)
            elif event == "start" and elem.tag == "lane":
                lane_id = elem.get("id")
                _check_lane_numbers(path, lane_id, elem)
                if edge_id is not None:
                    frm, to, left = edges[edge_id]
                    index = int(elem.get("index", "0"))
                    if left is None or index > left[0]:
                        edges[edge_id] = (frm, to, (index, lane_id, elem.get("width", "3.2"),
                                                    elem.get("shape", "")))
            elif event == "start" and elem.tag == "neigh" and lane_id is not None:
                opposite[lane_id] = elem.get("lane")
            elif event == "end" and elem.tag in ("edge", "junction", "connection", "tlLogic"):
                elem.clear()
    except (ET.ParseError, OSError) as exc:
        raise InputError(f"{path}: malformed XML: {exc}") from exc
    # (parallel edges between the same two junctions: the last one read stands for them)
    by_ends = {(frm, to): left for frm, to, left in edges.values() if left is not None}
    for (frm, to), left in by_ends.items():
        back = by_ends.get((to, frm))
        if back is None or left[1] in opposite or back[1] in opposite:
            continue
        if _side_by_side(left, back):
            opposite[left[1]] = back[1]
            opposite[back[1]] = left[1]
    return opposite


def _side_by_side(lane: tuple, other: tuple) -> bool:
    """The two lanes ((index, id, width, shape) as in the net file) lie next to each other: the
    other lane's centre line passes the middle of this one on its left at half the sum of their
    widths (within 0.3 m)."""
    try:
        a = np.array([[float(v) for v in p.split(",")[:2]] for p in lane[3].split()])
        b = np.array([[float(v) for v in p.split(",")[:2]] for p in other[3].split()])
        width = 0.5 * (float(lane[2]) + float(other[2]))
    except ValueError:
        return False
    if len(a) < 2 or len(b) < 2:
        return False
    mx, my, heading = point_at(a, 0.5 * _arclength(a)[-1])
    bx, by, _ = point_at(b, project(b, mx, my)[0])  # the nearest point of the other lane
    left = -math.sin(heading) * (bx - mx) + math.cos(heading) * (by - my)
    return abs(left - width) <= 0.3
def _check_lane_numbers(path: Path, lane_id: str | None, lane: ET.Element) -> None:
    """A lane's numbers, where given, must be numbers in range (SUMO itself crashes on some
    that are not): ``friction`` in (0, MU_MAX], ``width``, ``length`` and ``speed`` > 0,
    ``index`` a whole number >= 0."""
    for key, top in (("friction", MU_MAX), ("width", math.inf), ("length", math.inf),
                     ("speed", math.inf), ("index", math.inf)):
        text = lane.get(key)
        if text is None:
            continue
        try:
            value = int(text) if key == "index" else float(text)
        except ValueError:
            value = math.nan
        low_ok = value >= 0 if key == "index" else value > 0.0
        if not (low_ok and value <= top and math.isfinite(value)):
            bound = "a whole number >= 0" if key == "index" else (
                f"a number in (0, {top:g}]" if math.isfinite(top) else "a number > 0")
            raise InputError(f"{path}: lane '{lane_id}' {key}={text!r} must be {bound}")


def _option_files(root: ET.Element, cfg: Path, option: str) -> tuple[Path, ...]:
    files = []
    for elem in root.iter(option):
        value = elem.get("value", "")
        files += [cfg.parent / name.strip() for name in value.split(",") if name.strip()]
    return tuple(files)


def check_scenario(cfg: Path, ego_id: str = "ego") -> ScenarioFiles:
    """Check a ``.sumocfg`` and its files with ElementTree before SUMO sees them.

    Raises InputError naming the file for a missing or malformed file, a config without a
    net-file, or no vehicle ``ego_id`` in its route and additional files.
    """
    cfg = Path(cfg)
    root = _parse_xml(cfg, "sumocfg")
    nets = _option_files(root, cfg, "net-file")
    if len(nets) != 1:
        raise InputError(f"{cfg}: needs exactly one <net-file value=...>, found {len(nets)}")
    opposite = _read_net(nets[0])
    routes = _option_files(root, cfg, "route-files")
    additionals = _option_files(root, cfg, "additional-files")
    vehicles = {}
    for path, what in [(p, "route file") for p in routes] + [
        (p, "additional file") for p in additionals
    ]:
        for elem in _parse_xml(path, what).iter():
            if elem.tag in ("vehicle", "trip") and elem.get("id") is not None:
                params = {p.get("key"): p.get("value") for p in elem.findall("param")}
                routed = elem.tag == "vehicle" and (
                    "route" in elem.attrib or elem.find("route") is not None
                )
                vehicles[elem.get("id")] = VehicleSpec(
                    elem.get("id"), path, dict(elem.attrib), params, routed
                )
    if ego_id not in vehicles:
        searched = ", ".join(p.name for p in routes + additionals) or "no route files"
        raise InputError(
            f"{cfg}: no vehicle '{ego_id}' in its route or additional files ({searched})"
        )
    return ScenarioFiles(cfg, nets[0], routes, additionals, vehicles, opposite)


def _without_repeats(edges) -> list[str]:
    """Route edges with consecutive repeats dropped (a trip from an edge to itself)."""
    out: list[str] = []
    for edge in edges:
        if not out or edge != out[-1]:
            out.append(edge)
    return out


def _float_attr(spec: VehicleSpec, key: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{spec.source}: vehicle '{spec.vid}' {key}={text!r} is not a number")
    return value


@dataclass
class _Script:
    """Run-time state of a scripted emergency stop."""

    hold_end_s: float
    decel_mps2: float
    hold_speed_mps: float
    mu: float = 1.0
    last_cmd_mps: float = -1.0


def scripted_stops(files: ScenarioFiles, overrides: ScenarioOverrides,
                   ego_id: str | None = None) -> dict:
    """Vehicle id -> (hold_s, decel_mps2) for every vehicle whose stop is scripted (not the
    ego's: the plant drives it, whatever its parameters say)."""
    stops, aro_seen = {}, False
    for spec in files.vehicles.values():
        if spec.vid == ego_id:
            continue
        is_aro = spec.params.get(ROLE_KEY) == "aro"
        aro_seen = aro_seen or is_aro
        values = {}
        for key, override in (
            (HOLD_KEY, overrides.aro_hold_s),
            (DECEL_KEY, overrides.aro_decel_mps2),
        ):
            if is_aro and override is not None:
                values[key] = override
            elif key in spec.params:
                values[key] = _float_attr(spec, f"param {key}", spec.params[key])
        if not values:
            continue
        missing = [k for k in (HOLD_KEY, DECEL_KEY) if k not in values]
        if missing:
            raise InputError(
                f"{spec.source}: vehicle '{spec.vid}' has a scripted stop but no "
                f'<param key="{missing[0]}">'
            )
        hold = _number(
            f"{spec.source}: vehicle '{spec.vid}' {HOLD_KEY}", values[HOLD_KEY], minimum=0.0
        )
        decel = _number(
            f"{spec.source}: vehicle '{spec.vid}' {DECEL_KEY}",
            values[DECEL_KEY],
            minimum=0.0,
            inclusive=False,
        )
        stops[spec.vid] = (hold, decel)
    if not aro_seen and (overrides.aro_hold_s is not None or overrides.aro_decel_mps2 is not None):
        raise InputError(
            f"{files.cfg}: aro_hold_s/aro_decel_mps2 given but no vehicle has "
            f'<param key="{ROLE_KEY}" value="aro">'
        )
    return stops


def _arclength(poly: np.ndarray) -> np.ndarray:
    return np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(poly, axis=0).T))))


def point_at(poly: np.ndarray, s_m: float) -> tuple[float, float, float]:
    """(x, y, heading_rad) at arc length ``s_m`` along a polyline (clamped to its ends)."""
    s = _arclength(poly)
    i = int(np.clip(np.searchsorted(s, s_m, side="right") - 1, 0, len(poly) - 2))
    seg = poly[i + 1] - poly[i]
    u = (min(max(s_m, 0.0), s[-1]) - s[i]) / max(s[i + 1] - s[i], 1e-12)
    p = poly[i] + u * seg
    return float(p[0]), float(p[1]), math.atan2(seg[1], seg[0])


def project(poly: np.ndarray, x_m: float, y_m: float) -> tuple[float, float]:
    """(arc length, distance) of the point of a polyline nearest to (x_m, y_m)."""
    a, b = poly[:-1], poly[1:]
    seg = b - a
    seg_len2 = np.maximum(np.einsum("ij,ij->i", seg, seg), 1e-24)
    u = np.clip(np.einsum("ij,ij->i", np.array([x_m, y_m]) - a, seg) / seg_len2, 0.0, 1.0)
    foot = a + u[:, None] * seg
    dist = np.hypot(foot[:, 0] - x_m, foot[:, 1] - y_m)
    i = int(np.argmin(dist))
    return float(_arclength(poly)[i] + u[i] * math.sqrt(seg_len2[i])), float(dist[i])


def nav_angle_deg(yaw_rad: float) -> float:
    """SUMO navigation angle (degrees clockwise from north) of a yaw (rad CCW from +x)."""
    return (90.0 - math.degrees(yaw_rad)) % 360.0


def yaw_rad(nav_angle_deg: float) -> float:
    """Yaw in (-pi, pi], CCW from +x, of a SUMO navigation angle."""
    yaw = math.remainder(math.radians(90.0 - nav_angle_deg), 2.0 * math.pi)
    return yaw + 2.0 * math.pi if yaw <= -math.pi else yaw


class SumoSession:
    """One running SUMO scenario with the ego under external control. Use :meth:`start`."""

    def __init__(
        self,
        api,
        constants,
        errors: tuple,
        files: ScenarioFiles,
        overrides: ScenarioOverrides,
        ego_id: str,
        step_length_s: float,
        workdir: Path,
        process=None,
    ) -> None:
        self._api, self._tc, self._errors, self._files = api, constants, errors, files
        self._overrides, self.ego_id, self._dt = overrides, ego_id, step_length_s
        self._workdir, self._process = workdir, process
        self._veh, self._lane, self._sim = api.vehicle, api.lane, api.simulation
        self._closed = False
        self._time_s = self._sim.getTime()
        self._mu_cache: dict[str, float] = {}
        self._dims_cache: dict[str, tuple[float, float]] = {}
        self._stops = scripted_stops(files, overrides, ego_id)
        self._pending_stops = set(self._stops)
        self._scripts: dict[str, _Script] = {}
        self._radius_m: float | None = None
        self._tracking = False  # the other vehicles are followed (from the first ``nearby``)
        self._moving: dict[str, tuple | None] = {}  # vid -> (results, front, Body) once read
        self._parked: dict[str, tuple] = {}  # vid -> (front, Body), fixed while it stays parked
        self._parked_cache: tuple | None = None  # the last answer of _parked_near, see there
        self._sense_vars = [
            self._tc.VAR_POSITION,
            self._tc.VAR_ANGLE,
            self._tc.VAR_SPEED,
            self._tc.VAR_TYPE,
            self._tc.VAR_STOPSTATE,
        ]
        self._ego_vars = [self._tc.VAR_LANE_ID]  # every step (friction); the pose at the start
        self._results: dict | None = None  # variable-subscription results of this step, once read
        self._ego_mu = 1.0
        self._over_limit: dict[str, float] = {}  # vid -> speed of a departure above the limit
        self.ego_depart_time_s = self._time_s
        self.oncoming_id: str | None = None
        self.roles = {
            vid: s.params[ROLE_KEY] for vid, s in files.vehicles.items() if ROLE_KEY in s.params
        }

    # ----------------------------------------------------------------------------- start
    @classmethod
    def start(
        cls,
        cfg: Path,
        overrides: ScenarioOverrides = ScenarioOverrides(),
        *,
        ego_id: str = "ego",
        step_length_s: float = 0.01,
        gui: bool = False,
        use_traci: bool = False,
        extra_args: tuple[str, ...] = (),
    ) -> SumoSession:
        """Check the files, start SUMO, advance it to the ego's departure and make the step
        that inserts the ego at the requested speed; on return the ego is in SUMO and every
        query answers. ``gui`` runs ``sumo-gui`` through TraCI, ``use_traci`` plain ``sumo``
        through TraCI; otherwise libsumo (in-process, one session per process)."""
        if not isinstance(overrides, ScenarioOverrides):
            raise TypeError(
                f"overrides must be a ScenarioOverrides, not {type(overrides).__name__}"
            )
        step = _number("step_length_s", step_length_s, minimum=0.0, inclusive=False)
        if abs(step * 1000.0 - round(step * 1000.0)) > 1e-9:
            raise InputError(
                f"step_length_s={step_length_s!r} must be a whole number of milliseconds"
            )
        extra = tuple(str(a) for a in extra_args)
        files = check_scenario(Path(cfg), ego_id)
        scripted_stops(files, overrides, ego_id)

        import sumo
        import sumolib

        os.environ.setdefault("SUMO_HOME", sumo.SUMO_HOME)
        via_traci = gui or use_traci
        if gui and sys.platform.startswith("linux") and not (
                os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise InputError("--gui needs a display, and DISPLAY is not set (sumo-gui would "
                             "fail to connect after 30 s)")
        if not via_traci and _open_libsumo:
            raise RuntimeError("a libsumo session is already open in this process; close it first")
        workdir = Path(tempfile.mkdtemp(prefix="eoam-sumo-"))
        error_log = workdir / "sumo-errors.log"
        cmd = [
            sumolib.checkBinary("sumo-gui" if gui else "sumo"),
            "-c",
            str(files.cfg),
            "--step-length",
            f"{step:.3f}",
            "--error-log",
            str(error_log),
        ]
        given = {a.split("=", 1)[0] for a in extra if a.startswith("-")}
        for option, value in ENFORCED_OPTIONS:
            if option not in given:
                cmd += [option, value]
        if gui:
            cmd += ["--start", "true", "--quit-on-end", "true"]
        cmd += list(extra)
        try:
            if via_traci:
                import traci

                errors = (traci.exceptions.TraCIException, traci.exceptions.FatalTraCIError)
                try:
                    api, process = _traci_connect(cmd)
                except (*errors, OSError) as exc:
                    raise InputError(_start_error(files.cfg, error_log, exc)) from exc
                constants = traci.constants
            else:
                import libsumo

                errors = (libsumo.TraCIException, libsumo.FatalTraCIError)
                try:
                    with _stderr_into(workdir / ERROR_LOG_STDERR):
                        libsumo.start(cmd)
                except errors as exc:
                    raise InputError(_start_error(files.cfg, error_log, exc)) from exc
                api, constants, process = libsumo, libsumo.constants, None
        except BaseException:
            shutil.rmtree(workdir, ignore_errors=True)
            raise
        session = None
        try:
            session = cls(api, constants, errors, files, overrides, ego_id, step, workdir, process)
            if not via_traci:
                _open_libsumo.append(session)
            session._set_up()
        except BaseException as exc:
            if session is not None:
                session._release()
            else:
                _shut_down(api, process)
            detail = _start_error(files.cfg, error_log, exc) if isinstance(exc, errors) else None
            shutil.rmtree(workdir, ignore_errors=True)
            if detail is None:
                raise
            raise InputError(detail) from exc
        return session

    def _set_up(self) -> None:
        spec = self._files.vehicles[self.ego_id]
        depart = _float_attr(spec, "depart", spec.attrs.get("depart", "0"))
        if depart < self._time_s - 1e-9:
            raise InputError(
                f"{spec.source}: vehicle '{self.ego_id}' departs at {depart:g} s, "
                f"before the simulation begins ({self._time_s:g} s)"
            )
        if self._overrides.mu is not None:
            settable = True
            for lane_id in self._lane.getIDList():
                self._mu_cache[lane_id] = self._overrides.mu
                if settable:
                    try:
                        self._lane.setFriction(lane_id, self._overrides.mu)
                    except Exception:  # noqa: BLE001 - TraCI's class may come from SUMO_HOME/tools
                        # TraCI of SUMO 1.28 cannot set friction: the override lives here only
                        settable = False
        while self._time_s < depart - 0.5 * self._dt:
            self._sumo_step()
        self.ego_depart_time_s = self._time_s
        self._place_ego(spec)
        if self._overrides.oncoming_start_m is not None:
            self._add_oncoming()
        self._veh.subscribe(self.ego_id, self._ego_vars)
        self._sumo_step()
        if self.ego_id not in self._veh.getIDList():
            raise InputError(f"{spec.source}: SUMO did not insert vehicle '{self.ego_id}'")
        for vid, speed in self._over_limit.items():  # departed at rest (see _insert)
            self._veh.setPreviousSpeed(vid, speed)

    def _place_ego(self, spec: VehicleSpec) -> None:
        veh, ego = self._veh, self.ego_id
        try:
            if not spec.routed:  # a trip holds only its end points until SUMO routes it
                veh.rerouteTraveltime(ego)
            edges = _without_repeats(veh.getRoute(ego))
            self._ego_type = veh.getTypeID(ego)
        except self._errors as exc:
            raise InputError(f"{spec.source}: SUMO did not load vehicle '{ego}': {exc}") from exc
        lane_index = self._ego_lane_index(spec, edges[0])
        lane_id = f"{edges[0]}_{lane_index}"
        lane_len = self._lane.getLength(lane_id)
        pos = self._ego_depart_pos(spec, lane_len)
        speed = self._ego_speed(spec, lane_id)
        veh.remove(ego)
        self._insert(ego, self._ego_type, edges, lane_index, pos, speed, EGO_SPEED_MODE,
                     spec.params)
        self._route_edges = edges
        self._lane_index = lane_index
        self._start_lane_id = lane_id
        self.lane_width_m = float(self._lane.getWidth(lane_id))
        self.left_lane_exists = (
            lane_index < self._api.edge.getLaneNumber(edges[0]) - 1
            or lane_id in self._files.opposite_lanes
        )
        self._ego_mu = self._friction(lane_id)
        self._ego_front_start = self._lane_point(lane_id, pos)[:2]
        self._centreline = self._build_centreline()

    def _ego_lane_index(self, spec: VehicleSpec, edge: str) -> int:
        text = spec.attrs.get("departLane", "first")
        n_lanes = self._api.edge.getLaneNumber(edge)
        if text == "first":
            vclass = self._api.vehicletype.getVehicleClass(self._ego_type)
            for i in range(n_lanes):
                allowed = self._lane.getAllowed(f"{edge}_{i}")
                if (not allowed or vclass in allowed) and vclass not in self._lane.getDisallowed(
                    f"{edge}_{i}"
                ):
                    return i
            raise InputError(f"{spec.source}: no lane of edge '{edge}' allows vehicle '{spec.vid}'")
        if not text.isdigit() or int(text) >= n_lanes:
            raise InputError(
                f"{spec.source}: vehicle '{spec.vid}' departLane={text!r}: the ego needs "
                f"a lane index below {n_lanes} (or 'first')"
            )
        return int(text)

    def _ego_depart_pos(self, spec: VehicleSpec, lane_len: float) -> float:
        text = spec.attrs.get("departPos", "base")
        if text == "base":
            return min(self._api.vehicletype.getLength(self._ego_type), lane_len)
        pos = _float_attr(spec, "departPos", text)
        pos = pos + lane_len if pos < 0 else pos
        if not 0.0 <= pos <= lane_len:
            raise InputError(
                f"{spec.source}: vehicle '{spec.vid}' departPos={text!r} is off its "
                f"{lane_len:.2f} m start lane"
            )
        return pos

    def _ego_speed(self, spec: VehicleSpec, lane_id: str) -> float:
        if self._overrides.ego_speed_mps is not None:
            return self._overrides.ego_speed_mps
        text = spec.attrs.get("departSpeed", "0")
        if text in SPEED_LIMIT_WORDS:
            return min(
                self._lane.getMaxSpeed(lane_id), self._api.vehicletype.getMaxSpeed(self._ego_type)
            )
        speed = _float_attr(spec, "departSpeed", text)
        return _number(f"{spec.source}: vehicle '{spec.vid}' departSpeed", speed, minimum=0.0)

    def _lane_point(self, lane_id: str, pos_m: float) -> tuple[float, float, float]:
        shape = np.asarray(self._lane.getShape(lane_id), dtype=float)
        scale = _arclength(shape)[-1] / max(self._lane.getLength(lane_id), 1e-9)
        return point_at(shape, pos_m * scale)

    def _build_centreline(self) -> np.ndarray:
        """Centre line of the ego's start lane followed along its route: from each lane over its
        connection (and the junction's internal lanes) to the lane it leads to on the next
        route edge, the one with the same index when there are several."""
        lane = self._start_lane_id
        points = [tuple(p) for p in self._lane.getShape(lane)]
        for edge in self._route_edges[1:]:
            links = [link for link in self._lane.getLinks(lane)
                     if self._lane.getEdgeID(link[0]) == edge]
            if not links:
                raise InputError(
                    f"{self._files.net_file}: the ego's lane {lane} does not continue onto "
                    f"edge '{edge}' of its route (no connection: the lane ends); start the ego "
                    "in a lane that continues"
                )
            link = min(links, key=lambda k: abs(int(k[0].rsplit("_", 1)[1]) - self._lane_index))
            via = link[4]
            for _ in range(8):  # a junction's internal lanes, until the next normal lane
                if not via or not via.startswith(":"):
                    break
                points += [tuple(p) for p in self._lane.getShape(via)]
                onward = self._lane.getLinks(via)
                via = onward[0][0] if onward else None
            lane = link[0]
            points += [tuple(p) for p in self._lane.getShape(lane)]
        line = [points[0]]
        for p in points[1:]:
            if math.hypot(p[0] - line[-1][0], p[1] - line[-1][1]) > 1e-6:
                line.append(p)
        return np.array(line, dtype=float)

    def _add_oncoming(self) -> None:
        distance = self._overrides.oncoming_start_m
        s_ego, _ = project(self._centreline, *self._ego_front_start)
        total = _arclength(self._centreline)[-1]
        if s_ego + distance > total:
            raise InputError(
                f"oncoming_start_m={distance:g}: the ego's route ends "
                f"{total - s_ego:.1f} m ahead of the ego"
            )
        px, py, _ = point_at(self._centreline, s_ego + distance)
        opposite = []  # per route edge: the opposite lane of its leftmost lane, or None
        for edge in self._route_edges:
            leftmost = f"{edge}_{self._api.edge.getLaneNumber(edge) - 1}"
            opposite.append(self._files.opposite_lanes.get(leftmost))
        candidates = [
            (project(np.asarray(self._lane.getShape(o), float), px, py), k, o)
            for k, o in enumerate(opposite)
            if o is not None
        ]
        if not candidates:
            raise InputError(
                f"{self._files.net_file}: the ego's lane {self._start_lane_id} has no "
                "opposite lane (<neigh lane=...>) for the oncoming car"
            )
        (s_opp, _), k, lane_id = min(candidates, key=lambda c: c[0][1])
        edges = []
        for o in reversed(opposite[: k + 1]):
            if o is None:
                break
            edges.append(self._lane.getEdgeID(o))
        shape = np.asarray(self._lane.getShape(lane_id), dtype=float)
        pos = s_opp * self._lane.getLength(lane_id) / _arclength(shape)[-1]
        speed = self._overrides.oncoming_speed_mps
        types = self._api.vehicletype
        if "oncoming" not in types.getIDList():
            dims = oncoming_sedan()
            types.copy("DEFAULT_VEHTYPE", "oncoming")
            types.setLength("oncoming", dims.length_m)
            types.setWidth("oncoming", dims.width_m)
        vid, n = "oncoming", 0
        while vid in self._files.vehicles:
            n += 1
            vid = f"oncoming.{n}"
        index = int(lane_id.rsplit("_", 1)[1])  # SUMO lane ids are <edge>_<index>
        self._insert(vid, "oncoming", edges, index, pos, speed, ONCOMING_SPEED_MODE,
                     {ROLE_KEY: "oncoming"})
        self.oncoming_id = vid
        self.roles[vid] = "oncoming"

    def _insert(self, vid: str, type_id: str, edges: list, lane_index: int, pos: float,
                speed: float, speed_mode: int, params: dict) -> None:
        """Add ``vid`` on a fresh route over ``edges`` at ``pos`` of its first lane, placed there
        exactly with ``moveToXY`` and moving at ``speed`` from the insertion step on."""
        veh = self._veh
        route_id = f"eoam.route.{vid}.{uuid.uuid4().hex[:8]}"
        self._api.route.add(route_id, edges)
        try:
            veh.add(vid, route_id, type_id, depart="now", departLane=str(lane_index),
                    departPos=repr(float(pos)), departSpeed=repr(float(speed)))
        except self._errors as exc:
            if "too high" not in str(exc):
                raise
            # SUMO refuses a departure above the lane's limit times the vehicle's speed factor,
            # or above its type's maximum: depart at rest, with room to go faster; the speed
            # set below applies from the insertion step on (speed modes without limits)
            veh.add(vid, route_id, type_id, depart="now", departLane=str(lane_index),
                    departPos=repr(float(pos)), departSpeed="0")
            limit = self._lane.getMaxSpeed(f"{edges[0]}_{lane_index}")
            veh.setSpeedFactor(vid, max(veh.getSpeedFactor(vid), speed / limit * (1.0 + 1e-6)))
            veh.setMaxSpeed(vid, max(veh.getMaxSpeed(vid), speed * (1.0 + 1e-6)))
            self._over_limit[vid] = speed
        for key, value in params.items():
            veh.setParameter(vid, key, value)
        veh.setSpeedMode(vid, speed_mode)
        veh.setLaneChangeMode(vid, NO_LANE_CHANGES)
        x, y, heading = self._lane_point(f"{edges[0]}_{lane_index}", pos)
        veh.moveToXY(vid, edges[0], lane_index, x, y, nav_angle_deg(heading), keepRoute=1)
        veh.setPreviousSpeed(vid, speed)
        veh.setSpeed(vid, speed)

    # ----------------------------------------------------------------------------- stepping
    def _sumo_step(self) -> None:
        if self._scripts:
            self._apply_stops()
        self._api.simulationStep()
        self._results = None
        self._time_s = self._sim.getTime()
        if self._tracking or self._pending_stops:
            departed = self._sim.getDepartedIDList()
            if self._tracking:
                self._track(departed)
            for vid in departed:
                if vid in self._pending_stops:
                    self._start_stop(vid)

    def _watch(self, vid: str) -> None:
        """Subscribe to what the adapter reads of ``vid`` (its body, its scripted stop), or
        unsubscribe when that is nothing."""
        wanted = list(self._sense_vars) if vid in self._moving else []
        if vid in self._scripts:
            wanted += [v for v in (self._tc.VAR_SPEED, self._tc.VAR_LANE_ID) if v not in wanted]
        if wanted:
            self._veh.subscribe(vid, wanted)
        else:
            self._veh.unsubscribe(vid)
        self._results = None

    def _step_results(self) -> dict:
        """Vehicle id -> its variable-subscription results at this step (one read a step)."""
        if self._results is None:
            self._results = self._veh.getAllSubscriptionResults()
        return self._results

    def _track(self, departed) -> None:
        """Follow the vehicles that departed or ended parking in this step, drop those that
        arrived."""
        for vid in self._sim.getArrivedIDList():
            self._moving.pop(vid, None)
            if self._parked.pop(vid, None) is not None:
                self._parked_cache = None
        for vid in self._sim.getParkingEndingVehiclesIDList():
            if self._parked.pop(vid, None) is not None:
                self._parked_cache = None
                self._moving[vid] = None
                self._watch(vid)
        for vid in departed:
            if vid != self.ego_id:
                self._moving[vid] = None
                self._watch(vid)

    def _start_tracking(self) -> None:
        self._tracking = True
        self._veh.subscribe(self.ego_id, [*self._ego_vars, self._tc.VAR_POSITION])
        self._results = None  # re-read: this step's cached results lack the ego's position
        for vid in self._veh.getIDList():
            if vid != self.ego_id:
                self._moving[vid] = None
                self._watch(vid)

    def _start_stop(self, vid: str) -> None:
        hold, decel = self._stops[vid]
        self._pending_stops.discard(vid)
        self._scripts[vid] = _Script(
            self._veh.getDeparture(vid) + hold, decel, self._veh.getSpeed(vid)
        )
        self._veh.setSpeedMode(vid, SCRIPTED_SPEED_MODE)
        self._watch(vid)

    def _apply_stops(self) -> None:
        """Command each scripted vehicle's speed at the end of the coming step (Figure 19)."""
        t_next = self._time_s + self._dt
        for vid, script in list(self._scripts.items()):
            res = self._step_results().get(vid)
            if not res:
                del self._scripts[vid]
                continue
            if t_next <= script.hold_end_s + 1e-9:
                cmd = script.hold_speed_mps
            else:
                if res[self._tc.VAR_LANE_ID]:
                    script.mu = self._friction(res[self._tc.VAR_LANE_ID])
                decel = min(script.decel_mps2, script.mu * G_MPS2)
                cmd = max(
                    0.0, res[self._tc.VAR_SPEED] - decel * min(self._dt, t_next - script.hold_end_s)
                )
            if cmd != script.last_cmd_mps:
                self._veh.setSpeed(vid, cmd)
                script.last_cmd_mps = cmd
            elif cmd == 0.0 and res[self._tc.VAR_SPEED] == 0.0:
                # stopped under a standing zero command: every later command is zero too
                del self._scripts[vid]
                self._watch(vid)

    def step(self) -> None:
        """Advance SUMO by one step."""
        self._check_open()
        try:
            self._sumo_step()
        except self._errors as exc:
            raise RuntimeError(f"SUMO failed at t={self._time_s:.3f} s: {exc}") from exc

    @property
    def time_s(self) -> float:
        """SUMO's simulation time."""
        return self._time_s

    @property
    def step_length_s(self) -> float:
        return self._dt

    # ----------------------------------------------------------------------------- queries
    def ego_lane_centreline(self) -> np.ndarray:
        """(N, 2) centre line of the ego's start lane followed along its route (lane index kept)."""
        return self._centreline.copy()

    def _friction(self, lane_id: str) -> float:
        mu = self._mu_cache.get(lane_id)
        if mu is None:
            mu = self._mu_cache[lane_id] = float(self._lane.getFriction(lane_id))
        return mu

    def friction_at_ego(self) -> float:
        """Friction of the lane under the ego now (the last known one while it is off all lanes)."""
        lane_id = self._ego_results()[self._tc.VAR_LANE_ID]
        if lane_id:
            self._ego_mu = self._friction(lane_id)
        return self._ego_mu

    def lane_friction(self, lane_id: str) -> float:
        return float(self._lane.getFriction(lane_id))

    def lane_ids(self) -> list[str]:
        return list(self._lane.getIDList())

    def move_ego(
        self, x_front_m: float, y_front_m: float, angle_nav_deg: float, speed_mps: float
    ) -> None:
        """Place the ego's front bumper for the next step (keepRoute=2: any lane, even opposite)."""
        self._check_open()
        self._veh.moveToXY(self.ego_id, "", -1, x_front_m, y_front_m, angle_nav_deg, 2)
        self._veh.setSpeed(self.ego_id, speed_mps)

    def _dims(self, type_id: str) -> tuple[float, float]:
        dims = self._dims_cache.get(type_id)
        if dims is None:
            types = self._api.vehicletype
            dims = self._dims_cache[type_id] = (types.getLength(type_id), types.getWidth(type_id))
        return dims

    def _body(
        self, vid: str, front: tuple, angle_deg: float, speed: float, type_id: str, stop_state: int
    ) -> Body:
        length, width = self._dims(type_id)
        yaw = yaw_rad(angle_deg)
        half = 0.5 * length
        return Body(
            vid,
            front[0] - half * math.cos(yaw),
            front[1] - half * math.sin(yaw),
            yaw,
            speed,
            length,
            width,
            bool(stop_state & PARKING_BIT),
        )

    def nearby(self, radius_m: float) -> list[Body]:
        """Every other vehicle some part of which may be within ``radius_m`` of the ego's SUMO
        position (its front bumper), sorted by id: one whose front bumper is within
        ``radius_m`` plus its diagonal (no point of its box is farther from its front), so
        that a long vehicle is found as soon as its nearest point can be in reach.

        From the first call on the session follows all vehicles: a moving one through a
        variable subscription, a parked one as a fixed body once it was read parked twice
        with the same values, until SUMO reports its parking ended (a context subscription
        would read every parked car at every step). A vehicle whose values did not change
        since the last call is the same ``Body`` object as then.
        """
        self._check_open()
        if radius_m != self._radius_m:
            _number("radius_m", radius_m, minimum=0.0, inclusive=False)
            self._radius_m = radius_m
        if not self._tracking:
            self._start_tracking()
        results = self._step_results()
        ego = results.get(self.ego_id)
        if not ego:
            raise RuntimeError(f"the ego '{self.ego_id}' is no longer in the simulation")
        ex, ey = ego[self._tc.VAR_POSITION]
        near = self._moving_near(results, ex, ey, radius_m) + self._parked_near(ex, ey, radius_m)
        near.sort()  # Body tuples start with their (unique) id
        return near

    def _moving_near(self, results: dict, ex: float, ey: float, radius_m: float) -> list:
        """Bodies of the followed moving vehicles within ``radius_m`` of (ex, ey), from this
        step's ``results``; a vehicle found parked with settled values becomes fixed."""
        near, settled = [], []
        for vid, known in self._moving.items():
            r = results.get(vid)
            if not r:  # left without arriving (removed)
                settled.append((vid, None))
                continue
            if known is None or known[0] != r:
                known = self._moving[vid] = (r, r[self._tc.VAR_POSITION], self._sumo_body(vid, r))
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
                self._watch(vid)
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

    def _sumo_body(self, vid: str, r: dict) -> Body:
        """Body of a vehicle from its subscription results."""
        tc = self._tc
        return self._body(vid, r[tc.VAR_POSITION], r[tc.VAR_ANGLE], r[tc.VAR_SPEED],
                          r[tc.VAR_TYPE], r[tc.VAR_STOPSTATE])

    def _ego_results(self) -> dict:
        self._check_open()
        res = self._step_results().get(self.ego_id)
        if not res:
            raise RuntimeError(f"the ego '{self.ego_id}' is no longer in the simulation")
        return res

    def ego_body(self) -> Body:
        """The ego as SUMO sees it."""
        self._ego_results()  # fails when the ego has left
        veh, ego = self._veh, self.ego_id
        return self._body(
            ego, veh.getPosition(ego), veh.getAngle(ego), veh.getSpeed(ego), self._ego_type, 0
        )

    def body(self, vid: str) -> Body:
        """Any vehicle by id (getters; for checks, not for the step loop)."""
        self._check_open()
        veh = self._veh
        return self._body(
            vid,
            veh.getPosition(vid),
            veh.getAngle(vid),
            veh.getSpeed(vid),
            veh.getTypeID(vid),
            veh.getStopState(vid),
        )

    def vehicle_ids(self) -> list[str]:
        return list(self._veh.getIDList())

    def vehicle_speed(self, vid: str) -> float:
        return float(self._veh.getSpeed(vid))

    def vehicle_lane(self, vid: str) -> str:
        return self._veh.getLaneID(vid)

    # ----------------------------------------------------------------------------- life cycle
    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError("the SUMO session is closed")

    def _release(self) -> None:
        """End SUMO, keeping the session's working directory."""
        if self._closed:
            return
        self._closed = True
        if self in _open_libsumo:
            _open_libsumo.remove(self)
        _shut_down(self._api, self._process)

    def close(self) -> None:
        """End SUMO (idempotent)."""
        self._release()
        shutil.rmtree(self._workdir, ignore_errors=True)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _shut_down(api, process) -> None:
    """Close the connection to SUMO (errors of an already dead SUMO ignored), end its process."""
    with contextlib.suppress(Exception):
        api.close()
    _end_process(process)


def _end_process(process) -> None:
    """Wait for a SUMO server process to end (it was told to close or failed), else kill it."""
    if process is None:
        return
    try:
        process.wait(timeout=PROCESS_EXIT_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def _traci_connect(cmd: list[str]):
    """Start SUMO as a TraCI server and connect, polling every 50 ms (traci.start waits 1 s
    and prints while it retries)."""
    import io

    import sumolib
    import traci

    port = sumolib.miscutils.getFreeSocketPort()
    proc = subprocess.Popen([*cmd, "--remote-port", str(port)], stdout=subprocess.DEVNULL)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            conn = traci.connect(port, numRetries=TRACI_RETRIES, waitBetweenRetries=0.05)
    except BaseException:
        _end_process(proc)
        raise
    return conn, proc


@contextlib.contextmanager
def _stderr_into(path: Path):
    """Send this process's standard error (file descriptor 2) to ``path`` meanwhile: in-process
    SUMO reports errors met while loading the routes at start there, not to its error log."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(path, "ab") as sink:
            os.dup2(sink.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _start_error(cfg: Path, error_log: Path, exc: BaseException) -> str:
    """One line with SUMO's own error messages (its error log and what it wrote to standard
    error while starting, else the exception's text)."""
    text = ""
    for log in (error_log, error_log.with_name(ERROR_LOG_STDERR)):
        try:
            text += log.read_text(errors="replace")
        except OSError:
            pass
    lines = [ln.strip().removeprefix("Error: ") for ln in (text or str(exc)).splitlines()]
    detail = " ".join(ln for ln in lines if ln and ln != "Quitting (on error).")
    return f"{cfg}: SUMO could not load the scenario: {detail or type(exc).__name__}"
