"""The vehicles report of a batch (``vehicles.md``): Table 2 per vehicle, ABS/ESC and policy.

For each (vehicle, ABS/ESC, policy or driver, and any other setting that varies) of a
results frame, the outcome colour counts beside the paper's Table 2 counts (Lowe & Guvenc
2022, sec. 11.2, the ``[paper]`` table) and how many cells agree with the paper; then, per
vehicle and policy, every Table 2 cell whose colour ABS/ESC changes (its colour without,
with, and the run's reason with). Built from results.csv alone, so a finished batch can be
reported again.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from eoam_sumo.batch.report import GRID_AXES, settings_label, varying_settings
from eoam_sumo.colours import FAILED, MARKERS, OUTCOMES
from eoam_sumo.fileio import write_atomic
from eoam_sumo.matrix import POLICIES

VEHICLES_MD = "vehicles.md"
VEHICLES_PNG = "vehicles.png"
#: The paper's colours, counted in every row of the report.
COUNTED = ("green", "yellow", "orange", "red")
#: The keys one row of the report stands for: ``policy`` names the policy or the reference
#: driver, and every other setting that varies (``report.SETTINGS``).
GROUP = ("vehicle", "equipment", "policy")
#: The settings a row names in columns of their own (``vehicle``, ``equipment``) or as the
#: policy or driver; with Table 2's cell (speed, friction, oncoming car) left out of its label.
_OWN_COLUMNS = ("vehicle", "abs_fitted", "esc_fitted", "policy", "driver", *GRID_AXES)
#: The columns whose variation makes a batch a vehicles experiment.
VARIED = ("vehicle", "policy", "driver", "abs_fitted", "esc_fitted")


def sweeps_vehicles(results: pd.DataFrame) -> bool:
    """Whether the batch varies the vehicle, its ABS/ESC, the policy or the driver
    (``VARIED``)."""
    return any(col in results and _values(results[col]).nunique() > 1 for col in VARIED)


def _values(column: pd.Series) -> pd.Series:
    """A column's values as text, a failed case's empty cell left out (it is no equipment
    or policy of its own: one failed case made a plain batch a vehicles experiment)."""
    text = column.dropna().astype(str)
    return text[text != ""]


def _switch(value) -> str:
    """A results.csv ABS/ESC value as on / off ("?" for a failed case's empty cell)."""
    text = str(value)
    return "on" if text == "True" else "off" if text == "False" else "?"


def equipment_label(abs_fitted, esc_fitted) -> str:
    """``ABS/ESC off``, ``ABS/ESC on`` or ``ABS on, ESC off`` (and the like)."""
    abs_on, esc_on = _switch(abs_fitted), _switch(esc_fitted)
    if abs_on == esc_on:
        return f"ABS/ESC {abs_on}"
    return f"ABS {abs_on}, ESC {esc_on}"


def cell_id(row) -> str:
    """The Table 2 cell of a row, as Table 2's case ids name it: ``onc-none_v165_mu1.0``
    (``onc-none_v165`` on the network's own frictions, ``mu`` empty)."""
    onc = row["oncoming_start_m"]
    onc_text = "none" if pd.isna(onc) else f"{float(onc):g}"
    mu = "" if pd.isna(row["mu"]) else f"_mu{float(row['mu'])!r}"
    return f"onc-{onc_text}_v{float(row['ego_speed_kmh']):g}{mu}"


def labelled(results: pd.DataFrame) -> pd.DataFrame:
    """The frame with the report's columns: ``equipment``, ``colour`` (``failed`` for a case
    that did not finish), ``cell`` and ``policy`` as a row names it (``policy_label``)."""
    frame = results.copy()
    for col in VARIED:
        if col not in frame:
            frame[col] = None
    frame["equipment"] = [
        equipment_label(a, e) for a, e in zip(frame["abs_fitted"], frame["esc_fitted"])
    ]
    frame["colour"] = [
        o if s == "ok" else FAILED for o, s in zip(frame["outcome"], frame["status"])
    ]
    frame["cell"] = [cell_id(row) for _, row in frame.iterrows()]
    frame["vehicle"] = frame["vehicle"].fillna("sedan")
    frame["policy"] = frame["policy"].fillna("paper")
    frame["driver"] = frame["driver"].fillna("eoam")
    frame["policy"] = policy_label(frame)
    return frame


def policy_label(frame: pd.DataFrame) -> list[str]:
    """Each row's third column: the policy of the EOAM's runs, the driver of a reference
    driver's (it has no decision policy), with the policy when policies are swept too (its
    runs under each are rows of their own), then any other setting that varies."""
    policies = frame["policy"].nunique() > 1
    others = varying_settings(frame, leave_out=_OWN_COLUMNS)
    labels = []
    for _, row in frame.iterrows():
        parts = [str(row["policy"])]
        if row["driver"] != "eoam":
            parts = [str(row["driver"]), *([f"{row['policy']} policy"] if policies else [])]
        labels.append(", ".join(t for t in (*parts, settings_label(row, others)) if t))
    return labels


def colour_counts(results: pd.DataFrame) -> pd.DataFrame:
    """One row per (vehicle, equipment, policy) in the batch's order: the count of every
    colour (``COUNTED`` first, then any other seen), ``agree`` (cells whose colour is the
    paper's) and ``compared`` (cells the paper covers)."""
    frame = labelled(results)
    others = [c for c in (*OUTCOMES, FAILED) if c not in COUNTED and (frame["colour"] == c).any()]
    rows = []
    for key, group in frame.groupby(list(GROUP), sort=False):
        paper = group["paper_outcome"].fillna("").astype(str)
        row = dict(zip(GROUP, key))
        row.update({c: int((group["colour"] == c).sum()) for c in (*COUNTED, *others)})
        row["agree"] = int(((group["colour"] == paper) & (paper != "")).sum())
        row["compared"] = int((paper != "").sum())
        rows.append(row)
    return pd.DataFrame(rows)


def paper_counts(results: pd.DataFrame) -> dict[str, int]:
    """The paper's count of each ``COUNTED`` colour over the batch's Table 2 cells."""
    frame = labelled(results).drop_duplicates("cell")
    paper = frame["paper_outcome"].fillna("").astype(str)
    return {c: int((paper == c).sum()) for c in COUNTED}


def changed_cells(results: pd.DataFrame) -> pd.DataFrame:
    """Per vehicle and policy, each cell whose colour differs from the one without ABS/ESC
    (``ABS/ESC off``, else the batch's first equipment): vehicle, policy, cell, ``without``,
    ``equipment``, ``with`` and the with-run's ``reason``."""
    frame = labelled(results)
    labels = list(pd.unique(frame["equipment"]))
    base = "ABS/ESC off" if "ABS/ESC off" in labels else labels[0]
    keys = ["vehicle", "policy", "cell"]
    without = frame[frame["equipment"] == base][[*keys, "colour"]]
    others = frame[frame["equipment"] != base]
    merged = others.merge(without, on=keys, suffixes=("", "_without"))
    changed = merged[merged["colour"] != merged["colour_without"]]
    return pd.DataFrame(
        {
            "vehicle": changed["vehicle"],
            "policy": changed["policy"],
            "cell": changed["cell"],
            "without": changed["colour_without"],
            "equipment": changed["equipment"],
            "with": changed["colour"],
            "reason": changed.get("reason", pd.Series("", index=changed.index)).fillna(""),
        }
    ).reset_index(drop=True)


def _counts_table(counts: pd.DataFrame, paper: dict[str, int]) -> list[str]:
    """The markdown table of the colour counts, the paper's row first."""
    colours = [c for c in counts.columns if c not in (*GROUP, "agree", "compared")]
    head = "| vehicle | ABS/ESC | policy or driver | " + " | ".join(
        f"{MARKERS.get(c, '')} {c}" for c in colours
    )
    lines = [head + " | agree with the paper |", "|---" * (len(colours) + 4) + "|"]
    ref = " | ".join(str(paper.get(c, "")) for c in colours)
    lines.append(f"| **paper (Table 2)** | | | {ref} | |")
    for _, row in counts.iterrows():
        cells = " | ".join(str(row[c]) for c in colours)
        agree = f"{row['agree']}/{row['compared']}" if row["compared"] else "-"
        lines.append(
            f"| {row['vehicle']} | {row['equipment']} | {row['policy']} | {cells} | {agree} |"
        )
    return lines


def _changed_table(changed: pd.DataFrame) -> list[str]:
    """Per vehicle and policy, the cells ABS/ESC changes (or a line saying none does)."""
    if changed.empty:
        return ["ABS/ESC changes no cell's colour."]
    lines = []
    for (vehicle, policy), group in changed.groupby(["vehicle", "policy"], sort=False):
        named = f"{policy} policy" if policy in POLICIES else policy
        lines += [f"### {vehicle}, {named}", "", "| cell | change | reason |"]
        lines.append("|---|---|---|")
        for _, row in group.iterrows():
            change = (
                f"{MARKERS.get(row['without'], '')} {row['without']} -> "
                f"{MARKERS.get(row['with'], '')} {row['with']} ({row['equipment']})"
            )
            reason = str(row["reason"]).replace("|", "/")
            lines.append(f"| {row['cell']} | {change} | {reason} |")
        lines.append("")
    return lines


def vehicles_markdown(results: pd.DataFrame) -> str:
    """The text of ``vehicles.md`` (module docstring)."""
    lines = [
        "# Table 2 per vehicle, ABS/ESC and policy",
        "",
        "Outcome colours of each vehicle's Table 2 (Lowe & Guvenc 2022, sec. 11.2) beside "
        "the paper's counts; *agree*: cells whose colour is the paper's.",
        "",
        *_counts_table(colour_counts(results), paper_counts(results)),
        "",
        "## Cells ABS/ESC changes",
        "",
        *_changed_table(changed_cells(results)),
    ]
    return "\n".join(lines).rstrip("\n") + "\n"


def write_vehicles_report(out_dir: Path, results: pd.DataFrame) -> Path:
    """Write ``vehicles.md`` of a results frame into ``out_dir``; return its path."""
    return write_atomic(Path(out_dir) / VEHICLES_MD, vehicles_markdown(results))
