"""``eoam-sumo animate RUN_DIR``: an animated bird's-eye view of a run, following the ego.

Drawn per frame from the run folder: the road and its lane markings from the network named
in summary.json (``net_file``), every road user of traffic.csv as its footprint box coloured
by role (a road user keeps the colour of the most telling role it had: aro, oncoming,
parked, other), with its id beside it when asked (``labels``), the ego's radar cone
(``radar_range_m``, ``radar_fov_deg``), the planned path (the lateral target ``y_target_m``
of the next ``PLAN_AHEAD_S`` as logged, placed in the road frame), the ego's track so far,
and above the picture the time, EOAM mode, speed, DMM sector and FCW. The view turns with
the road and keeps the ego, its radar cone and every road user within the radar's range in
the picture (``plotting/view.py``); an arrow shows north. A run that ended in a contact ends
on the frame of the contact: the contact point ringed, the road user hit outlined in red.
Frames are taken every 1/fps seconds of simulated time and played at fps, so the film runs
in real time (``plotting/animation_frames.py``).

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
from matplotlib.text import Text
from matplotlib.transforms import Affine2D

from eoam_sumo.errors import InputError
from eoam_sumo.plotting.animation_frames import ROLE_RANK, RunFrames, load_frames
from eoam_sumo.plotting.figures import save
from eoam_sumo.plotting.roadmap import read_road_map
from eoam_sumo.plotting.run_plots import MODE_NAMES
from eoam_sumo.plotting.runfacts import fit
from eoam_sumo.plotting.view import radar_cone

ROLE_COLOURS = {
    "ego": "#1e88e5",
    "aro": "#e53935",
    "oncoming": "#fb8c00",
    "parked": "#757575",
    "other": "#43a047",
}
CONTACT_COLOUR = "#d50000"
TITLE_FONTSIZE = 8.0  # the run's reason and outcome above the picture, wrapped to its width
PLAN_AHEAD_S = 3.0  # the planned path drawn this far ahead of the frame's time [s]
DEFAULT_FPS = 10
AXES_BOX = (0.01, 0.09, 0.98, 0.76)  # the picture within the figure (left, bottom, w, h)
LABEL_GAP_M = 0.5  # an id is written this far beside its road user's box [m]
NORTH_PT = 16.0  # length of the north arrow [points]
NORTH_AT = (0.965, 0.82)  # the north arrow's middle in the picture (axes fractions)


def picture_aspect(size_in: tuple[float, float]) -> float:
    """Height / width of the picture in a figure of ``size_in`` inches."""
    return AXES_BOX[3] * size_in[1] / (AXES_BOX[2] * size_in[0])


def _check_out(out: Path) -> bool:
    """Whether ``out`` is an MP4 (else a GIF); InputError for any other name."""
    mp4 = out.suffix.lower() == ".mp4"
    if mp4 and shutil.which("ffmpeg") is None:
        raise InputError(f"{out}: an MP4 needs ffmpeg on PATH; name a .gif instead")
    if not mp4 and out.suffix.lower() not in (".gif", ".png"):
        raise InputError(f"{out}: the animation's file name must end in .gif, .mp4 or .png")
    return mp4


def still_frame(frames: RunFrames, at_s: float | None) -> int:
    """The frame of a still: the one nearest ``time_s`` = ``at_s``, or (None) the one with
    the ego farthest from its lane's centre (the evasion at its widest)."""
    if at_s is not None:
        return int(np.argmin(np.abs(frames.time_s - at_s)))
    offset = frames.series["lateral_offset_m"].to_numpy()[frames.rows]
    return int(np.nanargmax(np.abs(offset))) if np.isfinite(offset).any() else 0


def animate_run(
    run_dir: Path,
    out: Path | None = None,
    fps: int = DEFAULT_FPS,
    size_in: tuple[float, float] = (9.0, 3.6),
    dpi: int = 90,
    labels: bool = False,
    at_s: float | None = None,
) -> tuple[Path, int]:
    """Write the animation of ``run_dir`` (a ``.png`` ``out``: one still,
    :func:`still_frame`); (its path, the number of frames)."""
    frames = load_frames(Path(run_dir), fps, picture_aspect(size_in))
    out = Path(out) if out is not None else Path(run_dir) / "animation.gif"
    mp4 = _check_out(out)
    scene = Scene(frames, size_in, dpi, labels)
    if out.suffix.lower() == ".png":
        scene.draw(still_frame(frames, at_s))
        try:
            return save(scene.fig, out, dpi), 1
        except OSError as exc:
            raise InputError(f"{out}: cannot be written: {exc.strerror or exc}") from exc
    writer = FFMpegWriter(fps=fps) if mp4 else PillowWriter(fps=fps)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with writer.saving(scene.fig, str(out), dpi):
            for k in range(len(frames.rows)):
                scene.draw(k)
                writer.grab_frame()
    except OSError as exc:
        raise InputError(f"{out}: cannot be written: {exc.strerror or exc}") from exc
    return out, len(frames.rows)


class Scene:
    """The figure's artists, made once and updated per frame. Every artist in network
    coordinates is drawn through ``to_view`` (the frame's turn about its centre) and the
    axes' own transform; the axes' limits are the view's half width and height."""

    def __init__(self, frames: RunFrames, size_in=(9.0, 3.6), dpi: int = 90, labels=False):
        self.frames = frames
        self.summary = frames.summary
        self._read_series(frames.series)
        by_rank = {v: k for k, v in ROLE_RANK.items()}
        self.colour = np.array([ROLE_COLOURS[by_rank[r]] for r in frames.rank])
        self.roles_present = {by_rank[r] for r in set(frames.rank.tolist())}
        self.fig = Figure(figsize=size_in, dpi=dpi)
        # fixed margins (no layout engine run for every frame) and no ticks: the view
        # moves and turns, its scale is in the status line
        self.ax = ax = self.fig.add_axes(AXES_BOX)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_aspect("equal", adjustable="box")
        ax.set_facecolor("#a5d6a7")  # verges
        self.to_view = Affine2D()
        self.data = self.to_view + ax.transData
        self._draw_road()
        self._add_moving_artists(ax)
        self._add_contact_artists(ax)
        self.labels = self._add_labels(ax) if labels else []
        self._add_north_arrow(ax)
        self._static_overlay(size_in, dpi)

    def _read_series(self, ts) -> None:
        """The time series the frames show: the ego's track and speed, its planned path, the
        EOAM's mode, FCW and sector."""
        self.t = ts["time_s"].to_numpy()
        self.x, self.y = ts["x_m"].to_numpy(), ts["y_m"].to_numpy()
        road_yaw = ts["yaw_rad"].to_numpy() - ts["heading_error_rad"].to_numpy()
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
        boxes and the status text above the picture."""
        self.cone = Polygon(
            np.zeros((4, 2)),
            closed=True,
            facecolor="#ffee58",
            alpha=0.25,
            edgecolor="#f9a825",
            linewidth=0.6,
            zorder=2,
            transform=self.data,
        )
        ax.add_patch(self.cone)
        line = {"transform": self.data, "zorder": 3}
        (self.track,) = ax.plot([], [], color="#1e88e5", linewidth=0.8, alpha=0.6, **line)
        (self.plan,) = ax.plot([], [], color="black", linestyle="--", linewidth=1.0, **line)
        self.bodies = PolyCollection(
            [], edgecolors="black", linewidths=0.5, zorder=4, transform=self.data
        )
        ax.add_collection(self.bodies, autolim=False)
        self.text = self.fig.text(
            AXES_BOX[0], AXES_BOX[1] + AXES_BOX[3] + 0.01, "", va="bottom", fontsize=8
        )
        self.text.set_fontfamily("monospace")

    def _add_contact_artists(self, ax) -> None:
        """The contact ring and the outline of the road user hit, shown on the contact's
        frame."""
        (self.contact,) = ax.plot(
            [],
            [],
            marker="o",
            markersize=18,
            markerfacecolor="none",
            markeredgecolor=CONTACT_COLOUR,
            markeredgewidth=2.0,
            linestyle="",
            zorder=6,
            transform=self.data,
        )
        self.hit = Polygon(
            np.zeros((4, 2)),
            closed=True,
            fill=False,
            edgecolor=CONTACT_COLOUR,
            linewidth=2.2,
            zorder=5,
            transform=self.data,
            visible=False,
        )
        ax.add_patch(self.hit)

    def _add_labels(self, ax) -> list[Text]:
        """Enough id texts for the busiest frame, hidden until used."""
        most = int(np.max(self.frames.user_end - self.frames.user_start, initial=0))
        style = {"fontsize": 6, "ha": "center", "va": "center", "clip_on": True, "zorder": 7}
        return [
            ax.text(0.0, 0.0, "", transform=self.data, visible=False, **style) for _ in range(most)
        ]

    def _add_north_arrow(self, ax) -> None:
        """An arrow pointing north and an N at its tip, in the picture's top right corner."""
        self.north = ax.annotate(
            "",
            xy=NORTH_AT,
            xytext=NORTH_AT,
            xycoords="axes fraction",
            arrowprops={"arrowstyle": "->", "color": "black", "linewidth": 1.0},
            zorder=8,
        )
        self.north_n = ax.text(
            *NORTH_AT, "N", transform=ax.transAxes, ha="center", va="center", fontsize=7
        )
        width_in, height_in = self.fig.get_size_inches()
        # an arrow NORTH_PT long in axes fractions, across and up
        self.north_scale = (
            NORTH_PT / (72.0 * AXES_BOX[2] * width_in),
            NORTH_PT / (72.0 * AXES_BOX[3] * height_in),
        )

    def _point_north(self, rotation_rad: float) -> None:
        """The north arrow for a view turned by ``rotation_rad``."""
        north = 0.5 * math.pi - rotation_rad  # north's direction in the picture
        dx = 0.5 * self.north_scale[0] * math.cos(north)
        dy = 0.5 * self.north_scale[1] * math.sin(north)
        self.north.xy = (NORTH_AT[0] + dx, NORTH_AT[1] + dy)
        self.north.set_position((NORTH_AT[0] - dx, NORTH_AT[1] - dy))
        self.north_n.set_position((NORTH_AT[0] + 2.0 * dx, NORTH_AT[1] + 2.0 * dy))

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
        if self.frames.contact is not None:
            handles.append(
                Patch(facecolor="none", edgecolor=CONTACT_COLOUR, linewidth=2, label="hit")
            )
        over.legend(
            handles=handles,
            loc="lower center",
            bbox_to_anchor=(0.5, 0.0),
            fontsize=7,
            ncols=len(handles),
            frameon=False,
        )
        title = fit(self._title(self.summary), size_in[0], TITLE_FONTSIZE)
        over.suptitle(title, fontsize=TITLE_FONTSIZE, y=0.985)
        canvas = FigureCanvasAgg(over)
        canvas.draw()
        self.fig.figimage(np.asarray(canvas.buffer_rgba()), origin="upper", zorder=10)

    def _title(self, s: dict) -> str:
        hit = s.get("collision_with", "none")
        end = f"{s['outcome']}" + (f", hit {hit}" if hit not in (None, "none") else "")
        return f"{s.get('reason', '')} ({end})"

    def _draw_road(self) -> None:
        """The lanes of the network near any frame's view, once (the view turns them)."""
        views = self.frames.views
        net = self.summary.get("net_file")
        reach = 0.5 * np.hypot(views.width_m, views.height_m)
        bbox = (
            float(np.min(views.centre_x_m - reach)),
            float(np.min(views.centre_y_m - reach)),
            float(np.max(views.centre_x_m + reach)),
            float(np.max(views.centre_y_m + reach)),
        )
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
        for polygons, colour in ((road.road, "#616161"), (road.pavement, "#bdbdbd")):
            surface = PolyCollection(polygons, facecolors=colour, edgecolors="none", zorder=1)
            self.ax.add_collection(surface, autolim=False)
            surface.set_transform(self.data)
        solid = LineCollection(road.solid, colors="white", linewidths=1.0, zorder=1.5)
        dashed = LineCollection(
            road.dashed, colors="white", linewidths=0.8, linestyles=(0, (4, 6)), zorder=1.5
        )
        for lines in (solid, dashed):
            self.ax.add_collection(lines, autolim=False)
            lines.set_transform(self.data)

    def draw(self, k: int) -> None:
        """Update the artists to frame ``k``."""
        f = self.frames
        row = int(f.rows[k])
        self._turn_view(k)
        a, b = int(f.user_start[k]), int(f.user_end[k])
        self.bodies.set_verts(list(f.box[a:b]))
        self.bodies.set_facecolor(self.colour[a:b].tolist())
        self.cone.set_xy(
            radar_cone(f.radar_xy[k], f.ego_yaw_rad[k], f.radar_range_m, f.radar_fov_rad)
        )
        self.track.set_data(self.x[: row + 1], self.y[: row + 1])
        self.plan.set_data(*self._plan(row))
        self._draw_contact(k)
        self._draw_labels(k, a, b)
        self.text.set_text(self._status(k))

    def _turn_view(self, k: int) -> None:
        """Frame ``k``'s view: its centre to the origin, its heading to the right."""
        v = self.frames.views
        self.to_view.clear().translate(-v.centre_x_m[k], -v.centre_y_m[k])
        self.to_view.rotate(-v.rotation_rad[k])
        half_w, half_h = 0.5 * v.width_m[k], 0.5 * v.height_m[k]
        self.ax.set_xlim(-half_w, half_w)
        self.ax.set_ylim(-half_h, half_h)
        self._point_north(float(v.rotation_rad[k]))

    def _plan(self, row: int) -> tuple[np.ndarray, np.ndarray]:
        """The planned path from ``row``: ahead as long as the phase (manoeuvre or not)
        lasts, at most ``PLAN_AHEAD_S``."""
        end = int(np.searchsorted(self.t, self.t[row] + PLAN_AHEAD_S))
        phase = self.in_manoeuvre[row:end]
        n = int(np.argmin(phase == phase[0])) if not phase.all() and phase.any() else len(phase)
        return self.plan_x[row : row + n], self.plan_y[row : row + n]

    def _draw_contact(self, k: int) -> None:
        """The contact ring and the hit road user's outline on the contact's frame."""
        contact = self.frames.contact
        shown = contact is not None and k == len(self.frames.rows) - 1
        if contact is not None and shown:
            self.contact.set_data([contact.x_m], [contact.y_m])
        else:
            self.contact.set_data([], [])
        hit = contact.hit_row if contact is not None else None
        self.hit.set_visible(shown and hit is not None)
        if shown and hit is not None:
            self.hit.set_xy(self.frames.box[hit])

    def _draw_labels(self, k: int, a: int, b: int) -> None:
        """Each road user's id beside its box: above it in the picture, the ego's below it
        (so that the ego's and the obstacle's ids do not overlap at a contact)."""
        if not self.labels:
            return
        rotation = self.frames.views.rotation_rad[k]
        up = np.array([-math.sin(rotation), math.cos(rotation)])  # up in the picture
        across = np.where(self.frames.is_ego[a:b, None], -up, up)
        boxes = self.frames.box[a:b]
        centre = boxes.mean(axis=1)
        reach = np.max(np.einsum("nij,nj->ni", boxes - centre[:, None, :], across), axis=1)
        place = centre + (reach + LABEL_GAP_M)[:, None] * across
        for j, label in enumerate(self.labels):
            if j >= b - a:
                label.set_visible(False)
                continue
            label.set_position(tuple(place[j]))
            label.set_verticalalignment("top" if self.frames.is_ego[a + j] else "bottom")
            label.set_text(str(self.frames.user_id[a + j]))
            label.set_visible(True)

    def _status(self, k: int) -> str:
        row = int(self.frames.rows[k])
        mode = self.mode[row]
        name = MODE_NAMES.get(int(mode), "?") if np.isfinite(mode) else "end"
        sector = self.sector[row] or "-"
        fcw = "  FCW" if np.isfinite(self.fcw[row]) and self.fcw[row] > 0 else ""
        line = (
            f"t = {self.t[row]:6.2f} s   mode {name}   {3.6 * self.vx[row]:5.1f} km/h   "
            f"DMM sector {sector}{fcw}   view {self.frames.views.width_m[k]:.0f} m wide"
        )
        if self.frames.contact is not None and k == len(self.frames.rows) - 1:
            hit = self.summary.get("collision_with_id") or self.summary.get("collision_with")
            line += f"   CONTACT with {hit}"
        return line


def animate_cli(
    run_dir: Path, out: Path | None, fps: int, labels: bool = False, at_s: float | None = None
) -> str:
    """The line ``eoam-sumo animate`` prints."""
    path, n = animate_run(run_dir, out, fps, labels=labels, at_s=at_s)
    return f"{path} ({n} frames at {fps} fps)"
