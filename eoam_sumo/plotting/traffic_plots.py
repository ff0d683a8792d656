"""``traffic.png``: the ego and every road user of a run in the ego's road frame.

Two panels, both in the road frame of the ego's original lane (``roadtracks``: station ``s``
along its centre line, lateral offset ``d`` left positive, as ``timeseries.csv`` measures the
ego):

* the plan view unrolled along the road: ``d`` against ``s``, the ego's lane and the next
  lane to its left drawn at the run's lane width, the tracks of the ego's centre of gravity
  (from timeseries.csv) and of every road user's footprint centre (from traffic.csv),
  parked road users as their footprints;
* the space-time diagram: ``s`` against time, each road user as the band its length covers
  along the road.

Road users are coloured by the most telling role they had (``animate.ROLE_COLOURS``: the
outcome palette's red, orange, green for obstacle, oncoming and other traffic, blue for the
ego, grey for parked). Marked: the smallest box-to-box gaps to the obstacle and to oncoming
traffic (where, when, the footprints then), road users braking harder than
``roadtracks.HARD_BRAKING_MPS2``, and the contact (its point and the two footprints). Road
users more than ``FAR_LANES`` lane widths off the ego's lane throughout are not drawn.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from eoam_sumo.plotting.animate import ROLE_COLOURS
from eoam_sumo.plotting.figures import save
from eoam_sumo.plotting.roadtracks import (
    HARD_BRAKING_MPS2,
    Braking,
    Closest,
    EgoRoad,
    box_outline,
    closest_approach,
    ego_road,
    hard_braking,
    project_traffic,
    telling_roles,
)
from eoam_sumo.plotting.run_plots import load_run, run_title
from eoam_sumo.plotting.runfacts import fit, lane_width_m
from eoam_sumo.sim.runlog import written_as
from eoam_sumo.sim.trafficlog import (
    TRAFFIC_COLUMNS,
    TRAFFIC_FILE,
    TRAFFIC_RADIUS_M,
    read_traffic,
)

TRAFFIC_PNG = "traffic.png"
#: Road users whose centre stays farther than this many lane widths from the ego lane's
#: centre line are not drawn (cross streets, other roads within the log's radius).
FAR_LANES = 3.0
#: Without road.csv, road users are drawn only this far beyond the stretch the ego drove,
#: where the centre line is extended straight [m].
FALLBACK_REACH_M = 50.0
#: A road user's rows further apart than this in time are drawn as separate pieces [s].
TRACK_GAP_S = 0.05
CLOSEST_STYLE = {"aro": ("v", "obstacle"), "oncoming": ("D", "oncoming")}


@dataclass
class TrafficScene:
    """What the traffic plot draws, read once from the run folder."""

    summary: dict
    ts: pd.DataFrame
    road: EgoRoad
    traffic: pd.DataFrame  # projected rows of the road users drawn (the ego's included)
    roles: dict[str, str]
    lane_width_m: float
    notes: list[str] = field(default_factory=list)
    closest: dict[str, Closest] = field(default_factory=dict)
    braking: list[Braking] = field(default_factory=list)


def plot_traffic(run_dir: Path, out_dir: Path) -> Path:
    """``traffic.png`` of a run folder (the module doc); the ego alone, and a note saying
    why, when traffic.csv is missing or empty."""
    run_dir = Path(run_dir)
    summary, ts = load_run(run_dir)
    scene = read_scene(run_dir, summary, ts)
    fig = Figure(figsize=(13, 12), layout="constrained")
    plan, space_time = fig.subplots(2, 1, height_ratios=(1.0, 1.3))
    _draw_plan(plan, scene)
    _draw_space_time(space_time, scene)
    fig.legend(handles=_legend(scene), loc="outside lower center", ncols=4, fontsize=8)
    head = "Traffic in the ego's road frame — " + run_title(summary, ts, run_dir)
    fig.suptitle(fit("\n".join([head, *scene.notes]), 13, 10), fontsize=10)
    return save(fig, Path(out_dir) / TRAFFIC_PNG)


def read_scene(run_dir: Path, summary: dict, ts: pd.DataFrame) -> TrafficScene:
    """The run's road frame, its road users projected into it and the events to mark."""
    road = ego_road(run_dir, ts)
    width, recorded = lane_width_m(summary)
    notes = [f"road frame from {road.source}"]
    if not recorded:
        notes.append(f"lane width not recorded: {width:g} m assumed")
    traffic, why = _read_traffic(run_dir)
    if why:
        notes.append(why)
    traffic = project_traffic(traffic, road)
    traffic, dropped = _near_the_road(traffic, road, width)
    if dropped:
        notes.append(dropped)
    scene = TrafficScene(summary, ts, road, traffic, telling_roles(traffic), width, notes)
    if not why and not (traffic["role"] != "ego").any():
        notes.append(f"no other road user came within {TRAFFIC_RADIUS_M:g} m of the ego")
    hit = summary.get("collision_with_id") if summary.get("contact_time_s") is not None else None
    for role in CLOSEST_STYLE:
        found = closest_approach(traffic, role)
        if found is not None and not (found.gap_m <= 0.0 and found.vid == hit):
            scene.closest[role] = found  # (a contact is marked as such)
    scene.braking = hard_braking(traffic)
    return scene


def _read_traffic(run_dir: Path) -> tuple[pd.DataFrame, str]:
    """traffic.csv's rows with a whole footprint (finite pose, positive size), or none and
    why (missing or empty); a damaged file is an InputError naming it."""
    path = written_as(run_dir / TRAFFIC_FILE)  # or traffic.parquet
    if not path.is_file():
        return _no_traffic(), f"no {TRAFFIC_FILE} in the run folder: the ego alone"
    if path.stat().st_size == 0:
        return _no_traffic(), f"{TRAFFIC_FILE} is empty: the ego alone"
    frame = read_traffic(path)
    pose = frame[["time_s", "x_m", "y_m", "heading_rad", "speed_mps"]].to_numpy(dtype=float)
    whole = np.isfinite(pose).all(axis=1) & (frame["length_m"] > 0) & (frame["width_m"] > 0)
    frame = frame[whole].reset_index(drop=True)
    if frame.empty:
        return frame, f"{TRAFFIC_FILE} holds no rows: the ego alone"
    return frame, ""


def _no_traffic() -> pd.DataFrame:
    return pd.DataFrame({c: pd.Series(dtype=float) for c in TRAFFIC_COLUMNS}).astype(
        {"id": str, "vclass": str, "role": str}
    )


def _near_the_road(
    traffic: pd.DataFrame, road: EgoRoad, width_m: float
) -> tuple[pd.DataFrame, str]:
    """The rows of road users that came within ``FAR_LANES`` lane widths of the ego lane's
    centre line (and, without road.csv, of the stretch the ego drove), and what was left
    out."""
    keep = traffic["d_m"].abs() <= FAR_LANES * width_m
    if road.covered_m is not None:
        lo, hi = road.covered_m
        keep &= traffic["s_m"].between(lo - FALLBACK_REACH_M, hi + FALLBACK_REACH_M)
    keep |= traffic["role"] == "ego"
    near_ids = set(traffic.loc[keep, "id"])
    far = sorted(set(traffic["id"]) - near_ids)
    kept = traffic[keep & traffic["id"].isin(near_ids)]
    if not far:
        return kept, ""
    where = f"{FAR_LANES:g} lane widths of the ego's lane"
    if road.covered_m is not None:
        where += f" and {FALLBACK_REACH_M:g} m of the ego's stretch of road"
    return kept, f"{len(far)} road user(s) never within {where} not drawn"


def _pieces(t: np.ndarray, *values: np.ndarray) -> list[np.ndarray]:
    """``t`` and ``values`` with NaN between rows more than ``TRACK_GAP_S`` apart, so a line
    breaks where a road user left the log."""
    cut = np.flatnonzero(np.diff(t) > TRACK_GAP_S) + 1
    return [np.insert(np.asarray(v, dtype=float), cut, np.nan) for v in (t, *values)]


def _others(scene: TrafficScene):
    """(id, role, rows in time order) of every road user drawn but the ego."""
    traffic = scene.traffic[scene.traffic["role"] != "ego"]
    for vid, rows in traffic.sort_values("time_s", kind="stable").groupby("id", sort=True):
        yield str(vid), scene.roles[str(vid)], rows


def _ego_box_rows(scene: TrafficScene) -> pd.DataFrame:
    return scene.traffic[scene.traffic["role"] == "ego"].sort_values("time_s")


def _draw_lanes(ax, width_m: float) -> None:
    """The ego's lane and the next lane to its left, at the run's lane width."""
    ax.axhspan(-0.5 * width_m, 1.5 * width_m, color="0.93", zorder=0)
    for d, style in ((-0.5, "-"), (0.5, "--"), (1.5, "-")):
        ax.axhline(d * width_m, color="0.55", linestyle=style, linewidth=0.9, zorder=1)
    ax.axhline(0.0, color="0.75", linestyle=":", linewidth=0.8, zorder=1)
    ax.axhline(width_m, color="0.75", linestyle=":", linewidth=0.8, zorder=1)


def _draw_plan(ax, scene: TrafficScene) -> None:
    """Panel 1: lateral offset against station."""
    _draw_lanes(ax, scene.lane_width_m)
    for _vid, role, rows in _others(scene):
        colour = ROLE_COLOURS[role]
        if role == "parked" or np.ptp(rows["s_m"].to_numpy()) < 0.5:
            outline = box_outline(scene.road, rows.iloc[0])
            ax.fill(outline[:, 0], outline[:, 1], color=colour, alpha=0.45, zorder=2)
            continue
        _t, s, d = _pieces(*(rows[c].to_numpy() for c in ("time_s", "s_m", "d_m")))
        ax.plot(s, d, color=colour, linewidth=1.4, zorder=3)
        ax.plot(s[0], d[0], "o", color=colour, markersize=3, zorder=3)
    _draw_ego_plan(ax, scene.ts)
    _plan_limits(ax, scene)
    _mark_braking(ax, scene, "s_m", "d_m")
    _mark_closest_plan(ax, scene)
    _mark_contact_plan(ax, scene)
    ax.set_xlabel("station s along the ego's original lane [m]")
    ax.set_ylabel("lateral offset d [m] (left +)")
    ax.set_title(
        "plan view along the road (ego: centre of gravity; others: footprint centre; "
        "lanes at the run's width)",
        fontsize=10,
    )
    ax.grid(alpha=0.3)


def _draw_ego_plan(ax, ts: pd.DataFrame) -> None:
    """The ego's centre of gravity, beneath the road users' thinner lines (an obstacle in its
    lane runs along it), a dot at every whole second and the time at every other (where
    the labels do not crowd)."""
    s, d = ts["s_m"].to_numpy(dtype=float), ts["lateral_offset_m"].to_numpy(dtype=float)
    ax.plot(s, d, color=ROLE_COLOURS["ego"], linewidth=3.0, alpha=0.8, zorder=2.5)
    t = ts["time_s"].to_numpy(dtype=float)
    whole = np.flatnonzero(np.diff(np.floor(t + 1e-9), prepend=np.floor(t[0] + 1e-9) - 1) > 0)
    ax.plot(s[whole], d[whole], "o", color=ROLE_COLOURS["ego"], markersize=4, zorder=4)
    spacing = 0.04 * (np.nanmax(s) - np.nanmin(s) + 80.0)  # labels at least this far apart
    last = -np.inf
    for k in whole:
        if round(t[k]) % 2 == 0 and s[k] - last >= spacing:
            last = s[k]
            ax.annotate(
                f"{t[k]:.0f} s",
                (s[k], d[k]),
                xytext=(0, -11),
                textcoords="offset points",
                fontsize=7,
                ha="center",
                color=ROLE_COLOURS["ego"],
            )


def _plan_limits(ax, scene: TrafficScene) -> None:
    """Stations: the ego's stretch, 20 m behind to 60 m ahead, and whatever is marked;
    offsets: the two lanes, the ego and the marks, within ``FAR_LANES`` widths."""
    s = scene.ts["s_m"].to_numpy(dtype=float)
    d = scene.ts["lateral_offset_m"].to_numpy(dtype=float)
    marks = [scene.traffic.loc[c.row, ["s_m", "d_m"]].to_numpy() for c in scene.closest.values()]
    contact = _contact_sd(scene)
    if contact is not None:
        marks.append(np.asarray(contact))
    ms = np.array([m[0] for m in marks] or [np.nanmax(s)])
    md = np.array([m[1] for m in marks] or [0.0])
    ax.set_xlim(min(np.nanmin(s), ms.min()) - 20.0, max(np.nanmax(s), ms.max()) + 60.0)
    w, far = scene.lane_width_m, FAR_LANES * scene.lane_width_m
    lo = max(min(-1.5 * w, np.nanmin(d) - 1.0, md.min() - 1.5), -far)
    hi = min(max(2.0 * w, np.nanmax(d) + 1.0, md.max() + 1.5), far)
    ax.set_ylim(lo, hi)


def _draw_space_time(ax, scene: TrafficScene) -> None:
    """Panel 2: station against time, each road user as the band of its length."""
    for _vid, role, rows in _others(scene):
        colour = ROLE_COLOURS[role]
        t, s, half = _pieces(
            rows["time_s"].to_numpy(), rows["s_m"].to_numpy(), 0.5 * rows["length_m"].to_numpy()
        )
        ax.fill_between(t, s - half, s + half, color=colour, alpha=0.35, linewidth=0, zorder=2)
        ax.plot(t, s, color=colour, linewidth=1.0, zorder=3)
    ego = _ego_box_rows(scene)
    if len(ego):
        t, s, half = _pieces(
            ego["time_s"].to_numpy(), ego["s_m"].to_numpy(), 0.5 * ego["length_m"].to_numpy()
        )
        ax.fill_between(t, s - half, s + half, color=ROLE_COLOURS["ego"], alpha=0.3, linewidth=0)
    ts = scene.ts
    ax.plot(ts["time_s"], ts["s_m"], color=ROLE_COLOURS["ego"], linewidth=2.0, zorder=4)
    t_all = ts["time_s"].to_numpy(dtype=float)
    ax.set_xlim(np.nanmin(t_all), np.nanmax(t_all))
    _mark_braking(ax, scene, "time_s", "s_m")
    _mark_closest_time(ax, scene)
    _mark_contact_time(ax, scene)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("station s [m]")
    ax.set_title(
        "space-time diagram (bands: the length each body covers along the road)", fontsize=10
    )
    ax.grid(alpha=0.3)


def _note(ax, text: str, xy, above: bool = True, **style) -> None:
    """``text`` beside the point ``xy``: to its right, or to its left in the right third of
    the axes (so that it stays inside them), above or below it."""
    x0, x1 = ax.get_xlim()
    left = xy[0] - x0 > 0.65 * (x1 - x0)
    ax.annotate(
        text,
        xy,
        xytext=(-8 if left else 8, 9 if above else -9),
        textcoords="offset points",
        ha="right" if left else "left",
        va="bottom" if above else "top",
        fontsize=style.pop("fontsize", 8),
        **style,
    )


def _mark_braking(ax, scene: TrafficScene, x: str, y: str) -> None:
    """Spells of hard braking: a thick dark overlay on the track, the hardest deceleration
    named at its start."""
    for spell in scene.braking:
        rows = scene.traffic.loc[[r for r in spell.rows if r in scene.traffic.index]]
        if rows.empty:
            continue
        ax.plot(rows[x], rows[y], color="#4a148c", linewidth=4.0, alpha=0.55, zorder=5)
        _note(
            ax,
            f"{spell.vid} brakes {spell.peak_mps2:.1f} m/s²\n"
            f"{spell.speed_from_mps:.1f} → {spell.speed_to_mps:.1f} m/s",
            (rows[x].iloc[0], rows[y].iloc[0]),
            fontsize=7,
            color="#4a148c",
        )


def _closest_text(role: str, found: Closest) -> str:
    return f"closest {CLOSEST_STYLE[role][1]}: {found.gap_m:.2f} m at {found.time_s:.2f} s"


def _mark_closest_plan(ax, scene: TrafficScene) -> None:
    """The footprints of the ego and the road user at each smallest gap, and the gap."""
    for role, found in scene.closest.items():
        marker, _ = CLOSEST_STYLE[role]
        other, ego = scene.traffic.loc[found.row], scene.traffic.loc[found.ego_row]
        for row, colour in ((other, ROLE_COLOURS[role]), (ego, ROLE_COLOURS["ego"])):
            outline = box_outline(scene.road, row)
            ax.plot(outline[:, 0], outline[:, 1], color=colour, linewidth=1.2, linestyle="--")
        ax.plot(other["s_m"], other["d_m"], marker, color="black", markersize=7, zorder=6)
        _note(
            ax,
            _closest_text(role, found) + f"\n(s = {other['s_m']:.1f} m, d = {other['d_m']:.2f} m)",
            (other["s_m"], other["d_m"]),
            above=role == "oncoming",
        )


def _mark_closest_time(ax, scene: TrafficScene) -> None:
    """A dotted line from the ego to the road user at each smallest gap."""
    for role, found in scene.closest.items():
        marker, _ = CLOSEST_STYLE[role]
        other, ego = scene.traffic.loc[found.row], scene.traffic.loc[found.ego_row]
        ax.plot([found.time_s] * 2, [ego["s_m"], other["s_m"]], ":", color="black", zorder=6)
        ax.plot(found.time_s, other["s_m"], marker, color="black", markersize=7, zorder=6)
        _note(ax, _closest_text(role, found), (found.time_s, other["s_m"]), role == "oncoming")


def _contact_sd(scene: TrafficScene) -> tuple[float, float] | None:
    """The contact point in the road frame (None without a contact)."""
    s = scene.summary
    x, y = s.get("contact_x_m"), s.get("contact_y_m")
    if s.get("contact_time_s") is None or x is None or y is None:
        return None
    sd = scene.road.project_path(np.array([[x, y]], dtype=float))[0]
    return float(sd[0]), float(sd[1])


def _contact_rows(scene: TrafficScene) -> list[tuple[pd.Series, str]]:
    """The footprints of the ego and of the road user hit, at the logged time nearest the
    contact, with their colours."""
    s, traffic = scene.summary, scene.traffic
    hit = s.get("collision_with_id")
    out = []
    for rows in (
        traffic[traffic["role"] == "ego"],
        traffic[(traffic["id"] == hit) & (traffic["role"] != "ego")],
    ):
        if len(rows):
            k = (rows["time_s"] - float(s["contact_time_s"])).abs().idxmin()
            out.append((rows.loc[k], ROLE_COLOURS[scene.roles[str(rows.at[k, "id"])]]))
    return out


def _contact_text(scene: TrafficScene) -> str:
    s = scene.summary
    who = s.get("collision_with_id") or s.get("collision_with", "")
    return (
        f"contact at {float(s['contact_time_s']):.2f} s: {s.get('contact_kind', '')} with "
        f"{who} ({s.get('collision_with_class') or s.get('collision_with', '')}), "
        f"{float(s.get('impact_speed_mps') or 0.0):.1f} m/s"
    )


def _mark_contact_plan(ax, scene: TrafficScene) -> None:
    """The contact point and the two footprints then."""
    point = _contact_sd(scene)
    if point is None:
        return
    for row, colour in _contact_rows(scene):
        outline = box_outline(scene.road, row)
        ax.fill(outline[:, 0], outline[:, 1], color=colour, alpha=0.3, zorder=5)
        ax.plot(outline[:, 0], outline[:, 1], color="black", linewidth=1.0, zorder=5)
    ax.plot(*point, "*", color="yellow", markeredgecolor="black", markersize=16, zorder=7)
    _note(ax, _contact_text(scene), point, above=False)  # a braking note may be above


def _mark_contact_time(ax, scene: TrafficScene) -> None:
    point = _contact_sd(scene)
    if point is None:
        return
    t = float(scene.summary["contact_time_s"])
    ax.plot(t, point[0], "*", color="yellow", markeredgecolor="black", markersize=16, zorder=7)
    _note(ax, _contact_text(scene), (t, point[0]))


def _legend(scene: TrafficScene) -> list:
    """Roles present, then the marks drawn."""
    present = set(scene.roles.values()) | {"ego"}
    handles: list = [
        Patch(facecolor=ROLE_COLOURS[r], edgecolor="black", label=r if r != "ego" else "ego")
        for r in ROLE_COLOURS
        if r in present
    ]
    for role in scene.closest:
        marker, what = CLOSEST_STYLE[role]
        handles.append(
            Line2D([], [], marker=marker, color="black", linestyle="", label=f"closest {what}")
        )
    if scene.braking:
        handles.append(
            Line2D(
                [],
                [],
                color="#4a148c",
                linewidth=4.0,
                alpha=0.55,
                label=f"braking harder than {HARD_BRAKING_MPS2:g} m/s²",
            )
        )
    if _contact_sd(scene) is not None:
        handles.append(
            Line2D(
                [],
                [],
                marker="*",
                color="yellow",
                markeredgecolor="black",
                markersize=12,
                linestyle="",
                label="contact point",
            )
        )
    return handles
