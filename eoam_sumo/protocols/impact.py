"""What a protocol scores, measured from a run's time series: the longitudinal relative impact
speed (Euro NCAP's ``v_rel_impact``, not the magnitude of the relative velocity), the VUT's
speed at impact (its reduction, ``v_reduction``), the warning's lead over the emergency
braking (R152 para. 5.2.1.1) and whether the EOAM braked or steered (the scorecard's B/S).

The pure functions take plain numbers; ``measure`` reads a case folder's ``timeseries.csv``
and ``traffic.csv`` (docs/outputs.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

#: modes of a lane change (decision.modes: 2 UPDATE STEER+BRAKE, 4 ONCOMING STEER+BRAKE)
STEERING_MODES = (2, 4)


@dataclass(frozen=True)
class Measured:
    """A run's scored quantities [km/h, s]; ``contact`` False: no impact (speeds 0)."""

    contact: bool
    impact_long_kmh: float  # |relative velocity along the target's heading| at contact
    ego_speed_at_impact_kmh: float | None  # the VUT's forward speed then (None: no contact)
    warning_lead_s: float | None  # first emergency braking time - first FCW time
    braked: bool  # the EOAM left normal driving (every intervention mode brakes)


def longitudinal_closing_mps(
    ego_vx_mps: float,
    ego_vy_mps: float,
    ego_yaw_rad: float,
    target_speed_mps: float,
    target_heading_rad: float,
) -> float:
    """|(v_ego - v_target) . e_target|: the relative velocity along the target's heading
    (the ego's velocity from its body-frame vx, vy and yaw; the target moves along its
    heading). Head-on (target heading opposite) it is the sum of the two speeds."""
    ux, uy = math.cos(target_heading_rad), math.sin(target_heading_rad)
    c, s = math.cos(ego_yaw_rad), math.sin(ego_yaw_rad)
    vex, vey = ego_vx_mps * c - ego_vy_mps * s, ego_vx_mps * s + ego_vy_mps * c
    return abs(vex * ux + vey * uy - target_speed_mps)


def warning_lead_s(times_s: list[float], fcw: list[bool], modes: list[int]) -> float | None:
    """Time from the first FCW to the first step out of mode 0 (the emergency braking's
    start); None when either never happened."""
    t_fcw = next((t for t, f in zip(times_s, fcw) if f), None)
    t_brake = next((t for t, m in zip(times_s, modes) if m != 0), None)
    if t_fcw is None or t_brake is None:
        return None
    return t_brake - t_fcw


def steered(modes_visited: str, time_in_next_lane_s: float) -> bool:
    """The EOAM steered: a lane-change mode visited, or the ego's centre in the next lane."""
    visited = {int(m) for m in str(modes_visited).split("-") if m.strip().isdigit()}
    return bool(visited & set(STEERING_MODES)) or time_in_next_lane_s > 0.0


def measure(case_dir: Path, contact_time_s: float | None) -> Measured | None:
    """The scored quantities of the run in ``case_dir`` (None: its time series is missing)."""
    ts_path, tr_path = case_dir / "timeseries.csv", case_dir / "traffic.csv"
    if not ts_path.is_file():
        return None
    ts = pd.read_csv(ts_path, usecols=["time_s", "mode", "fcw", "yaw_rad", "vx_mps", "vy_mps"])
    lead = warning_lead_s(
        ts["time_s"].tolist(), [bool(f) for f in ts["fcw"]], [int(m) for m in ts["mode"]]
    )
    braked = bool((ts["mode"] != 0).any())
    if contact_time_s is None or math.isnan(contact_time_s) or not tr_path.is_file():
        return Measured(False, 0.0, None, lead, braked)
    ego = ts[ts["time_s"] <= contact_time_s + 1e-6].iloc[-1]
    tr = pd.read_csv(tr_path, usecols=["time_s", "id", "heading_rad", "speed_mps"])
    tgt = tr[(tr["id"] == "target") & (tr["time_s"] <= contact_time_s + 1e-6)].iloc[-1]
    closing = longitudinal_closing_mps(
        float(ego["vx_mps"]),
        float(ego["vy_mps"]),
        float(ego["yaw_rad"]),
        float(tgt["speed_mps"]),
        float(tgt["heading_rad"]),
    )
    return Measured(True, closing * 3.6, float(ego["vx_mps"]) * 3.6, lead, braked)
