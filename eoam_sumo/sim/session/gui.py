"""Watching a run in sumo-gui: real-time pacing, the view following the ego, screenshots.

Under TraCI sumo-gui steps as fast as it is told (its own delay setting does not apply), so
the session paces the steps itself: each takes at least ``delay_ms`` of wall time (the
sumocfg's ``delay`` when not given, else real time: the step length). The view follows the
ego, ``view_width_m`` of road wide, in a 1280 x 800 window unless the sumocfg sets
``window-size``, drawn in the "real world" scheme unless it sets ``gui-settings-file``.
A screenshot requested for simulation time T (SUMO's time, as ``time_s`` in timeseries.csv)
is taken by sumo-gui after the step that reaches T, into
``screenshot_dir/screenshot_<T>s.png``. At the end the window stays open until the user
closes it (``keep_open``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError

VIEW_ID = "View #0"  # sumo-gui's first (default) view
SCHEME = "real world"  # sumo-gui's scheme drawing vehicle shapes (default: triangles)
BEHIND_LIMIT_S = 0.5  # pacing forgets a lag longer than this (a slow step is not made up)


@dataclass(frozen=True)
class GuiSettings:
    """How sumo-gui shows a run (used only with ``gui``)."""

    delay_ms: float | None = None  # wall time per step [ms]; None: real time (step length)
    screenshots_s: tuple[float, ...] = ()  # simulation times of screenshots [s]
    screenshot_dir: Path | None = None  # where they go (required with screenshots)
    view_width_m: float = 150.0  # width of road shown around the ego [m]
    track_ego: bool = True
    keep_open: bool = True  # the window stays until closed; False: it closes with the run

    def __post_init__(self) -> None:
        if self.delay_ms is not None and not (
            math.isfinite(self.delay_ms) and self.delay_ms >= 0.0
        ):
            raise InputError(f"gui delay {self.delay_ms!r} ms must be a number >= 0")
        if any(not (math.isfinite(t) and t >= 0.0) for t in self.screenshots_s):
            raise InputError(f"screenshot times {self.screenshots_s!r} must be numbers >= 0 s")
        if self.screenshots_s and self.screenshot_dir is None:
            raise InputError("screenshots need a folder to go to")
        if not (math.isfinite(self.view_width_m) and self.view_width_m > 0.0):
            raise InputError(f"gui view width {self.view_width_m!r} m must be > 0")


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
        self._due = sorted(settings.screenshots_s)
        self._next_wall: float | None = None
        self.screenshots: list[Path] = []  # requested so far, in order

    def follow(self, ego_id: str) -> None:
        """Centre the view on the ego, zoomed to ``view_width_m`` (sumo-gui's zoom is relative
        to the network's size: the width shown scales inversely with it)."""
        if not self.settings.track_ego:
            return
        if self._scheme is not None:
            self._gui.setSchema(VIEW_ID, self._scheme)
        self._gui.trackVehicle(VIEW_ID, ego_id)
        zoom = self._gui.getZoom(VIEW_ID)
        (x0, _), (x1, _) = self._gui.getBoundary(VIEW_ID)
        if x1 > x0:
            self._gui.setZoom(VIEW_ID, zoom * (x1 - x0) / self.settings.view_width_m)

    def before_step(self, t_next_s: float) -> None:
        """Ask for the screenshots due by the end of the coming step (ending at ``t_next_s``),
        then wait until this step's wall time has come."""
        while self._due and self._due[0] <= t_next_s + 1e-9:
            t = self._due.pop(0)
            path = Path(self.settings.screenshot_dir or ".") / f"screenshot_{t:.2f}s.png"
            self._gui.screenshot(VIEW_ID, str(path.resolve()))
            self.screenshots.append(path)
        if self._delay_s <= 0.0:
            return
        now = time.perf_counter()
        if self._next_wall is None or now - self._next_wall > BEHIND_LIMIT_S:
            self._next_wall = now
        elif self._next_wall > now:
            time.sleep(self._next_wall - now)
        self._next_wall += self._delay_s
