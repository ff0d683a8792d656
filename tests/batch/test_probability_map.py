"""The probability map (binomial GLM) against draws of a known logistic truth; monotone data;
degenerate inputs; determinism."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from eoam_sumo.batch.probability_map import (
    MAP_FILE,
    X,
    Y,
    candidate_formulas,
    fit_map,
    probability_map,
    write_probability_map,
)


def _truth(speed_kmh, mu):
    """P(event): logit-linear, rising with speed, falling with friction."""
    return 1.0 / (1.0 + np.exp(-(-1.0 + 0.06 * (speed_kmh - 110.0) - 5.0 * (mu - 0.55))))


def _draws(n: int, seed: int, truth=_truth) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    draws = pd.DataFrame({X: rng.uniform(60, 160, n), Y: rng.uniform(0.1, 1.0, n)})
    draws["event"] = (rng.uniform(size=n) < truth(draws[X], draws[Y])).astype(float)
    return draws


def test_the_map_recovers_a_logistic_truth_within_its_band():
    """Over 6 data sets of 300 draws, the truth lies inside the pointwise 95 % band at most
    grid points and the map is close to it."""
    inside, errors = [], []
    for seed in range(6):
        fitted = fit_map(_draws(300, seed))
        truth = _truth(fitted[X], fitted[Y])
        assert fitted["model"].str.startswith("logit GLM").all()
        inside.append(((fitted["p_low"] <= truth) & (truth <= fitted["p_high"])).mean())
        errors.append(np.median(np.abs(fitted["p"] - truth)))
    assert np.mean(inside) >= 0.8, inside
    assert max(errors) < 0.06, errors


def test_more_draws_narrow_the_band():
    width = [np.median(fit_map(_draws(n, 1)).eval("p_high - p_low")) for n in (60, 240, 960)]
    assert width[0] > width[1] > width[2]


def test_monotone_data_give_a_monotone_map():
    """Events only above a speed that falls with friction: p rises with speed and falls with
    friction everywhere on the grid."""
    rng = np.random.default_rng(7)
    draws = pd.DataFrame({X: rng.uniform(60, 160, 200), Y: rng.uniform(0.1, 1.0, 200)})
    draws["event"] = (draws[X] > 90 + 50 * draws[Y]).astype(float)
    grid = fit_map(draws).pivot_table(index=X, columns=Y, values="p").to_numpy()
    assert (np.diff(grid, axis=0) >= -1e-9).all()  # along speed
    assert (np.diff(grid, axis=1) <= 1e-9).all()  # along friction
    assert grid[0, -1] < 0.05 and grid[-1, 0] > 0.95


@pytest.mark.parametrize(
    ("events", "why"),
    [(np.zeros(40), "none (0 of 40)"), (np.ones(40), "none (40 of 40)")],
)
def test_no_event_or_only_events_give_the_overall_interval(events, why):
    draws = _draws(40, 2).assign(event=events)
    fitted = fit_map(draws)
    assert fitted["model"].str.startswith(why).all()
    assert (fitted["p"] == events[0]).all()
    low, high = (0.0, 0.0876) if events[0] == 0 else (0.9124, 1.0)  # Wilson, 0 or 40 of 40
    assert fitted["p_low"].iloc[0] == pytest.approx(low, abs=1e-3)
    assert fitted["p_high"].iloc[0] == pytest.approx(high, abs=1e-3)


def test_few_draws_give_the_overall_interval():
    fitted = fit_map(_draws(4, 3))
    assert fitted["model"].str.startswith("none (4 draws)").all()


def test_one_distinct_speed_gives_a_map_over_friction_only():
    draws = _draws(120, 4).assign(**{X: 120.0})
    draws["event"] = (np.random.default_rng(4).uniform(size=120) < 1.0 - draws[Y]).astype(float)
    fitted = fit_map(draws)
    assert fitted[X].nunique() == 1 and fitted[Y].nunique() > 10
    assert X not in fitted["model"].iloc[0]
    ordered = fitted.sort_values(Y)
    assert ordered["p"].iloc[0] > 0.6 and ordered["p"].iloc[-1] < 0.4


def test_a_separated_sweep_keeps_a_finite_band():
    """Two swept speeds, events only at the higher: a small p with a finite band at the
    lower speed (the shrinkage), not a diverging fit."""
    draws = pd.DataFrame({X: np.repeat([80.0, 120.0], 26), Y: np.tile([0.4, 1.0], 26)})
    draws["event"] = ((draws[X] == 120) & (np.arange(52) % 5 == 0)).astype(float)
    fitted = fit_map(draws)
    slow, fast = fitted[fitted[X] == 80], fitted[fitted[X] == 120]
    assert fitted["model"].str.startswith("logit GLM").all()
    assert slow["p"].max() < 0.05 < fast["p"].min()
    assert np.isfinite(fitted[["p_low", "p_high"]].to_numpy()).all()
    assert (fitted["p_low"] <= fitted["p"]).all() and (fitted["p"] <= fitted["p_high"]).all()


def test_candidates_fit_the_distinct_values():
    assert candidate_formulas(1, 1) == [("1", 1)]
    assert candidate_formulas(2, 2) == [(f"{X} + {Y}", 3), (f"{X} + {Y} + {X}:{Y}", 4)]
    assert (f"bs({X}, df=3) + {Y}", 5) in candidate_formulas(30, 2)


def _results(n: int, seed: int) -> pd.DataFrame:
    draws = _draws(n, seed)
    hit = draws["event"] > 0
    return pd.DataFrame(
        {
            "status": "ok",
            X: draws[X],
            Y: draws[Y],
            "collision_with": np.where(hit, "aro", "none"),
            "outcome": np.where(hit, "yellow", "green"),
            "near_miss": np.where(hit, "False", "True"),
            "road": np.where(np.arange(n) % 2, "rural", "motorway"),
            "los": "C",
        }
    )


def test_the_csv_is_per_road_level_and_outcome_and_repeats_exactly(tmp_path):
    results = _results(120, 5)
    frame = probability_map(results)
    assert list(frame.columns) == [
        "road", "los", X, Y, "outcome", "p", "p_low", "p_high", "n", "events", "model",
    ]  # fmt: skip
    assert set(frame["outcome"]) == {"contact", "red", "near_miss"}
    assert set(frame["road"]) == {"rural", "motorway"}
    red = frame[frame["outcome"] == "red"]
    assert (red["p"] == 0).all() and red["model"].str.startswith("none (0 of 60)").all()
    path = write_probability_map(tmp_path, frame)
    assert path.name == MAP_FILE
    again = write_probability_map(tmp_path / "again", probability_map(results))
    assert path.read_text() == again.read_text()
