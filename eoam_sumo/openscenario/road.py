"""The OpenDRIVE road as a SUMO network, and OpenDRIVE lane positions on it.

netconvert imports the road (``--opendrive-files``); ``--output.original-names`` gives each
SUMO lane the parameter ``origId="<road>_<lane>"`` (OpenDRIVE road and lane id). A lane with a
negative id runs along the road's s on edge ``-<road>`` (``#k`` for lane section k), a positive
one against it. Shoulders and borders are dropped; ``stop`` lanes (hard shoulders) stay,
drivable. The network is cached under ``cache_dir`` keyed by the road file's SHA-256.
"""

from __future__ import annotations

import bisect
import hashlib
import shutil
import subprocess
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo import __version__
from eoam_sumo.errors import InputError
from eoam_sumo.netbuild import _sumo_env

NETCONVERT_OPTIONS = ("--output.original-names", "true", "--no-turnarounds", "true")


@dataclass(frozen=True)
class SumoLane:
    """A SUMO lane carrying an OpenDRIVE lane from ``start_s_m`` to ``end_s_m`` of its road's
    reference line (its edge's part of the road); ``s_pts``/``pos_pts`` pair each vertex of
    its shape with the ``s`` it lies at (increasing) and its position along the lane, so that
    a lane of a curve beside straights, or one that starts in a later lane section, maps
    ``s`` to its own positions (:mod:`.lanetable`)."""

    edge: str
    index: int
    start_s_m: float
    end_s_m: float
    length_m: float
    along_s: bool
    s_pts: tuple[float, ...]
    pos_pts: tuple[float, ...]

    def pos_m(self, s_m: float) -> float:
        """Position along the SUMO lane of the reference-line coordinate ``s_m`` (beyond the
        lane's shape, where netconvert cut it short of a junction, straight on from its end:
        an entity driving through moves on, it does not stop at the lane's end and jump)."""
        s, pos = self.s_pts, self.pos_pts
        if len(s) < 2 or s[0] <= s_m <= s[-1]:
            return _interp(s_m, s, pos)
        slope = (pos[-1] - pos[0]) / (s[-1] - s[0]) if s[-1] > s[0] else 0.0
        end = 0 if s_m < s[0] else -1
        return pos[end] + (s_m - s[end]) * slope

    def s_m(self, pos_m: float) -> float:
        """The reference-line coordinate of a position along the SUMO lane."""
        pos, s = (self.pos_pts, self.s_pts) if self.along_s else (
            self.pos_pts[::-1], self.s_pts[::-1])  # fmt: skip
        return _interp(pos_m, pos, s)


def _interp(x: float, xp: tuple[float, ...], fp: tuple[float, ...]) -> float:
    """``numpy.interp`` for one value: piecewise linear over increasing ``xp``, held at the
    end values outside."""
    if x <= xp[0]:
        return float(fp[0])
    if x >= xp[-1]:
        return float(fp[-1])
    k = bisect.bisect_right(xp, x)
    x0, x1, f0, f1 = xp[k - 1], xp[k], fp[k - 1], fp[k]
    return float(f0 + (f1 - f0) * (x - x0) / (x1 - x0)) if x1 > x0 else float(f1)


def convert(xodr: Path, cache_dir: Path) -> Path:
    """``cache_dir/<sha256>/<name>.net.xml`` built from ``xodr`` (reused when present)."""
    import sumolib

    digest = hashlib.sha256(Path(xodr).read_bytes()).hexdigest()[:16]
    folder = Path(cache_dir) / digest
    net = folder / (Path(xodr).stem + ".net.xml")
    if net.is_file():
        return net
    tmp = folder.with_name(digest + ".tmp")
    tmp.mkdir(parents=True, exist_ok=True)
    args = [sumolib.checkBinary("netconvert"), "--opendrive-files", str(Path(xodr).resolve())]
    args += [*NETCONVERT_OPTIONS, "--output-file", net.name]
    done = subprocess.run(
        args, cwd=tmp, env=_sumo_env(), capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise InputError(f"{xodr}: netconvert cannot convert the road: {done.stderr.strip()}")
    text = (tmp / net.name).read_text(encoding="utf-8")
    note = f"<!-- converted from {Path(xodr).name} (sha256 {digest}) by eoam_sumo {__version__}"
    head, sep, body = text.partition("<net ")
    (tmp / net.name).write_text(f"{head}{note} -->\n{sep}{body}", encoding="utf-8")
    shutil.rmtree(folder, ignore_errors=True)
    tmp.rename(folder)
    return net


def check_road(xodr: Path) -> None:
    """InputError for a road under left-hand traffic (OpenDRIVE 1.5+ ``rule="LHT"``): its
    lanes with positive ids run along s, the mapping here (negative ids along s) is the
    right-hand one."""
    for road in parse_xodr(xodr).iter("road"):
        if road.get("rule", "RHT").upper() == "LHT":
            raise InputError(
                f'{xodr}: road {road.get("id")} has rule="LHT": left-hand traffic is not '
                "supported (docs/openscenario.md)"
            )


def parse_xodr(xodr: Path) -> ET.Element:
    """The OpenDRIVE file's root element; ``InputError`` naming the file when it is not
    well-formed XML (a broken tag, bytes that are no text)."""
    try:
        return ET.parse(xodr).getroot()
    except ET.ParseError as exc:
        raise InputError(f"{xodr}: not well-formed XML: {exc}") from None
    except OSError as exc:
        raise InputError(f"{xodr}: cannot be read: {exc.strerror or exc}") from None


WIDE_M = 6.0  # a driving lane wider than this: the EOAM may swerve inside it


def wide_lanes(xodr: Path) -> list[str]:
    """A note (one line) naming the driving lanes wider than ``WIDE_M`` (Vector's NCAP road is
    one 28 m lane each way: the EOAM swerves within it), or none."""
    wide: dict[str, float] = {}
    for road in parse_xodr(xodr).iter("road"):
        for lane, length_m in _section_lanes(road):
            widest = _widest_m(lane, length_m)
            if lane.get("type") == "driving" and widest > WIDE_M:
                key = f"road {road.get('id')} lane {lane.get('id')}"
                wide[key] = max(widest, wide.get(key, 0.0))
    if not wide:
        return []
    listed = ", ".join(f"{k}: {w:g} m" for k, w in wide.items())
    return [f"driving lanes wider than {WIDE_M:g} m ({listed}): the EOAM may swerve within one"]


def _section_lanes(road: ET.Element) -> list[tuple[ET.Element, float]]:
    """Each lane of each lane section of ``road``, with the section's length [m]."""
    sections = list(road.iter("laneSection"))
    starts = [float(sec.get("s", "0")) for sec in sections]
    ends = [*starts[1:], float(road.get("length", "0"))]
    return [
        (lane, max(end - start, 0.0))
        for sec, start, end in zip(sections, starts, ends, strict=True)
        for lane in sec.iter("lane")
    ]


def _widest_m(lane: ET.Element, section_m: float) -> float:
    """A lane's largest width over its section: each ``<width>`` polynomial
    ``a + b ds + c ds^2 + d ds^3`` (OpenDRIVE 1.6 sec. 9.5.1) sampled from its ``sOffset`` to
    the next one's (or the section's end)."""
    entries = list(lane.iter("width"))
    offsets = [float(w.get("sOffset", "0")) for w in entries]
    ends = [*offsets[1:], section_m][: len(entries)]
    widest = 0.0
    for w, start, end in zip(entries, offsets, ends, strict=True):
        a, b, c, d = (float(w.get(k, "0")) for k in "abcd")
        for i in range(11):
            ds = max(end - start, 0.0) * i / 10.0
            widest = max(widest, a + ds * (b + ds * (c + ds * d)))
    return widest


def road_lengths(xodr: Path) -> dict[str, float]:
    """OpenDRIVE road id -> its reference line length."""
    root = parse_xodr(xodr)
    return {r.get("id", ""): float(r.get("length", "0")) for r in root.iter("road")}


def locate(table: dict, road: str, lane: int, s_m: float, where: str) -> tuple[SumoLane, float]:
    """The SUMO lane and position of OpenDRIVE ``road``/``lane`` at ``s_m``."""
    lanes = table.get((road, lane))
    if not lanes:
        raise InputError(f"{where}: road {road} lane {lane} is not a drivable SUMO lane")
    for sl in lanes:
        if sl.start_s_m - 1e-6 <= s_m <= sl.end_s_m + 1e-6:
            return sl, sl.pos_m(s_m)
    raise InputError(f"{where}: s={s_m:g} m is off road {road} lane {lane}")
