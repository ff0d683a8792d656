"""sumo-gui under the co-simulation: screenshots that show the ego and the obstacle, real-time
pacing, the window left open at the end. Needs a display: DISPLAY, or Xvfb to make one; without
either every test here is SKIPPED (not passed): sumo-gui was not tested."""

import os
import shutil
import subprocess
import time

import numpy as np
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.gui import GuiSettings
from eoam_sumo.sim.settings import RunSettings
from tests.builders import BASELINE

pytestmark = pytest.mark.sumo

EGO_RGB, ARO_RGB = (0, 128, 255), (255, 64, 64)  # colours of scenarios/vtypes.add.xml


@pytest.fixture(scope="module")
def display():
    """A display for sumo-gui: the one in DISPLAY, else a private Xvfb (ended afterwards)."""
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip(
            "no display: DISPLAY is not set and Xvfb is not installed, so sumo-gui "
            "is NOT tested here"
        )
    name = f":{100 + os.getpid() % 800}"
    proc = subprocess.Popen(
        [xvfb, name, "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1.0)
    if proc.poll() is not None:
        pytest.skip(f"Xvfb could not start display {name}, so sumo-gui is NOT tested here")
    os.environ["DISPLAY"] = name
    yield name
    del os.environ["DISPLAY"]
    proc.terminate()
    proc.wait(timeout=10)


def _pixels_like(png, rgb) -> int:
    import matplotlib.image

    image = np.round(matplotlib.image.imread(png)[..., :3] * 255.0)
    return int((np.abs(image - np.array(rgb)).sum(axis=-1) < 30).sum())


def test_a_screenshot_mid_manoeuvre_shows_the_ego_and_the_obstacle(display, tmp_path):
    gui = GuiSettings(delay_ms=0.0, screenshots_s=(6.0,), screenshot_dir=tmp_path, keep_open=False)
    summary = run_case(
        BASELINE,
        ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0),
        tmp_path,
        RunSettings(gui=True, use_traci=True, gui_settings=gui),
    )
    assert 2 in summary["modes_visited"]  # the lane change ran (at 6 s the ego is beside the ARO)
    png = tmp_path / "screenshot_6.00s.png"
    assert png.is_file()
    assert _pixels_like(png, EGO_RGB) > 100 and _pixels_like(png, ARO_RGB) > 100
    assert summary["sumo_overrides"]["start"] == "true"


def test_the_run_is_paced_and_the_window_stays_open(display, tmp_path):
    s = SumoSession.start(
        BASELINE, ScenarioOverrides(), gui=True, gui_settings=GuiSettings(delay_ms=20.0)
    )
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
