"""traffic.csv and ``eoam-sumo animate`` on a real run: the baseline scenario with a person
walking along the ego's lane ahead and an oncoming car; SUMO's own fcd-output of the same
run is the independent record the traffic log is checked against."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from eoam_sumo.cli import main
from eoam_sumo.plotting.animate import (
    ROLE_COLOURS,
    Scene,
    animate_run,
    picture_aspect,
    still_frame,
)
from eoam_sumo.plotting.animation_frames import load_frames
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.trafficlog import TRAFFIC_COLUMNS, read_traffic
from tests.builders import halted_car_scenario

pytestmark = pytest.mark.sumo
ROOT = Path(__file__).resolve().parents[2]
STEP_S = 0.01
WALKER = (
    '<person id="walker" depart="1.00" departPos="260"><walk edges="E0" arrivalPos="400"/></person>'
)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("walker")
    scenarios = ROOT / "scenarios"
    routes = (scenarios / "baseline.rou.xml").read_text().replace("</routes>", WALKER + "</routes>")
    (folder / "walker.rou.xml").write_text(routes)
    (folder / "walker.sumocfg").write_text(
        f'<configuration><input><net-file value="{ROOT / "networks" / "highway.net.xml"}"/>'
        f'<route-files value="{scenarios / "parked.rou.xml"},walker.rou.xml"/>'
        f'<additional-files value="{scenarios / "vtypes.add.xml"},'
        f'{ROOT / "networks" / "highway_parking.add.xml"}"/></input>'
        f'<output><fcd-output value="fcd.xml"/><precision value="6"/></output>'
        "</configuration>"
    )
    run_case(
        folder / "walker.sumocfg",
        ScenarioOverrides(ego_speed_mps=90 / 3.6, oncoming_start_m=300.0),
        folder / "run",
        RunSettings(max_time_s=3.0),
    )
    return folder / "run"


def test_traffic_csv_holds_the_ego_the_parked_cars_and_the_walker(run_dir):
    traffic = read_traffic(run_dir / "traffic.csv")
    assert tuple(traffic.columns) == TRAFFIC_COLUMNS
    ts = pd.read_csv(run_dir / "timeseries.csv")
    ego = traffic[traffic["id"] == "ego"]
    np.testing.assert_array_equal(ego["time_s"].to_numpy(), ts["time_s"].round(6).to_numpy())
    assert set(ego["role"]) == {"ego"}
    parked = traffic[traffic["id"].str.startswith("parked_")]
    assert set(parked["role"]) == {"parked"} and set(parked["speed_mps"]) == {0.0}
    assert parked["id"].nunique() >= 3  # the ones within 250 m of the ego
    walker = traffic[traffic["id"] == "walker"]
    assert len(walker) == len(ego)  # on the road, ahead, in the log at every step
    assert set(walker["vclass"]) == {"pedestrian"}
    assert set(walker["role"]) == {"aro"}  # in the ego's lane, ahead of it
    assert walker["speed_mps"].iloc[1:].between(0.5, 2.0).all()  # walking (from rest)
    assert (np.diff(walker["x_m"]) >= 0.0).all() and walker["x_m"].iloc[-1] > 262.0
    assert set(traffic.loc[traffic["id"] == "aro", "role"]) == {"aro"}
    assert set(traffic.loc[traffic["id"] == "oncoming", "role"]) == {"oncoming"}


def _fcd(path: Path) -> pd.DataFrame:
    rows = [
        (
            round(float(step.get("time")), 3),
            user.get("id"),
            float(user.get("x")),
            float(user.get("y")),
        )
        for step in ET.parse(path).getroot().iter("timestep")
        for user in step
    ]
    return pd.DataFrame(rows, columns=["time_s", "id", "fx", "fy"])


def test_traffic_csv_at_t_is_sumos_fcd_output_at_t_minus_one_step(run_dir):
    """SUMO writes each step's result under the time the step began, the co-simulation logs
    it under SUMO's clock after the step: the front of every road user in traffic.csv at
    t is where fcd-output puts it at t - 0.01 s (the ego's first row aside: the plant starts
    its centre of gravity where SUMO had the body's centre)."""
    traffic = read_traffic(run_dir / "traffic.csv")
    traffic["fx"] = traffic["x_m"] + 0.5 * traffic["length_m"] * np.cos(traffic["heading_rad"])
    traffic["fy"] = traffic["y_m"] + 0.5 * traffic["length_m"] * np.sin(traffic["heading_rad"])
    traffic["time_s"] = traffic["time_s"].round(3)
    fcd = _fcd(run_dir.parent / "fcd.xml")
    first = traffic["time_s"].min()
    for shift, close in ((-STEP_S, True), (0.0, False)):
        at = fcd.assign(time_s=(fcd["time_s"] - shift).round(3))
        both = traffic.merge(at, on=["time_s", "id"], suffixes=("", "_fcd"))
        both = both[~((both["id"] == "ego") & (both["time_s"] == first))]
        gap = np.hypot(both["fx"] - both["fx_fcd"], both["fy"] - both["fy_fcd"])
        assert set(both["id"]) >= {"ego", "aro", "oncoming", "walker", "parked_0"}
        assert (gap.max() < 1e-3) == close, (shift, gap.max())


def test_animate_writes_a_gif_that_follows_the_ego(run_dir, tmp_path):
    out, frames = animate_run(run_dir, tmp_path / "a.gif", fps=8, size_in=(6.0, 2.4), dpi=60)
    assert frames >= 20
    with Image.open(out) as gif:
        assert gif.n_frames == frames
        first = np.asarray(gif.convert("RGB"))
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB"))
    blue = np.array([int(ROLE_COLOURS["ego"][k : k + 2], 16) for k in (1, 3, 5)])
    for image in (first, last):  # the ego's box is in every frame
        assert (np.abs(image.astype(int) - blue).sum(axis=2) < 40).sum() > 20
    assert not np.array_equal(first, last)


def test_a_png_is_one_still_of_the_frame_asked_for(run_dir, tmp_path, capsys):
    """``--out X.png``: one frame, by default where the ego is farthest from its lane centre;
    ``--at-s``: the frame nearest that time."""
    frames = load_frames(run_dir, 10, picture_aspect((9.0, 3.6)))
    offset = np.abs(frames.series["lateral_offset_m"].to_numpy()[frames.rows])
    widest = still_frame(frames, None)
    assert offset[widest] == np.nanmax(offset)
    assert still_frame(frames, 1.04) == int(np.argmin(np.abs(frames.time_s - 1.04)))
    out = tmp_path / "still.png"
    assert main(["animate", str(run_dir), "--out", str(out), "--at-s", "1.0"]) == 0
    assert capsys.readouterr().out.strip() == f"{out} (1 frames at 10 fps)"
    with Image.open(out) as png:
        assert png.format == "PNG" and getattr(png, "n_frames", 1) == 1


def test_animate_cli_bad_run_dir_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["animate", str(tmp_path / "nowhere")]) == 2
    assert main(["animate", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"eoam-sumo: error: {tmp_path / 'nowhere'}: no such run folder",
        f"eoam-sumo: error: {tmp_path}: not a run folder (no summary.json)",
    ]


def test_animate_refuses_more_frames_than_the_runs_steps(tmp_path, capsys):
    """--fps 1000 wrote a GIF whose frame delays were 0 (viewers then play it at their own
    speed) while saying "1000 fps"."""
    assert main(["animate", str(tmp_path), "--fps", "1000"]) == 2
    assert capsys.readouterr().err.strip() == (
        "eoam-sumo: error: --fps 1000: at most 100 (a frame every 10 ms, the run's step and a "
        "GIF's finest delay)"
    )


# --- on any road: the view follows the ego round a curve and along roads running every way


def _road_run(
    folder: Path, points: list[tuple[float, float]], obstacle_m: float, speed_mps: float, mu: float
) -> Path:
    """A one-lane one-way road through ``points`` (no lane to escape into), a car halted on
    it ``obstacle_m`` from its start, the ego 20 m from the start at ``speed_mps``: the run's
    folder."""
    shape = " ".join(f"{x:.3f},{y:.3f}" for x, y in points)
    (x0, y0), (x1, y1) = points[0], points[-1]
    cfg = halted_car_scenario(
        folder,
        f'<nodes><node id="a" x="{x0:.3f}" y="{y0:.3f}"/>'
        f'<node id="b" x="{x1:.3f}" y="{y1:.3f}"/></nodes>',
        f'<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="40" shape="{shape}"/></edges>',
        obstacle_m,
    )
    run_case(
        cfg,
        ScenarioOverrides(ego_speed_mps=speed_mps, mu=mu),
        folder / "run",
        RunSettings(max_time_s=30.0),
    )
    return folder / "run"


def _left_turn(
    lead_m: float, radius_m: float, turn_deg: float, tail_m: float
) -> list[tuple[float, float]]:
    """A straight ``lead_m`` east, a left arc of ``radius_m`` through ``turn_deg`` (2 m
    chords), then a straight ``tail_m``."""
    turn = math.radians(turn_deg)
    n = math.ceil(radius_m * turn / 2.0)
    points = [(0.0, 0.0)] + [
        (lead_m + radius_m * math.sin(turn * k / n), radius_m * (1 - math.cos(turn * k / n)))
        for k in range(n + 1)
    ]
    x, y = points[-1]
    return [*points, (x + tail_m * math.cos(turn), y + tail_m * math.sin(turn))]


CURVE = {"lead_m": 30.0, "radius_m": 40.0, "turn_deg": 100.0, "tail_m": 300.0}


@pytest.fixture(scope="module")
def curve_run(tmp_path_factory) -> Path:
    """A 40 m radius left turn through 100 deg, 30 m from the road's start; a car halted just
    past it (its tail 0.6 m beyond the curve's end, heading 100 deg); the ego at 12 m/s on
    mu 0.6 sees it too late and hits it."""
    return _road_run(tmp_path_factory.mktemp("curve"), _left_turn(**CURVE), 105.0, 12.0, 0.6)


def _boxes_at(traffic: pd.DataFrame, time_s: float, user: str) -> np.ndarray:
    """(4, 2) corners of ``user``'s box in traffic.csv at ``time_s``, worked out here."""
    row = traffic[(np.abs(traffic["time_s"] - time_s) < 1e-6) & (traffic["id"] == user)]
    assert len(row) == 1, (time_s, user)
    x, y, h, length, width = row[["x_m", "y_m", "heading_rad", "length_m", "width_m"]].to_numpy()[0]
    along, left = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    return np.array(
        [
            [x, y] + a * 0.5 * length * along + b * 0.5 * width * left
            for a, b in ((1, 1), (1, -1), (-1, -1), (-1, 1))
        ]
    )


def _in_view(views, k: int, xy: np.ndarray) -> bool:
    """Whether the points ``xy`` lie inside frame ``k``'s view (rotation matrix worked out
    here)."""
    c, s = math.cos(views.rotation_rad[k]), math.sin(views.rotation_rad[k])
    d = xy - [views.centre_x_m[k], views.centre_y_m[k]]
    u, v = d @ [c, s], d @ [-s, c]
    return bool(
        (np.abs(u) <= views.width_m[k] / 2).all() and (np.abs(v) <= views.height_m[k] / 2).all()
    )


def _check_every_frame(run_dir: Path, fps: int = 10):
    """Every frame's view holds the ego's and the obstacle's boxes of traffic.csv; the last
    frame is the contact's. The frames, the summary and the traffic log."""
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["end_cause"] == "contact" and summary["collision_with_id"] == "stalled"
    frames = load_frames(run_dir, fps, picture_aspect((9.0, 3.6)))
    traffic = read_traffic(run_dir / "traffic.csv")
    for k, t in enumerate(frames.time_s):
        for user in ("ego", "stalled"):
            assert _in_view(frames.views, k, _boxes_at(traffic, t, user)), (k, t, user)
    assert abs(frames.time_s[-1] - summary["contact_time_s"]) <= STEP_S + 1e-9
    assert len(frames.time_s) >= fps * (summary["contact_time_s"] - frames.time_s[0])
    return frames, summary, traffic


def test_round_a_curve_every_frame_shows_the_ego_and_the_obstacle_and_ends_on_the_contact(
    curve_run,
):
    frames, summary, traffic = _check_every_frame(curve_run)
    turn = traffic.loc[traffic["id"] == "ego", "heading_rad"]
    assert turn.max() - turn.min() > math.radians(90.0)  # the road turned the ego round
    obstacle = traffic.loc[traffic["id"] == "stalled", "heading_rad"].iloc[0]
    assert obstacle > math.radians(95.0)
    # the view turned with it: from east to the obstacle's heading
    assert abs(frames.views.rotation_rad[0]) < math.radians(10.0)
    assert abs(frames.views.rotation_rad[-1] - obstacle) < math.radians(10.0)
    # the last frame shows the contact: the ring at the contact point, the obstacle outlined
    scene = Scene(frames, labels=True)
    scene.draw(len(frames.rows) - 1)
    np.testing.assert_allclose(
        np.column_stack(scene.contact.get_data()),
        [[summary["contact_x_m"], summary["contact_y_m"]]],
    )
    assert scene.hit.get_visible()
    np.testing.assert_allclose(
        scene.hit.get_xy()[:4], _boxes_at(traffic, frames.time_s[-1], "stalled"), atol=1e-3
    )
    assert "CONTACT with stalled" in scene.text.get_text()
    scene.draw(len(frames.rows) - 2)  # not before
    assert not scene.hit.get_visible() and len(scene.contact.get_xdata()) == 0


@pytest.mark.parametrize("heading_deg", [90.0, 180.0, -90.0, -135.0])
def test_roads_heading_north_west_south_and_south_west_keep_both_in_view(tmp_path, heading_deg):
    """A straight one-lane road 600 m long heading this way, the car halted 110 m along it
    (within the radar's range of the ego from the start), the ego at 30 m/s on mu 0.3."""
    h = math.radians(heading_deg)
    run = _road_run(
        tmp_path, [(0.0, 0.0), (600.0 * math.cos(h), 600.0 * math.sin(h))], 110.0, 30.0, 0.3
    )
    frames, _, _ = _check_every_frame(run)
    np.testing.assert_allclose(
        np.angle(np.exp(1j * (frames.views.rotation_rad - h))), 0.0, atol=1e-3
    )


def test_labels_write_each_road_users_id_beside_its_box(curve_run):
    frames = load_frames(curve_run, 10, picture_aspect((9.0, 3.6)))
    scene = Scene(frames, labels=True)
    for k in (0, len(frames.rows) - 1):
        scene.draw(k)
        shown = {t.get_text(): t.get_position() for t in scene.labels if t.get_visible()}
        assert set(shown) == {"ego", "stalled"}
        a = frames.user_start[k]
        for j, user in enumerate(frames.user_id[a : frames.user_end[k]]):
            centre = frames.box[a + j].mean(axis=0)
            assert 0.5 < math.dist(shown[user], centre) < 3.0  # beside its own box
    assert Scene(frames).labels == []  # not asked: none


def test_animate_cli_labels_writes_the_gif(curve_run, tmp_path, capsys):
    out = tmp_path / "c.gif"
    assert main(["animate", str(curve_run), "--out", str(out), "--fps", "4", "--labels"]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == int(capsys.readouterr().out.split("(")[1].split()[0])
