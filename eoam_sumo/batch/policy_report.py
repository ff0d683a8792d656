"""The decision policy of a batch in its Table 2 report: title, settings line, sight distances.

Under the safe policy every case records what its sight-distance gate needed (the passing
sight distance of the lane change when the DMM first asked for one) and the length of the
next lane known to be free then; ``sight_markdown`` lays them out in the grid of Table 2.
"""

from __future__ import annotations

import math

import pandas as pd

from eoam_sumo.batch.report import grid_layout, mu_text


def _first(results: pd.DataFrame, column: str, default=None):
    if column not in results:
        return default
    values = results[column].dropna()
    return values.iloc[0] if len(values) else default


def _policies(results: pd.DataFrame) -> list[str]:
    """The batch's decision policies in its order (none recorded: the paper's)."""
    if "policy" not in results:
        return ["paper"]
    return [str(p) for p in pd.unique(results["policy"].dropna())] or ["paper"]


def policy_title(results: pd.DataFrame) -> str:
    """'Table 2, policy safe, V2X 1000 m' (the paper policy without V2X: 'Table 2'; policies
    swept: 'Table 2, policies paper and safe'). Whose outcomes it shows, the EOAM's or a
    reference driver's, the grid's ``subject`` says after it."""
    policies = _policies(results)
    v2x = _first(results, "v2x_range_m", 0.0)
    if len(policies) > 1:
        title = f"Table 2, policies {' and '.join(policies)}"
    else:
        title = "Table 2" if policies[0] == "paper" else f"Table 2, policy {policies[0]}"
    if v2x and v2x > 0:
        title += f", V2X {v2x:g} m"
    return title


def policy_line(results: pd.DataFrame) -> str:
    """One line naming the policy (policies swept: each, a row each), the radar range and
    the V2X link."""
    policies = _policies(results)
    radar = _first(results, "radar_range_m")
    radar_text = "100 m (default)" if radar is None or not math.isfinite(radar) else f"{radar:g} m"
    if len(policies) > 1:
        line = f"Policies {', '.join(f'**{p}**' for p in policies)} (a row each)"
    else:
        line = f"Policy **{policies[0]}**"
    line += f"; forward radar {radar_text}"
    v2x = _first(results, "v2x_range_m", 0.0)
    if v2x and v2x > 0:
        line += (
            f"; V2X range {v2x:g} m, latency {_first(results, 'v2x_latency_s'):g} s, "
            f"loss {_first(results, 'v2x_loss'):g}, penetration "
            f"{_first(results, 'v2x_penetration'):g}"
        )
    elif "safe" in policies:
        line += "; no V2X"
    return line + "."


def _sight_cell(row) -> str:
    gate = row.get("sight_gate") or ""
    if not gate:
        return "—"
    need = row.get("sight_needed_m")
    free = row.get("sight_known_free_m")
    need_text = "∞" if need is None or not math.isfinite(need) else f"{need:.0f}"
    free_text = "?" if free is None or not math.isfinite(free) else f"{free:.0f}"
    return f"{need_text} / {free_text} {'✓' if gate == 'passed' else '✗'}"


def sight_markdown(results: pd.DataFrame) -> str:
    """The sight distance each case needed and knew free at its first lane-change request,
    in Table 2's grid (``report.grid_layout``; empty text when no case asked the gate)."""
    if "sight_gate" not in results or not (results["sight_gate"].fillna("") != "").any():
        return ""
    grid = grid_layout(results)
    cells = {place: _sight_cell(row) for place, (_, row) in zip(grid.places, results.iterrows())}
    lines = [
        "## Sight distance of each lane change (safe policy)",
        "",
        (
            "Each cell: passing sight distance needed [m] / length of the next lane known free "
            "[m], when the DMM first asked for the lane change; ✓ the gate let it begin, ✗ it "
            "braked in lane instead; — no lane change was asked for; ∞ the ego would never get "
            "past the obstacle."
        ),
        "",
        "| Traffic | Initial ego speed | "
        + " | ".join(f"{mu_text(mu)} surface mu" for mu in grid.mus)
        + " |",
        "|---|---|" + "---|" * len(grid.mus),
    ]
    previous = None
    for i, (traffic, speed) in enumerate(grid.rows):
        cols = [cells.get((i, j), "") for j in range(len(grid.mus))]
        lines.append(
            f"| {traffic if traffic != previous else ''} | {speed} | " + " | ".join(cols) + " |"
        )
        previous = traffic
    return "\n".join(lines) + "\n"
