"""Probability maps of a sampled batch: ``outcome_probability_map.csv``.

The probability of each outcome (any contact, red, near miss) as a smooth function of the
initial speed and the friction, with a pointwise 95 % confidence band: a binomial GLM with a
logit link (statsmodels), its terms B-splines (patsy ``bs``) or straight lines in each
parameter and their product, the candidate with the lowest AIC (Akaike 1974) among those with
at least ``EVENTS_PER_PARAMETER`` of the rarer result per coefficient (Vittinghoff and
McCulloch 2007). Each draw is shrunk towards the overall rate by k/n pseudo-draws (Clogg et al.
1991: y* = (y + p k/n) / (1 + k/n), k coefficients, n draws), so that a parameter range with
no event gives a small probability with a finite band instead of a diverging fit. The band is
the GLM's Wald interval of the linear predictor mapped through the logistic function. The map
covers the observed range only; the friction of a draw on the network's own (a matrix without
``mu``) is the one under the ego at its start (``mu_at_start``). Degenerate data fall back
to the overall Wilson interval (:func:`eoam_sumo.sampling.wilson_interval`) at every grid
point, the ``model`` column saying why: no event or only events, fewer than ``MIN_DRAWS``
draws, or no fit converged. One map
per slice (``slices``): the draws of two settings (policy, vehicle, driver, ...) are never one
fit.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.batch.probabilities import group_of
from eoam_sumo.batch.report import SETTINGS, setting_text, varying_settings
from eoam_sumo.fileio import write_atomic
from eoam_sumo.sampling import wilson_interval

MAP_FILE = "outcome_probability_map.csv"
X, Y = "ego_speed_kmh", "mu"  # the map's two parameters
GRID_POINTS = 21  # per varying parameter
MIN_DRAWS = 10  # fewer finished draws: no map, the overall rate
EVENTS_PER_PARAMETER = 5.0
SPLINE_MIN_DISTINCT = 6  # distinct values a parameter needs for a spline term
#: A generated scenario's road and level of service: columns of the CSV whenever set.
SCENARIO_COLUMNS = ("road", "los")
#: A drawn setting with more distinct values is a continuous draw: pooled like a scenario's.
MAX_DRAWN_LEVELS = 8

#: A draw cut off with this outcome says nothing of how it would have ended (docs/outcomes.md):
#: neither an event nor a non-event, it is left out of every map, as a failed draw is.
UNDECIDED = "unfinished"

#: outcome -> whether each decided draw had it
OUTCOMES: dict[str, Callable[[pd.DataFrame], pd.Series]] = {
    "contact": lambda r: r["collision_with"].fillna("none").astype(str) != "none",
    "red": lambda r: r["outcome"].astype(str) == "red",
    "near_miss": lambda r: r["near_miss"].astype(str) == "True",
}


def _terms(name: str, distinct: int) -> list[tuple[str, int]]:
    """A parameter's candidate terms and their coefficients: a straight line, and B-splines
    when it has the values for them."""
    if distinct < 2:
        return []
    splines = [(f"bs({name}, df={df})", df) for df in (3, 4) if distinct >= SPLINE_MIN_DISTINCT]
    return [(name, 1), *splines]


def candidate_formulas(distinct_x: int, distinct_y: int) -> list[tuple[str, int]]:
    """The candidate right-hand sides with their number of coefficients, simplest first
    (``1``: no parameter varies)."""
    xs, ys = _terms(X, distinct_x) or [("", 0)], _terms(Y, distinct_y) or [("", 0)]
    formulas = []
    for tx, kx in xs:
        for ty, ky in ys:
            formulas.append((" + ".join(t for t in (tx, ty) if t) or "1", 1 + kx + ky))
    if distinct_x >= 2 and distinct_y >= 2:
        formulas += [(f"{f} + {X}:{Y}", k + 1) for f, k in list(formulas)]
    return formulas


def _grid(draws: pd.DataFrame) -> pd.DataFrame:
    """The map's grid over the observed range of each parameter (one value if constant)."""
    axes = [np.linspace(draws[c].min(), draws[c].max(), GRID_POINTS) for c in (X, Y)]
    axes = [np.unique(a) for a in axes]
    gx, gy = np.meshgrid(*axes, indexing="ij")
    return pd.DataFrame({X: gx.ravel(), Y: gy.ravel()})


def _fallback(grid: pd.DataFrame, events: int, n: int, why: str) -> pd.DataFrame:
    low, high = wilson_interval(events, n)
    return grid.assign(p=events / n, p_low=low, p_high=high, model=f"none ({why}): overall")


def _fit(formula: str, coefficients: int, data: pd.DataFrame):
    """The shrunk binomial GLM of ``formula`` (statsmodels imported here only), or None for
    a singular design or a diverging, separated or non-converging fit."""
    import statsmodels.api as sm
    import statsmodels.formula.api as smf
    from statsmodels.tools.sm_exceptions import ModelWarning

    n, rate = len(data), float(data["event"].mean())
    with warnings.catch_warnings():
        for category in (RuntimeWarning, ModelWarning):
            warnings.simplefilter("error", category)
        try:
            shrink = coefficients / n
            shrunk = data.assign(event=(data["event"] + rate * shrink) / (1.0 + shrink))
            result = smf.glm(
                f"event ~ {formula}",
                shrunk,
                family=sm.families.Binomial(),
                var_weights=np.full(n, 1.0 + shrink),
            ).fit()
        except (ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeWarning, ModelWarning):
            return None
    return result if result.converged and np.isfinite(result.aic) else None


def fit_map(draws: pd.DataFrame) -> pd.DataFrame:
    """The map of one outcome over ``draws`` (columns X, Y and ``event``, 0/1): the grid with
    ``p, p_low, p_high`` and ``model`` (the chosen formula, or why there is none)."""
    grid, n, events = _grid(draws), len(draws), int(draws["event"].sum())
    if n < MIN_DRAWS:
        return _fallback(grid, events, n, f"{n} draws")
    if events in (0, n):
        return _fallback(grid, events, n, f"{events} of {n}")
    budget = max(3.0, min(events, n - events) / EVENTS_PER_PARAMETER)
    distinct = [draws[c].nunique() for c in (X, Y)]
    best = None
    for formula, coefficients in candidate_formulas(*distinct):
        result = _fit(formula, coefficients, draws) if coefficients <= budget else None
        if result is None:
            continue
        if best is None or result.aic < best[1].aic - 1e-9:
            best = (formula, result)
    if best is None:
        return _fallback(grid, events, n, "no fit")
    frame = best[1].get_prediction(grid).summary_frame(alpha=0.05)
    return grid.assign(
        p=frame["mean"].to_numpy(),
        p_low=frame["mean_ci_lower"].to_numpy(),
        p_high=frame["mean_ci_upper"].to_numpy(),
        model=f"logit GLM: {best[0]}",
    )


def slice_columns(ok: pd.DataFrame) -> list[str]:
    """The settings (``report.SETTINGS``) that get a map each: every one that varies among
    the draws but the map's axes (X, Y) and a drawn scenario value (``pooled``, varying
    within a group of swept values) or continuous draw (more than ``MAX_DRAWN_LEVELS``
    values); a generated scenario's road and level of service always."""
    groups = ok["case_id"].map(group_of) if "case_id" in ok else pd.Series(0, index=ok.index)
    columns = []
    for setting in varying_settings(ok, leave_out=(X, Y)):
        values = ok[setting.column]
        drawn = bool((values.groupby(groups).nunique(dropna=False) > 1).any())
        if not drawn or not (setting.pooled or values.nunique() > MAX_DRAWN_LEVELS):
            columns.append(setting.column)
    named = {c for c in SCENARIO_COLUMNS if c in ok and ok[c].fillna("").astype(str).ne("").any()}
    return [s.column for s in SETTINGS if s.column in named or s.column in columns]


def slices(ok: pd.DataFrame) -> list[tuple[dict, pd.DataFrame]]:
    """(slice values, draws) per combination of the ``slice_columns``, else one slice of
    every draw."""
    keys = slice_columns(ok)
    if not keys:
        return [({}, ok)]
    return [
        (dict(zip(keys, values if isinstance(values, tuple) else (values,))), draws)
        for values, draws in ok.groupby(keys, sort=True, dropna=False)
    ]


def slice_name(values: dict, leave_out: tuple[str, ...] = ()) -> str:
    """'safe policy, LoS E': a slice's values (but ``leave_out``) as a report names them."""
    texts = (
        setting_text(s, values[s.column])
        for s in SETTINGS
        if s.column in values and s.column not in leave_out
    )
    return ", ".join(t for t in texts if t)


def decided(results: pd.DataFrame) -> pd.DataFrame:
    """The draws whose run ended and decided its outcome: not failed, not ``UNDECIDED`` (cut
    off at the time limit before anything was decided); a draw on the network's own
    frictions (``mu`` empty) has the friction under the ego at its start as its ``mu``."""
    ok = results[(results["status"] == "ok") & (results["outcome"].astype(str) != UNDECIDED)]
    if "mu_at_start" not in ok or not ok[Y].isna().any():
        return ok
    return ok.assign(**{Y: ok[Y].fillna(ok["mu_at_start"])})


def probability_map(results: pd.DataFrame) -> pd.DataFrame:
    """Every outcome's map over the decided draws of a results frame (``read_results``,
    ``decided``), one per slice (``slices``): the slice's columns, ego_speed_kmh, mu, outcome,
    p, p_low, p_high, n, events, model."""
    ok = decided(results)
    frames = []
    for values, draws in slices(ok):
        data = draws[[X, Y]].astype(float).reset_index(drop=True)
        for outcome, event in OUTCOMES.items():
            data["event"] = event(draws).astype(float).to_numpy()
            fitted = fit_map(data)
            frames.append(
                fitted.assign(
                    **values, outcome=outcome, n=len(data), events=int(data["event"].sum())
                )
            )
    if not frames:
        return pd.DataFrame()
    columns = [s.column for s in SETTINGS if s.column in frames[0] and s.column not in (X, Y)]
    columns += [X, Y, "outcome", "p", "p_low", "p_high", "n", "events", "model"]
    return pd.concat(frames, ignore_index=True)[columns]


def write_probability_map(out_dir: Path, frame: pd.DataFrame) -> Path:
    """Write ``outcome_probability_map.csv`` (atomically, 6 significant digits)."""
    path = Path(out_dir) / MAP_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, frame.to_csv(index=False, float_format="%.6g"))
    return path
