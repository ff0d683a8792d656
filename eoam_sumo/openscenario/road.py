"""The OpenDRIVE road as a SUMO network, and OpenDRIVE lane positions on it.

netconvert imports the road (``--opendrive-files``); ``--output.original-names`` gives each
SUMO lane the parameter ``origId="<road>_<lane>"`` (OpenDRIVE road and lane id). A lane with a
negative id runs along the road's s on edge ``-<road>`` (``#k`` for lane section k), a positive
one against it. Shoulders and borders are dropped; ``stop`` lanes (hard shoulders) stay,
drivable. The network is cached under ``cache_dir`` keyed by the road file's SHA-256.
"""

from __future__ import annotations

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
    """A SUMO lane: ``pos_m`` along it of a reference-line ``s`` (``scale``: lane length per
    metre of road, 1 on a straight road)."""

    edge: str
    index: int
    start_s_m: float
    length_m: float
    scale: float
    along_s: bool

    def pos_m(self, s_m: float) -> float:
        """Position along the SUMO lane of the reference-line coordinate ``s_m``."""
        d = (s_m - self.start_s_m) * self.scale
        return d if self.along_s else self.length_m - d


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


def road_lengths(xodr: Path) -> dict[str, float]:
    """OpenDRIVE road id -> its reference line length."""
    root = ET.parse(xodr).getroot()
    return {r.get("id", ""): float(r.get("length", "0")) for r in root.iter("road")}


def lane_table(net: Path, xodr: Path) -> dict[tuple[str, int], list[SumoLane]]:
    """(road, lane id) -> the SUMO lanes carrying it, in the order of s."""
    lengths = road_lengths(xodr)
    found: dict[tuple[str, int], list[tuple[str, int, float]]] = {}
    for edge in ET.parse(net).getroot().iter("edge"):
        if edge.get("function") == "internal":
            continue
        for lane in edge.iter("lane"):
            orig = next(
                (p.get("value") for p in lane.iter("param") if p.get("key") == "origId"), None
            )
            if orig is None or "_" not in orig:
                continue
            road, _, lane_id = orig.rpartition("_")
            key = (road, int(lane_id))
            item = (edge.get("id", ""), int(lane.get("index", "0")), float(lane.get("length", "0")))
            found.setdefault(key, []).append(item)
    return {key: _ordered(key, items, lengths) for key, items in found.items()}


def _ordered(
    key: tuple[str, int], items: list[tuple[str, int, float]], lengths: dict[str, float]
) -> list[SumoLane]:
    along = key[1] < 0
    items = sorted(items, key=lambda it: _section(it[0]), reverse=not along)
    total = sum(it[2] for it in items)
    road_m = lengths.get(key[0], total) or total
    scale = total / road_m
    out, start = [], 0.0
    for edge, index, length in items if along else reversed(items):
        out.append(SumoLane(edge, index, start, length, scale, along))
        start += length / scale
    return out if along else list(reversed(out))


def _section(edge: str) -> int:
    _, sep, k = edge.rpartition("#")
    return int(k) if sep and k.isdigit() else 0


def locate(table: dict, road: str, lane: int, s_m: float, where: str) -> tuple[SumoLane, float]:
    """The SUMO lane and position of OpenDRIVE ``road``/``lane`` at ``s_m``."""
    lanes = table.get((road, lane))
    if not lanes:
        raise InputError(f"{where}: road {road} lane {lane} is not a drivable SUMO lane")
    for sl in lanes:
        if sl.start_s_m - 1e-6 <= s_m <= sl.start_s_m + sl.length_m / sl.scale + 1e-6:
            return sl, sl.pos_m(s_m)
    raise InputError(f"{where}: s={s_m:g} m is off road {road} lane {lane}")
