"""Scenario builders shared by the tests: small SUMO networks, route files and sumocfg files,
written under a test's temporary folder. Building a network runs netconvert, so a test that
calls ``network`` or ``netconvert`` is marked ``sumo``."""

from __future__ import annotations

import subprocess
import textwrap
from collections.abc import Iterable
from pathlib import Path

from eoam_sumo import netbuild

ROOT = Path(__file__).resolve().parents[1]
NETWORKS = ROOT / "networks"
SCENARIOS = ROOT / "scenarios"
HIGHWAY_NET = NETWORKS / "highway.net.xml"
VTYPES = SCENARIOS / "vtypes.add.xml"
BASELINE = SCENARIOS / "baseline.sumocfg"
PARKED_ONLY = SCENARIOS / "parked_only.sumocfg"


def write_sumocfg(
    path: Path,
    net: Path | str,
    routes: Path | str,
    additional: Iterable[Path | str] = (),
    step_length_s: float | None = None,
) -> Path:
    """A sumocfg at ``path`` naming these files (relative names are relative to its folder)."""
    files = ",".join(str(a) for a in additional)
    text = f'<configuration><input><net-file value="{net}"/><route-files value="{routes}"/>'
    if files:
        text += f'<additional-files value="{files}"/>'
    text += "</input>"
    if step_length_s is not None:
        text += f'<time><step-length value="{step_length_s}"/></time>'
    path.write_text(text + "</configuration>")
    return path


def network(folder: Path, stem: str, nodes_xml: str, edges_xml: str) -> Path:
    """``STEM.net.xml`` built from these plain nodes and edges by ``eoam_sumo.netbuild`` (the
    project's netconvert options, lane frictions written out)."""
    (folder / f"{stem}.nod.xml").write_text(nodes_xml)
    (folder / f"{stem}.edg.xml").write_text(edges_xml)
    return netbuild.build_network(folder / f"{stem}.nod.xml")


def straight_road(folder: Path, name: str, widths: list[float], lanes: list[int]) -> None:
    """``NAME.sumocfg``: a straight one-way road of 500 m edges ``e0``, ``e1``, ... with these
    lane widths and lane counts, the ego alone on it (``NAME.rou.xml``, 30 m/s in lane 0)."""
    nodes = "".join(f'<node id="n{k}" x="{500.0 * k}" y="0"/>' for k in range(len(widths) + 1))
    edges = "".join(
        f'<edge id="e{k}" from="n{k}" to="n{k + 1}" numLanes="{n}" speed="50" width="{w}"/>'
        for k, (w, n) in enumerate(zip(widths, lanes))
    )
    network(folder, name, f"<nodes>{nodes}</nodes>", f"<edges>{edges}</edges>")
    route = " ".join(f"e{k}" for k in range(len(widths)))
    (folder / f"{name}.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departPos="50" departLane="0" '
        f'departSpeed="30"><route edges="{route}"/></vehicle></routes>'
    )
    write_sumocfg(folder / f"{name}.sumocfg", f"{name}.net.xml", f"{name}.rou.xml")


def netconvert(folder: Path, stem: str, nodes_xml: str, edges_xml: str, *options: str) -> Path:
    """``STEM.net.xml`` built by plain netconvert with these options, as a user would build it
    (netconvert's defaults otherwise)."""
    import sumolib

    (folder / f"{stem}.nod.xml").write_text(nodes_xml)
    (folder / f"{stem}.edg.xml").write_text(edges_xml)
    net = folder / f"{stem}.net.xml"
    subprocess.run(
        [
            sumolib.checkBinary("netconvert"),
            "-n",
            str(folder / f"{stem}.nod.xml"),
            "-e",
            str(folder / f"{stem}.edg.xml"),
            *options,
            "-o",
            str(net),
        ],
        check=True,
        capture_output=True,
    )
    return net


def on_highway(folder: Path, routes_xml: str, net: Path = HIGHWAY_NET) -> Path:
    """These routes (vehicle types of ``scenarios/vtypes.add.xml`` available) on the project's
    highway, or on another network: ``v.sumocfg``."""
    (folder / "v.rou.xml").write_text(routes_xml)
    return write_sumocfg(folder / "v.sumocfg", net, "v.rou.xml", [VTYPES])


def walker_on_highway(
    folder: Path,
    depart_pos_m: float,
    arrival_pos_m: float,
    ego_speed_mps: float,
    person_depart_s: float = 1.0,
) -> Path:
    """The ego at ``ego_speed_mps`` (front bumper at x = 100 m, departing at 1 s) and a person
    walking along its lane (no sidewalk: SUMO's persons walk on the road) from
    ``depart_pos_m`` to ``arrival_pos_m`` along E0 (towards the ego when the arrival lies
    behind the departure)."""
    return on_highway(
        folder,
        f"""<routes>
  <vType id="walker" vClass="pedestrian" length="0.30" width="0.55" maxSpeed="1.4"/>
  <route id="eastbound" edges="E0"/>
  <vehicle id="ego" type="ego" route="eastbound" depart="1.00" departLane="0"
           departPos="100.00" departSpeed="{ego_speed_mps:.3f}" insertionChecks="none"/>
  <person id="walker" type="walker" depart="{person_depart_s:.2f}" departPos="{depart_pos_m}">
    <walk edges="E0" arrivalPos="{arrival_pos_m}"/>
  </person>
</routes>""",
    )


def baseline_variant(folder: Path, old: str, new: str, extra_additional: str = "") -> Path:
    """The baseline scenario with one edit to its route file (and an additional file of
    ``folder`` besides the vehicle types, if given): ``variant.sumocfg``."""
    routes = (SCENARIOS / "baseline.rou.xml").read_text()
    assert old in routes
    (folder / "r.rou.xml").write_text(routes.replace(old, new, 1))
    return write_sumocfg(
        folder / "variant.sumocfg",
        HIGHWAY_NET,
        "r.rou.xml",
        filter(None, [str(VTYPES), extra_additional]),
    )


def halted_car_scenario(
    folder: Path, nodes_xml: str, edges_xml: str, obstacle_pos_m: float, *netconvert_options: str
) -> Path:
    """A small user scenario: the given road (edge ``fwd`` first), a car halted on it at
    ``obstacle_pos_m`` by a plain ``<stop>``, the ego 20 m from the start at 27 m/s."""
    netconvert(folder, "n", nodes_xml, edges_xml, "--no-turnarounds", "true", *netconvert_options)
    (folder / "r.rou.xml").write_text(
        textwrap.dedent(f"""\
        <routes>
          <vType id="car" length="4.6" width="1.8" decel="9" sigma="0"/>
          <route id="r" edges="fwd"/>
          <vehicle id="stalled" type="car" route="r" depart="0" departPos="{obstacle_pos_m}"
                   departSpeed="0">
            <stop lane="fwd_0" endPos="{obstacle_pos_m + 5}" duration="1000"/>
          </vehicle>
          <vehicle id="ego" type="car" route="r" depart="0" departPos="20" departSpeed="27"/>
        </routes>""")
    )
    return write_sumocfg(folder / "s.sumocfg", "n.net.xml", "r.rou.xml")


def write_matrix(
    path: Path, sweep: str, sumocfg: Path = BASELINE, scenario: str = "", paper_table: bool = False
) -> Path:
    """An experiment matrix at ``path``: ``[scenario]`` with ``sumocfg`` and the extra
    ``scenario`` lines, ``[sweep]`` with the ``sweep`` lines, and the paper's Table 2 to
    compare with if ``paper_table``."""
    text = f'[scenario]\nsumocfg = "{sumocfg.as_posix()}"\n{scenario}[sweep]\n{sweep}'
    if paper_table:
        text += f'[paper]\ntable = "{(SCENARIOS / "paper_table2.csv").as_posix()}"\n'
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def right_lane_sensing(lane_width_m: float, target_width_m: float):
    """The corner radars' sensing of the lane right of the ego's (same direction, 36 m/s
    limit, a 100 m / 18 deg forward radar, the sedan's 4.92 x 1.85 m body)."""
    from eoam_sumo.sensing.next_lane import NextLaneSensing

    return NextLaneSensing(
        opposing=False,
        speed_limit_mps=36.0,
        lane_width_m=lane_width_m,
        radar_range_m=100.0,
        radar_fov_deg=18.0,
        ego_length_m=4.92,
        ego_width_m=1.85,
        side=-1,
        target_width_m=target_width_m,
    )
