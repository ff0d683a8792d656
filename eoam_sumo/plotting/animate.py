"""``eoam-sumo animate RUN_DIR``: an animated bird's-eye view of a run, following the ego.

Drawn per frame from the run folder: the road and its lane markings from the network named
in summary.json (``net_file``), every road user of traffic.csv as its footprint box coloured
by role (a road user keeps the colour of the most telling role it had: aro, oncoming,
parked, other), the ego's radar cone (``radar_range_m``, ``radar_fov_deg``), the planned
path (the lateral target ``y_target_m`` of the next ``PLAN_AHEAD_S`` as logged, placed in
the road frame), the ego's track so far, and as text the time, EOAM mode, speed, DMM sector
and FCW; from the contact on, the contact point is marked. Frames are taken every 1/fps
seconds of simulated time and played at fps, so the film runs in real time.

GIF through matplotlib's PillowWriter; MP4 through FFMpegWriter when ffmpeg is on PATH and
the file name ends in .mp4.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
from matplotlib.animation import FFMpegWriter, PillowWriter
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon

from eoam_sumo.errors import InputError
from eoam_sumo.plotting.roadmap import read_road_map
from eoam_sumo.plotting.run_plots import MODE_NAMES, load_run
from eoam_sumo.sim.trafficlog import TRAFFIC_FILE, read_traffic

ROLE_COLOURS = {
    "ego": "#1e88e5",
    "aro": "#e53935",
    "oncoming": "#fb8c00",
    "parked": "#757575",
    "other": "#43a047",
}
_ROLE_RANK = {"ego": 0, "aro": 1, "oncoming": 2, "parked": 3, "other": 4}
PLAN_AHEAD_S = 3.0  # the planned path drawn this far ahead of the frame's time [s]
VIEW_BEHIND_M, VIEW_AHEAD_M = 40.0, 110.0  # view along the ego's heading [m]
MIN_DRAWN_M = 1.0  # road users are drawn at least this long and wide [m]
DEFAULT_FPS = 10
DEFAULT_RADAR_FOV_DEG = 18.0


def _boxes(x, y, yaw, length, width) -> np.ndarray:
    """(n, 4, 2) corners of footprint rectangles centred at (x, y)."""
    c, s = np.cos(yaw), np.sin(yaw)
    hl, hw = 0.5 * length, 0.5 * width
    corners = []
    for fl, fw in ((1, 1), (1, -1), (-1, -1), (-1, 1)):
        corners.append(
            np.column_stack((x + fl * hl * c - fw * hw * s, y + fl * hl * s + fw * hw * c))
        )
    return np.stack(corners, axis=1)


def _frame_rows(times: np.ndarray, fps: float) -> np.ndarray:
    """Indices of the time-series rows shown as frames: one every 1/fps s of run time."""
    wanted = np.arange(times[0], times[-1] + 1e-9, 1.0 / fps)
    return np.unique(np.clip(np.searchsorted(times, wanted - 1e-9), 0, len(times) - 1))


def animate_run(
    run_dir: Path,
    out: Path | None = None,
    fps: int = DEFAULT_FPS,
    size_in: tuple[float, float] = (9.0, 3.6),
    dpi: int = 90,
) -> tuple[Path, int]:
    """Write the animation of ``run_dir``; (its path, the number of frames)."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: no such run folder")
    if not (run_dir / "summary.json").is_file():
        raise InputError(f"{run_dir}: not a run folder (no summary.json)")
    if fps < 1:
        raise InputError(f"--fps {fps} must be a whole number >= 1")
    summary, ts = load_run(run_dir)
    traffic_path = run_dir / TRAFFIC_FILE
    if not traffic_path.is_file():
        raise InputError(
            f"{run_dir}: has no {TRAFFIC_FILE} (a run of an older eoam-sumo; run it again)"
        )
    traffic = read_traffic(traffic_path)
    out = Path(out) if out is not None else run_dir / "animation.gif"
    mp4 = out.suffix.lower() == ".mp4"
    if mp4 and shutil.which("ffmpeg") is None:
        raise InputError(f"{out}: an MP4 needs ffmpeg on PATH; name a .gif instead")
    if not mp4 and out.suffix.lower() != ".gif":
        raise InputError(f"{out}: the animation's file name must end in .gif or .mp4")
    scene = _Scene(summary, ts, traffic, size_in, dpi)
    frames = _frame_rows(ts["time_s"].to_numpy(), fps)
    writer = FFMpegWriter(fps=fps) if mp4 else PillowWriter(fps=fps)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with writer.saving(scene.fig, str(out), dpi):
            for row in frames:
                scene.draw(int(row))
                writer.grab_frame()
    except OSError as exc:
        raise InputError(f"{out}: cannot be written: {exc.strerror or exc}") from exc
    return out, len(frames)


class _Scene:
    """The figure's artists, made once and updated per frame."""

    def __init__(self, summary: dict, ts, traffic, size_in, dpi):
        self.summary = summary
        self._read_series(ts)
        self._traffic_index(traffic)
        self.radar_m = float(summary.get("radar_range_m") or 100.0)
        self.fov_rad = math.radians(float(summary.get("radar_fov_deg") or DEFAULT_RADAR_FOV_DEG))
        self.contact_t = summary.get("contact_time_s")
        self.fig = Figure(figsize=size_in, dpi=dpi)
        # fixed margins (no layout engine run for every frame) and no ticks: the
        # view moves, its scale is in the status line
        self.ax = ax = self.fig.add_axes((0.01, 0.01, 0.98, 0.90))
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_aspect("equal", adjustable="box")
        self.view_ratio = 0.90 * size_in[1] / (0.98 * size_in[0])  # view height / width
        ax.set_facecolor("#a5d6a7")  # verges
        self._draw_road(summary)
        self._add_moving_artists(ax)
        self._static_overlay(size_in, dpi)

    def _read_series(self, ts) -> None:
        """The time series the frames show: the ego's pose and speed, its planned path, the
        EOAM's mode, FCW and sector."""
        self.t = ts["time_s"].to_numpy()
        self.x, self.y = ts["x_m"].to_numpy(), ts["y_m"].to_numpy()
        self.yaw = ts["yaw_rad"].to_numpy()
        road_yaw = self.road_yaw = self.yaw - ts["heading_error_rad"].to_numpy()
        # the planned path: the target offset placed beside the ego's station
        shift = ts["y_target_m"].to_numpy() - ts["lateral_offset_m"].to_numpy()
        self.plan_x = self.x - shift * np.sin(road_yaw)
        self.plan_y = self.y + shift * np.cos(road_yaw)
        self.mode = ts["mode"].to_numpy(dtype=float)
        self.in_manoeuvre = np.isfinite(self.mode) & (self.mode != 0)
        self.vx = ts["vx_mps"].to_numpy()
        self.fcw = ts["fcw"].to_numpy(dtype=float)
        self.sector = ts["sector"].fillna("").astype(str).to_list()

    def _add_moving_artists(self, ax) -> None:
        """The artists each frame updates: radar cone, track, planned path, road users'
        boxes, the contact mark and the status text."""
        self.cone = Polygon(
            np.zeros((3, 2)),
            closed=True,
            facecolor="#ffee58",
            alpha=0.25,
            edgecolor="#f9a825",
            linewidth=0.6,
            zorder=2,
        )
        ax.add_patch(self.cone)
        (self.track,) = ax.plot([], [], color="#1e88e5", linewidth=0.8, alpha=0.6, zorder=3)
        (self.plan,) = ax.plot([], [], color="black", linestyle="--", linewidth=1.0, zorder=3)
        self.bodies = PolyCollection([], edgecolors="black", linewidths=0.5, zorder=4)
        ax.add_collection(self.bodies)
        (self.contact,) = ax.plot(
            [],
            [],
            marker="o",
            markersize=18,
            markerfacecolor="none",
            markeredgecolor="#d50000",
            markeredgewidth=2.0,
            linestyle="",
            zorder=5,
        )
        self.text = ax.text(
            0.01,
            0.97,
            "",
            transform=ax.transAxes,
            va="top",
            fontsize=8,
            family="monospace",
            zorder=6,
            bbox={"facecolor": "white", "alpha": 0.85, "linewidth": 0},
        )

    def _static_overlay(self, size_in, dpi) -> None:
        """Title and legend drawn once onto a transparent image laid over every frame (their
        text would otherwise be laid out again for each frame)."""
        over = Figure(figsize=size_in, dpi=dpi)
        over.patch.set_alpha(0.0)
        handles: list[Artist] = [
            Patch(facecolor=ROLE_COLOURS[r], edgecolor="black", label=r)
            for r in ROLE_COLOURS
            if r in self.roles_present
        ]
        handles.append(Line2D([], [], color="black", linestyle="--", label="planned path"))
        over.legend(
            handles=handles,
            loc="lower right",
            bbox_to_anchor=(0.985, 0.02),
            fontsize=7,
            ncols=3,
            framealpha=0.85,
        )
        over.suptitle(self._title(self.summary), fontsize=8, y=0.985)
        canvas = FigureCanvasAgg(over)
        canvas.draw()
        self.fig.figimage(np.asarray(canvas.buffer_rgba()), origin="upper", zorder=10)

    def _title(self, s: dict) -> str:
        hit = s.get("collision_with", "none")
        end = f"{s['outcome']}" + (f", hit {hit}" if hit not in (None, "none") else "")
        return f"{s.get('reason', '')} ({end})"

    def _traffic_index(self, traffic) -> None:
        """Per time-series row: the slice of traffic rows logged at the same time."""
        traffic = traffic.sort_values("time_s", kind="stable")
        times = traffic["time_s"].to_numpy()
        self.tr_start = np.searchsorted(times, self.t - 5e-7)
        self.tr_end = np.searchsorted(times, self.t + 5e-7)
        rank = traffic["role"].map(_ROLE_RANK).fillna(4)
        best = rank.groupby(traffic["id"]).transform("min").astype(int)
        by_rank = {v: k for k, v in _ROLE_RANK.items()}
        self.tr_colour = np.array([ROLE_COLOURS[by_rank[r]] for r in best])
        self.roles_present = {by_rank[r] for r in set(best)}
        x, y, heading, length, width = (
            traffic[c].to_numpy() for c in ("x_m", "y_m", "heading_rad", "length_m", "width_m")
        )
        # a person (0.2 x 0.5 m) would be a pixel or two: small road users drawn larger
        self.tr_boxes = _boxes(
            x, y, heading, np.maximum(length, MIN_DRAWN_M), np.maximum(width, MIN_DRAWN_M)
        )
        self.tr_is_ego = (traffic["role"] == "ego").to_numpy()
        self.tr_xy = traffic[["x_m", "y_m"]].to_numpy()
        ego = traffic[self.tr_is_ego]
        self.ego_front_m = float(ego["length_m"].iloc[0]) * 0.5 if len(ego) else 0.0
        # per time-series row: the ego's box centre (its CG when traffic.csv lacks the row)
        rows = np.searchsorted(ego["time_s"].to_numpy(), self.t - 5e-7).clip(0, len(ego) - 1)
        found = len(ego) > 0 and np.abs(ego["time_s"].to_numpy()[rows] - self.t) < 5e-7
        self.ego_cx = np.where(found, ego["x_m"].to_numpy()[rows] if len(ego) else 0, self.x)
        self.ego_cy = np.where(found, ego["y_m"].to_numpy()[rows] if len(ego) else 0, self.y)

    def _draw_road(self, summary: dict) -> None:
        net = summary.get("net_file")
        pad = VIEW_AHEAD_M + 50.0
        bbox = (self.x.min() - pad, self.y.min() - pad, self.x.max() + pad, self.y.max() + pad)
        if not net or not Path(net).is_file():
            self.ax.text(
                0.5,
                0.5,
                f"road not drawn: network {net or '(not recorded)'} not found",
                transform=self.ax.transAxes,
                ha="center",
                fontsize=8,
            )
            return
        road = read_road_map(Path(net), bbox)
        self.ax.add_collection(
            PolyCollection(road.road, facecolors="#616161", edgecolors="none", zorder=1)
        )
        self.ax.add_collection(
            PolyCollection(road.pavement, facecolors="#bdbdbd", edgecolors="none", zorder=1)
        )
        self.ax.add_collection(
            LineCollection(road.solid, colors="white", linewidths=1.0, zorder=1.5)
        )
        self.ax.add_collection(
            LineCollection(
                road.dashed, colors="white", linewidths=0.8, linestyles=(0, (4, 6)), zorder=1.5
            )
        )

    def draw(self, k: int) -> None:
        """Update the artists to time-series row ``k``."""
        x, y, yaw = self.x[k], self.y[k], self.yaw[k]
        c, s = math.cos(yaw), math.sin(yaw)
        a, b = self.tr_start[k], self.tr_end[k]
        self.bodies.set_verts(list(self.tr_boxes[a:b]))
        self.bodies.set_facecolor(self.tr_colour[a:b].tolist())
        fx = self.ego_cx[k] + self.ego_front_m * c
        fy = self.ego_cy[k] + self.ego_front_m * s
        r, h = self.radar_m, 0.5 * self.fov_rad
        self.cone.set_xy(
            [
                (fx, fy),
                (fx + r * math.cos(yaw + h), fy + r * math.sin(yaw + h)),
                (fx + r * math.cos(yaw - h), fy + r * math.sin(yaw - h)),
            ]
        )
        self.track.set_data(self.x[: k + 1], self.y[: k + 1])
        end = int(np.searchsorted(self.t, self.t[k] + PLAN_AHEAD_S))
        phase = self.in_manoeuvre[k:end]  # ahead as long as the phase (manoeuvre or not) lasts
        n = int(np.argmin(phase == phase[0])) if not phase.all() and phase.any() else len(phase)
        self.plan.set_data(self.plan_x[k : k + n], self.plan_y[k : k + n])
        if self.contact_t is not None and self.t[k] >= self.contact_t - 1e-9:
            self.contact.set_data(*self._contact_point(self.contact_t))
        else:
            self.contact.set_data([], [])
        mid = 0.5 * (VIEW_AHEAD_M - VIEW_BEHIND_M)  # the view looks ahead along the road
        road_yaw = self.road_yaw[k] if np.isfinite(self.road_yaw[k]) else yaw
        cx, cy = x + mid * math.cos(road_yaw), y + mid * math.sin(road_yaw)
        half = 0.5 * (VIEW_AHEAD_M + VIEW_BEHIND_M)
        self.ax.set_xlim(cx - half, cx + half)
        self.ax.set_ylim(cy - half * self.view_ratio, cy + half * self.view_ratio)
        self.text.set_text(self._status(k))

    def _status(self, k: int) -> str:
        mode = self.mode[k]
        name = MODE_NAMES.get(int(mode), "?") if np.isfinite(mode) else "end"
        sector = self.sector[k] or "-"
        fcw = "  FCW" if np.isfinite(self.fcw[k]) and self.fcw[k] > 0 else ""
        return (
            f"t = {self.t[k]:6.2f} s   mode {name}   {3.6 * self.vx[k]:5.1f} km/h   "
            f"DMM sector {sector}{fcw}\nview {VIEW_BEHIND_M + VIEW_AHEAD_M:g} m wide"
        )

    def _contact_point(self, contact_t: float) -> tuple[list, list]:
        """The contact point of summary.json, else (a run of an older eoam-sumo) the midpoint
        between the ego and the road user nearest to it when the contact was found
        (``contact_t``)."""
        x, y = self.summary.get("contact_x_m"), self.summary.get("contact_y_m")
        if x is not None and y is not None:
            return [x], [y]
        k = min(int(np.searchsorted(self.t, contact_t - 1e-9)), len(self.t) - 1)
        a, b = self.tr_start[k], self.tr_end[k]
        xy, ego = self.tr_xy[a:b], self.tr_is_ego[a:b]
        if ego.sum() != 1 or len(xy) < 2:
            return [self.x[k]], [self.y[k]]
        e = xy[ego][0]
        others = xy[~ego]
        near = others[np.argmin(np.hypot(*(others - e).T))]
        return [0.5 * (e[0] + near[0])], [0.5 * (e[1] + near[1])]


def animate_cli(run_dir: Path, out: Path | None, fps: int) -> str:
    """The line ``eoam-sumo animate`` prints."""
    path, n = animate_run(run_dir, out, fps)
    return f"{path} ({n} frames at {fps} fps)"
