"""``eoam-sumo plot`` on a batch folder of an .xosc's variations: each case's outcome over its
parameters (results.csv's ``param:NAME`` columns)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from eoam_sumo.batch.probabilities import outcomes_of
from eoam_sumo.colours import FAILED, HEX, OUTCOMES
from eoam_sumo.errors import InputError

PARAM = "param:"
OUT_NAME = "xosc_outcomes.png"
MAX_PANELS = 4


def is_xosc_results(path: Path) -> bool:
    """Whether results.csv is an .xosc batch's (its header has ``param:NAME`` columns or
    starts with the .xosc batch's first columns, ``openscenario.batch.FIRST``)."""
    try:
        with open(path, encoding="utf-8") as f:
            names = f.readline().rstrip("\n").split(",")
    except (OSError, UnicodeDecodeError):
        return False  # the batch's reader says why in its words
    return any(n.startswith(PARAM) for n in names) or names[:4] == [
        "case_id",
        "status",
        "error",
        "outcome",
    ]


def _axis(values: pd.Series) -> tuple[pd.Series, list[str] | None]:
    """Numbers as they are; text as category positions with their labels."""
    numbers = pd.to_numeric(values, errors="coerce")
    if numbers.notna().all():
        return numbers, None
    labels = sorted(values.astype(str).unique())
    return values.astype(str).map({v: i for i, v in enumerate(labels)}), labels


def plot_xosc_batch(batch_dir: Path, out_dir: Path) -> list[Path]:
    """One panel per varied parameter (the first ``MAX_PANELS``): the impact speed of each
    case (0 without contact) over the parameter, coloured by its outcome."""
    path = Path(batch_dir) / "results.csv"
    frame = pd.read_csv(path, dtype=str, keep_default_na=False)
    params = [c for c in frame.columns if c.startswith(PARAM)]
    if frame.empty:
        raise InputError(f"{path}: no cases to plot")
    params = [c for c in params if frame[c].nunique() > 1][:MAX_PANELS] or params[:1]
    outcome = outcomes_of(frame)
    speed = pd.to_numeric(frame.get("impact_speed_mps"), errors="coerce").fillna(0.0)
    panels = max(len(params), 1)
    fig = Figure(figsize=(4.2 * panels + 1.0, 3.8), layout="constrained")
    axes = fig.subplots(1, panels, squeeze=False)
    for ax, column in zip(axes[0], params or [None], strict=True):
        x, labels = _axis(frame[column]) if column else (pd.Series(range(len(frame))), None)
        for name in (*OUTCOMES, FAILED):
            mine = outcome == name
            if mine.any():
                ax.scatter(x[mine], speed[mine], c=HEX[name], edgecolors="k", label=name, s=40)
        if labels is not None:
            ax.set_xticks(range(len(labels)), labels, rotation=30, ha="right")
        ax.set_xlabel(column.removeprefix(PARAM) if column else "case")
        ax.set_ylabel("impact speed [m/s] (0: no contact)")
        top = max(float(speed.max()) * 1.1, 1.0)
        ax.set_ylim(-0.04 * top, top)  # the no-contact cases' markers whole on the axis
        ax.grid(alpha=0.3)
    axes[0][-1].legend(title="outcome", fontsize=8, loc="best")
    fig.suptitle(f"{Path(batch_dir).name}: {len(frame)} cases of the .xosc's variations")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / OUT_NAME
    fig.savefig(target, dpi=110)
    return [target]
