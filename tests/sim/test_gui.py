"""sumo-gui under the co-simulation: the same run as without it (the handover before the ego
departs included), screenshots timed from the ego's departure and showing the ego and the
obstacle, real-time pacing, the window left open at the end or closed on Xvfb. Needs a
display: DISPLAY, or Xvfb to make one (CI's `.ci/run` installs Debian's xvfb; `make test`
never installs system packages); without either every test here that starts sumo-gui is
SKIPPED (not passed), saying why."""

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

from eoam_sumo.cli import build_parser, main
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.gui import GuiSettings, virtual_display
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.traffic_scenario import write_traffic_scenario
from tests.builders import BASELINE

pytestmark = pytest.mark.sumo

EGO_RGB, ARO_RGB = (0, 128, 255), (255, 64, 64)  # colours of scenarios/vtypes.add.xml
DEPART_S = 120.0  # the traffic scenario's ego departs late, after a handover at 0.1 s steps
XVFB_READY_S = 30.0
ROOT = Path(__file__).resolve().parents[2]


class Display(NamedTuple):
    name: str  # as in DISPLAY
    ours: bool  # a private Xvfb started here


def _free_display() -> int:
    """A display number with neither a lock file nor a socket (from a start varied by pid)."""
    for k in range(400):
        n = 100 + (os.getpid() + k) % 400
        if not any(Path(f).exists() for f in (f"/tmp/.X{n}-lock", f"/tmp/.X11-unix/X{n}")):
            return n
    pytest.skip("no free X display number, so sumo-gui is NOT tested here")


def _start_xvfb(xvfb: str) -> tuple[subprocess.Popen, str] | None:
    """Xvfb on a free display, once its lock file and socket exist (what virtual_display
    and sumo-gui look for); None when it did not start."""
    n = _free_display()
    proc = subprocess.Popen(
        [xvfb, f":{n}", "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + XVFB_READY_S
    while proc.poll() is None and time.monotonic() < deadline:
        if Path(f"/tmp/.X11-unix/X{n}").exists() and Path(f"/tmp/.X{n}-lock").exists():
            return proc, f":{n}"
        time.sleep(0.05)
    proc.kill()
    proc.wait()
    return None


@pytest.fixture(scope="module")
def display():
    """A display for sumo-gui: the one in DISPLAY, else a private Xvfb (ended afterwards)."""
    if os.environ.get("DISPLAY"):
        yield Display(os.environ["DISPLAY"], False)
        return
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip(
            "no display: DISPLAY is not set and Xvfb is not installed, so sumo-gui "
            "is NOT tested here"
        )
    started = _start_xvfb(xvfb)
    if started is None:
        pytest.skip("Xvfb could not start a display, so sumo-gui is NOT tested here")
    proc, name = started
    os.environ["DISPLAY"] = name
    try:
        yield Display(name, True)
    finally:
        os.environ.pop("DISPLAY", None)
        proc.terminate()
        proc.wait(timeout=10)


@pytest.fixture(scope="module")
def late_traffic(tmp_path_factory) -> Path:
    """Heavy traffic at 0.1 s steps before the ego departs at 120 s (a handover)."""
    return write_traffic_scenario(
        tmp_path_factory.mktemp("traffic"), ego_depart_s=DEPART_S, step_length_s=0.1
    )


def _pixels_like(png, rgb) -> int:
    import matplotlib.image

    image = np.round(matplotlib.image.imread(png)[..., :3] * 255.0)
    return int((np.abs(image - np.array(rgb)).sum(axis=-1) < 30).sum())


def test_a_screenshot_mid_manoeuvre_shows_the_ego_and_the_obstacle(display, tmp_path):
    gui = GuiSettings(delay_ms=0.0, screenshots_s=(5.0,), screenshot_dir=tmp_path, keep_open=False)
    summary = run_case(
        BASELINE,
        ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0),
        tmp_path,
        RunSettings(gui=True, use_traci=True, gui_settings=gui),
    )
    assert 2 in summary["modes_visited"]  # the lane change ran (5 s on the ego is beside the ARO)
    png = tmp_path / "screenshot_+5.00s.png"  # the ego departs at 1 s: SUMO's time 6 s
    assert png.is_file()
    assert _pixels_like(png, EGO_RGB) > 100 and _pixels_like(png, ARO_RGB) > 100
    assert summary["sumo_overrides"]["start"] == "true"


# Each step's end colours the ego (setColor before the step is drawn with it): a screenshot
# shows which step's end it is
MARKS = {121.0: (0, 255, 0), 122.0: (255, 0, 255)}
OTHER = (255, 0, 0)


def test_screenshots_are_the_scenes_at_their_times_after_the_departure(
    display, late_traffic, tmp_path, capsys
):
    gui = GuiSettings(
        delay_ms=0.0,
        screenshots_s=(2.0, 1.0, 30.0),  # 30 s: after the end
        screenshots_at_s=(121.0, 50.0),  # the scene of +1 s; before the departure
        screenshot_dir=tmp_path,
        keep_open=False,
    )
    with SumoSession.start(late_traffic, gui=True, gui_settings=gui) as session:
        assert session.ego_depart_time_s == DEPART_S
        while session.time_s < 122.5:
            t_next = round(session.time_s + session.step_length_s, 3)
            session._api.vehicle.setColor(session.ego_id, (*MARKS.get(t_next, OTHER), 255))
            session.step()
        view = session.gui
        assert view is not None
    assert [p.name for p in view.screenshots] == ["screenshot_+1.00s.png", "screenshot_+2.00s.png"]
    assert view.scene_times_s == pytest.approx([121.0, 122.0], abs=1e-9)
    for png, t in zip(view.screenshots, (121.0, 122.0), strict=True):
        assert _pixels_like(png, MARKS[t]) > 100, png.name  # the ego as it was at t
        assert _pixels_like(png, OTHER) == 0, png.name
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [p.name for p in view.screenshots]
    warned = capsys.readouterr().err.splitlines()
    assert len(view.warnings) == 3 and [f"eoam-sumo: {w}" for w in view.warnings] == [
        line for line in warned if "screenshot" in line
    ]
    assert "@50 s: the ego departs at 120 s" in view.warnings[0]
    assert "@121 s shows the scene of screenshot_+1.00s.png" in view.warnings[1]
    assert "+30 s: the run ended at 122.50 s, +2.50 s after the ego's departure" in view.warnings[2]


def _cli_run(cfg: Path, out: Path, *extra: str) -> int:
    return main(["run", str(cfg), "--speed-kmh", "140", "--mu", "0.3", "--out", str(out), *extra])


def test_a_gui_run_is_the_headless_run(display, late_traffic, tmp_path, capsys):
    """Before the ego departs sumo-gui runs at the sumocfg's 0.1 s step too: the same traffic
    at the departure, so the same outcome, impact speed and time series."""
    assert _cli_run(late_traffic, tmp_path / "headless") == 0
    gui_options = ["--gui", "--gui-delay-ms", "0", "--gui-screenshot", "1,2,99"]
    if not display.ours:  # a display someone may watch: the window would stay open
        gui_options.append("--gui-close")
    assert _cli_run(late_traffic, tmp_path / "gui", *gui_options) == 0
    err = capsys.readouterr().err
    headless, gui = (
        json.loads((tmp_path / d / "summary.json").read_text()) for d in ("headless", "gui")
    )
    assert gui["outcome"] == headless["outcome"] == "yellow"  # it hits the broken-down car
    assert gui["impact_speed_mps"] == headless["impact_speed_mps"] > 10.0
    for name in ("timeseries.csv", "traffic.csv"):
        assert (tmp_path / "gui" / name).read_bytes() == (tmp_path / "headless" / name).read_bytes()
    one, two = (tmp_path / "gui" / f"screenshot_+{t}.00s.png" for t in (1, 2))
    assert one.read_bytes() != two.read_bytes()  # two scenes, not one twice
    assert sorted(p.name for p in (tmp_path / "gui").glob("*.png")) == [one.name, two.name]
    assert "eoam-sumo: no screenshot at +99 s: the run ended at 12" in err
    if display.ours:  # Xvfb: the window closed with the run
        assert "stays open" not in err


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="xvfb-run is not installed")
def test_under_xvfb_run_the_window_closes_without_x_errors(display, tmp_path):
    """``xvfb-run eoam-sumo run --gui`` ends its Xvfb after the run: a window left open would
    die then with "X Fatal error." on the terminal."""
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    cmd = [sys.executable, "-m", "eoam_sumo", "run", str(BASELINE), "--gui", "--gui-delay-ms", "0"]
    proc = subprocess.run(
        ["xvfb-run", "-a", *cmd, "--out", str(tmp_path)],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "X Fatal error" not in proc.stderr and "stays open" not in proc.stderr


def test_the_run_is_paced_and_the_window_stays_open(display, late_traffic):
    """After a handover too (sumo-gui's options are those it was restarted with)."""
    s = SumoSession.start(late_traffic, gui=True, gui_settings=GuiSettings(delay_ms=20.0))
    process = s._process
    try:
        s.step()
        wall0 = time.perf_counter()
        for _ in range(50):
            s.step()
        assert time.perf_counter() - wall0 >= 50 * 0.020 - 0.025
        s.close()
        time.sleep(1.0)
        assert process.poll() is None  # the window is the user's to close
    finally:
        s.close()
        process.terminate()
        process.wait(timeout=10)


def test_a_virtual_display_is_told_from_others(display):
    assert virtual_display(display.name) == virtual_display()  # DISPLAY is the fixture's
    if display.ours:
        assert virtual_display(display.name) and virtual_display(f"unix{display.name}.0")
    assert not virtual_display("otherhost:0")  # remote
    assert not virtual_display(":4242")  # no server there


def test_screenshot_times_parse_relative_and_absolute():
    args = build_parser().parse_args(
        ["run", "x.sumocfg", "--gui", "--gui-screenshot", "1, @121,0.5"]
    )
    assert args.gui_screenshot == ((1.0, False), (121.0, True), (0.5, False))
