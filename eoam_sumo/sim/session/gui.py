"""Watching a run in sumo-gui: real-time pacing, the view following the ego, screenshots.

Under TraCI sumo-gui steps as fast as it is told (its own delay setting does not apply), so
the session paces the steps itself: each takes at least ``delay_ms`` of wall time (the
sumocfg's ``delay`` when not given, else real time: the step length). The view follows the
ego, ``view_width_m`` of road wide, in a 1280 x 800 window unless the sumocfg sets
``window-size``, drawn in the "real world" scheme unless it sets ``gui-settings-file``.

Screenshots: a time T is in seconds after the ego's departure (SUMO's time when the step that
inserts the ego begins), or, in ``screenshots_at_s``, SUMO's own time (as ``time_s`` in
timeseries.csv). Each is the scene at the end of the first step that reaches it (sumo-gui
draws a screenshot asked for before a step once that step is done), named by that scene's
time: ``screenshot_+<s after the departure>s.png``, or ``screenshot_@<SUMO time>s.png`` for an
absolute time. A time before the departure or after the run's end, or a second time on the
same scene, gets a warning on standard error instead of a file. At the end the window stays
open until the user closes it (``keep_open``), which a virtual display (Xvfb) cannot show.
"""

from __future__ import annotations

import math
import os
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError

VIEW_ID = "View #0"  # sumo-gui's first (default) view
SCHEME = "real world"  # sumo-gui's scheme drawing vehicle shapes (default: triangles)
BEHIND_LIMIT_S = 0.5  # pacing forgets a lag longer than this (a slow step is not made up)
TIME_TOL_S = 1e-6  # SUMO counts time in whole milliseconds
_LOCAL_DISPLAY = re.compile(r"(?:unix)?:(\d+)(?:\.\d+)?")


@dataclass(frozen=True)
class GuiSettings:
    """How sumo-gui shows a run (used only with ``gui``)."""

    delay_ms: float | None = None  # wall time per step [ms]; None: real time (step length)
    screenshots_s: tuple[float, ...] = ()  # screenshot times after the ego's departure [s]
    screenshot_dir: Path | None = None  # where they go (required with screenshots)
    view_width_m: float = 150.0  # width of road shown around the ego [m]
    track_ego: bool = True
    keep_open: bool = True  # the window stays until closed; False: it closes with the run
    screenshots_at_s: tuple[float, ...] = ()  # screenshot times in SUMO's time [s]

    def __post_init__(self) -> None:
        if self.delay_ms is not None and not (
            math.isfinite(self.delay_ms) and self.delay_ms >= 0.0
        ):
            raise InputError(f"gui delay {self.delay_ms!r} ms must be a number >= 0")
        for times in (self.screenshots_s, self.screenshots_at_s):
            if any(not (math.isfinite(t) and t >= 0.0) for t in times):
                raise InputError(f"screenshot times {times!r} must be numbers >= 0 s")
        if (self.screenshots_s or self.screenshots_at_s) and self.screenshot_dir is None:
            raise InputError("screenshots need a folder to go to")
        if not (math.isfinite(self.view_width_m) and self.view_width_m > 0.0):
            raise InputError(f"gui view width {self.view_width_m!r} m must be > 0")


def virtual_display(display: str | None = None) -> bool:
    """Whether the local X display ``display`` (default: ``DISPLAY``) is served by Xvfb, whose
    window nobody sees: its lock file ``/tmp/.X<n>-lock`` names the server's process."""
    text = os.environ.get("DISPLAY", "") if display is None else display
    match = _LOCAL_DISPLAY.fullmatch(text.strip())
    if match is None:
        return False
    try:
        pid = int(Path(f"/tmp/.X{match.group(1)}-lock").read_text().strip())
        server = Path(f"/proc/{pid}/comm").read_text().strip()
    except (OSError, ValueError):
        return False
    return server == "Xvfb"


def _seconds_text(t_s: float) -> str:
    """``t_s`` with two decimals, three when it is not a whole number of 10 ms."""
    hundredths = t_s * 100.0
    return f"{t_s:.2f}" if abs(hundredths - round(hundredths)) < 1e-6 else f"{t_s:.3f}"


@dataclass(frozen=True)
class _Shot:
    """A screenshot still to take: due when SUMO's time reaches ``due_s``."""

    due_s: float
    request: str  # as asked: "+1 s" after the departure, "@121 s" in SUMO's time
    absolute: bool


class GuiView:
    """The running side of :class:`GuiSettings` for one session."""

    def __init__(
        self,
        api,
        settings: GuiSettings,
        step_s: float,
        cfg_delay_ms: float | None = None,
        cfg_gui_settings: bool = False,
    ) -> None:
        self._gui, self.settings = api.gui, settings
        self._scheme = None if cfg_gui_settings else SCHEME
        delay_ms = settings.delay_ms if settings.delay_ms is not None else cfg_delay_ms
        self._delay_s = step_s if delay_ms is None else delay_ms / 1000.0
        self._due: list[_Shot] = []
        self._depart_s = 0.0
        self._next_wall: float | None = None
        self._taken: dict[int, Path] = {}  # scene time [ms] -> its file
        self.screenshots: list[Path] = []  # requested so far, in order
        self.scene_times_s: list[float] = []  # SUMO's time each of them shows [s]
        self.warnings: list[str] = []  # the times that gave no file, as told on stderr

    def depart(self, depart_s: float, front_xy: tuple[float, float]) -> None:
        """Before the step that inserts the ego (it begins at ``depart_s``, the ego's front
        bumper placed at ``front_xy``): the screenshots' times fixed, those before the
        departure dropped with a warning, and the view put on the ego's start."""
        self._depart_s = depart_s
        settings = self.settings
        shots = [_Shot(depart_s + t, f"+{t:g} s", False) for t in settings.screenshots_s]
        for t in settings.screenshots_at_s:
            if t < depart_s - TIME_TOL_S:
                self._warn(f"no screenshot at @{t:g} s: the ego departs at {depart_s:g} s")
            else:
                shots.append(_Shot(t, f"@{t:g} s", True))
        self._due = sorted(shots, key=lambda shot: shot.due_s)
        if not settings.track_ego:
            return
        if self._scheme is not None:
            self._gui.setSchema(VIEW_ID, self._scheme)
        self._gui.setOffset(VIEW_ID, *front_xy)  # tracking moves the view only a few draws on
        zoom = self._gui.getZoom(VIEW_ID)
        (x0, _), (x1, _) = self._gui.getBoundary(VIEW_ID)
        if x1 > x0:
            self._gui.setZoom(VIEW_ID, zoom * (x1 - x0) / settings.view_width_m)

    def follow(self, ego_id: str) -> None:
        """Keep the view on the ego from now on (sumo-gui's zoom, set by :meth:`depart`, is
        relative to the network's size: the width shown scales inversely with it)."""
        if self.settings.track_ego:
            self._gui.trackVehicle(VIEW_ID, ego_id)

    def before_step(self, t_next_s: float) -> None:
        """Ask for the screenshots due by the end of the coming step (ending at ``t_next_s``),
        then wait until this step's wall time has come."""
        self.request_screenshots(t_next_s)
        self.pace()

    def request_screenshots(self, t_next_s: float) -> None:
        """Ask sumo-gui for the screenshots due by ``t_next_s``: each is drawn once the coming
        step (ending then) is done; one file per scene."""
        while self._due and self._due[0].due_s <= t_next_s + TIME_TOL_S:
            shot = self._due.pop(0)
            scene_ms = round(t_next_s * 1000.0)
            if scene_ms in self._taken:
                self._warn(
                    f"screenshot at {shot.request} shows the scene of "
                    f"{self._taken[scene_ms].name}: not saved twice"
                )
                continue
            label = (
                f"@{_seconds_text(t_next_s)}"
                if shot.absolute
                else f"+{_seconds_text(t_next_s - self._depart_s)}"
            )
            path = Path(self.settings.screenshot_dir or ".") / f"screenshot_{label}s.png"
            self._gui.screenshot(VIEW_ID, str(path.resolve()))
            self._taken[scene_ms] = path
            self.screenshots.append(path)
            self.scene_times_s.append(t_next_s)

    def pace(self) -> None:
        """Wait until the coming step's wall time has come (``delay_ms`` per step)."""
        if self._delay_s <= 0.0:
            return
        now = time.perf_counter()
        if self._next_wall is None or now - self._next_wall > BEHIND_LIMIT_S:
            self._next_wall = now
        elif self._next_wall > now:
            time.sleep(self._next_wall - now)
        self._next_wall += self._delay_s

    def finish(self, end_s: float) -> None:
        """The run ended at SUMO time ``end_s``: a warning for every screenshot not reached."""
        for shot in self._due:
            self._warn(
                f"no screenshot at {shot.request}: the run ended at {end_s:.2f} s, "
                f"+{end_s - self._depart_s:.2f} s after the ego's departure"
            )
        self._due = []

    def _warn(self, text: str) -> None:
        self.warnings.append(text)
        print(f"eoam-sumo: {text}", file=sys.stderr)
