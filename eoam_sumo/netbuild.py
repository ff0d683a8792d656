"""Build SUMO networks from plain XML sources with netconvert.

``python -m eoam_sumo.netbuild DIR`` rebuilds ``NAME.net.xml`` for every ``NAME.nod.xml`` in DIR
that has a matching ``NAME.edg.xml`` (plus ``NAME.con.xml`` / ``NAME.typ.xml`` when present).
netconvert omits a lane's ``friction`` when it equals SUMO's default 1.0; the built network
gets every friction declared in the edge source written out explicitly, so the surface of an
experiment is visible (and editable) in its network file.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr

from eoam_sumo import __version__
from eoam_sumo.errors import InputError

NETCONVERT_OPTIONS = ("--no-turnarounds", "true", "--offset.disable-normalization", "true")


def _sumo_env() -> dict[str, str]:
    import sumo

    env = dict(os.environ)
    env.setdefault("SUMO_HOME", sumo.SUMO_HOME)
    return env


def declared_frictions(edg_file: Path) -> dict[str, float]:
    """Lane id -> friction for every ``<lane index= friction=>`` of a plain edge file."""
    try:
        root = ET.parse(edg_file).getroot()
    except (OSError, ET.ParseError) as exc:
        raise InputError(f"{edg_file}: cannot read the edge file: {exc}") from exc
    frictions = {}
    for edge in root.iter("edge"):
        for lane in edge.iter("lane"):
            if "friction" in lane.attrib:
                lane_id = f"{edge.get('id')}_{lane.get('index')}"
                try:
                    frictions[lane_id] = float(lane.attrib["friction"])
                except ValueError as exc:
                    raise InputError(
                        f"{edg_file}: lane {lane_id} friction={lane.get('friction')!r} "
                        "is not a number"
                    ) from exc
    return frictions


def write_frictions(net_text: str, frictions: dict[str, float]) -> str:
    """Add ``friction="..."`` to each lane in ``frictions`` that netconvert left without one."""

    def add(match: re.Match) -> str:
        tag = match.group(0)
        lane_id = match.group(1)
        if lane_id not in frictions or " friction=" in tag:
            return tag
        return tag.replace(
            f'id="{lane_id}"', f'id="{lane_id}" friction="{frictions[lane_id]:.2f}"', 1
        )

    return re.sub(r'<lane id="([^"]+)"[^>]*>', add, net_text)


def build_network(nod_file: Path) -> Path:
    """Run netconvert on ``NAME.nod.xml`` + ``NAME.edg.xml``; returns ``NAME.net.xml``."""
    import sumolib

    nod_file = Path(nod_file)
    directory = nod_file.parent
    name = nod_file.name.removesuffix(".nod.xml")
    edg_file = directory / f"{name}.edg.xml"
    if not edg_file.is_file():
        raise InputError(f"{nod_file}: no matching edge file {edg_file.name}")
    out_file = directory / f"{name}.net.xml"
    args = [
        sumolib.checkBinary("netconvert"),
        "--node-files",
        nod_file.name,
        "--edge-files",
        edg_file.name,
    ]
    for suffix, option in ((".con.xml", "--connection-files"), (".typ.xml", "--type-files")):
        if (directory / f"{name}{suffix}").is_file():
            args += [option, f"{name}{suffix}"]
    args += [*NETCONVERT_OPTIONS, "--output-file", out_file.name]
    done = subprocess.run(
        args, cwd=directory, env=_sumo_env(), capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise RuntimeError(f"netconvert failed on {nod_file}: {done.stderr.strip()}")
    text = write_frictions(out_file.read_text(encoding="utf-8"), declared_frictions(edg_file))
    note = (
        f"<!-- lane friction written explicitly by eoam_sumo.netbuild {__version__} "
        f"from {edg_file.name} -->\n"
    )
    head, sep, body = text.partition("<net ")
    out_file.write_text(head + note + "\n" + sep + body, encoding="utf-8")
    return out_file


def build_all(directory: Path) -> list[Path]:
    """Rebuild every network in ``directory``; returns the written files in name order."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"{directory}: not a directory")
    return [build_network(nod) for nod in sorted(directory.glob("*.nod.xml"))]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        sys.stderr.write("usage: python -m eoam_sumo.netbuild DIR\n")
        return 2
    try:
        built = build_all(Path(args[0]))
    except InputError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    for path in built:
        sys.stdout.write(f"built {path}\n")
    return 0


_SUMOCFG = """<?xml version="1.0" encoding="UTF-8"?>
{comment}<configuration>
    <input>
        <net-file value={net}/>
        <route-files value={routes}/>
        <additional-files value={additional}/>
    </input>
    <time><begin value="0"/><end value="{end:g}"/><step-length value="0.01"/></time>
    <processing><collision.action value="none"/><time-to-teleport value="-1"/></processing>
    <random_number><seed value="42"/></random_number>
    <report><no-step-log value="true"/></report>
</configuration>
"""


def sumocfg_text(
    net: str, routes: str, additional: str, end_s: float = 600.0, comment: str = ""
) -> str:
    """A generated scenario's sumocfg: its network, routes and vTypes, SUMO's 10 ms step,
    no collision handling or teleports (the co-simulation judges contacts), seed 42."""
    head = f"<!-- {comment} -->\n" if comment else ""
    return _SUMOCFG.format(
        comment=head,
        net=quoteattr(net),
        routes=quoteattr(routes),
        additional=quoteattr(additional),
        end=end_s,
    )


if __name__ == "__main__":
    raise SystemExit(main())
