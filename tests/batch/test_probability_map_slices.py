"""One probability map per combination of the settings that vary, but the map's own axes and
the scenario values a study draws: two policies' draws are never one fit (the review's
sampled batch over paper and safe)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from eoam_sumo.batch.probability_map import X, Y, probability_map, slice_columns

DRAWS = 15


def _draws(groups: dict[str, dict], seed: int = 7, **sampled) -> pd.DataFrame:
    """``DRAWS`` fabricated draws per group (its swept values), speed and friction uniform,
    ``sampled`` columns drawn per draw from their choices; contacts more likely fast and on
    low friction, red only in a group whose ``red`` is set."""
    rng = np.random.default_rng(seed)
    frames = []
    for group, values in groups.items():
        speed, mu = rng.uniform(90, 165, DRAWS), rng.uniform(0.1, 1.0, DRAWS)
        hit = rng.uniform(size=DRAWS) < 1 / (1 + np.exp(-(0.05 * (speed - 125) - 3 * (mu - 0.5))))
        red = hit & values.pop("red", False)
        frame = pd.DataFrame(
            {
                "case_id": [f"{group}_d{k}" for k in range(DRAWS)],
                X: speed,
                Y: mu,
                "status": "ok",
                "collision_with": np.where(hit, "oncoming", "none"),
                "outcome": np.where(red, "red", np.where(hit, "yellow", "green")),
                "near_miss": "False",
                "oncoming_start_m": rng.choice([300.0, 400.0], DRAWS),
                **values,
            }
        )
        for column, choices in sampled.items():
            frame[column] = rng.choice(choices, DRAWS)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def _fits(frame: pd.DataFrame, outcome: str) -> pd.DataFrame:
    """One row per fit of ``outcome``: its slice's columns, n and events."""
    chosen = frame[frame["outcome"] == outcome]
    keys = [c for c in chosen.columns if c not in (X, Y, "p", "p_low", "p_high", "model")]
    return chosen[keys].drop_duplicates().reset_index(drop=True)


def test_two_policies_get_a_map_each():
    results = _draws({"paper": {"policy": "paper", "red": True}, "safe": {"policy": "safe"}})
    frame = probability_map(results)
    assert list(frame.columns[:3]) == ["policy", X, Y]
    for outcome in ("contact", "red"):
        fits = _fits(frame, outcome).set_index("policy")
        assert list(fits.index) == ["paper", "safe"] and (fits["n"] == DRAWS).all()
        for policy, draws in results.groupby("policy"):
            events = draws["collision_with"] != "none" if outcome == "contact" else None
            events = draws["outcome"] == "red" if events is None else events
            assert fits.loc[policy, "events"] == int(events.sum())
    assert _fits(frame, "red").set_index("policy").loc["safe", "events"] == 0


def test_a_drawn_scenario_value_is_pooled_and_a_swept_one_is_not():
    """The sampled oncoming distance (a choice per draw) is one of the map's uncertain
    inputs; swept (a value per group), each value is a map of its own."""
    drawn = _draws({"g": {}})
    assert slice_columns(drawn) == [] and probability_map(drawn)["n"].eq(DRAWS).all()
    swept = _draws({"onc-300": {}, "onc-400": {}})
    swept["oncoming_start_m"] = np.where(swept["case_id"].str.startswith("onc-300"), 300.0, 400.0)
    fits = _fits(probability_map(swept), "contact")
    assert list(fits["oncoming_start_m"]) == [300.0, 400.0] and (fits["n"] == DRAWS).all()


def test_a_drawn_choice_of_systems_is_split_and_a_continuous_draw_pooled():
    """mu_belief known or estimate (two systems) gets a map each; a normal draw of the
    believed friction (a value per draw) is pooled."""
    choice = _draws({"g": {}, "h": {}}, mu_belief=["known", "estimate"], radar_model=["ideal"])
    assert slice_columns(choice) == ["mu_belief"]
    fits = _fits(probability_map(choice), "contact")
    assert sorted(fits["mu_belief"]) == ["estimate", "known"] and fits["n"].sum() == 2 * DRAWS
    continuous = _draws({"g": {}, "h": {}})
    continuous["mu_belief"] = np.linspace(0.3, 1.0, len(continuous))
    assert slice_columns(continuous) == []


def test_road_and_level_stay_columns_and_a_driver_splits_them():
    results = _draws(
        {
            "rural_A_eoam": {"road": "rural", "los": "A", "driver": "eoam"},
            "rural_A_cc": {"road": "rural", "los": "A", "driver": "r157-cc"},
        }
    )
    frame = probability_map(results)
    assert list(frame.columns[:3]) == ["driver", "road", "los"]
    assert list(_fits(frame, "contact")["driver"]) == ["eoam", "r157-cc"]


def test_unfinished_draws_are_neither_events_nor_non_events():
    """A draw cut off at the time limit before anything was decided says nothing of how it
    would have ended: left out of n as a failed draw is (it counted as a draw without a
    contact, a map biased low)."""
    results = _draws({"paper": {"policy": "paper"}})
    cut = results.index[:4]
    results.loc[cut, "outcome"] = "unfinished"
    results.loc[cut, "collision_with"] = "none"
    results.loc[results.index[4], "status"] = "failed"
    frame = probability_map(results)
    kept = results.drop(index=[*cut, results.index[4]])
    contact = frame[frame["outcome"] == "contact"]
    assert (contact["n"] == len(kept)).all()
    assert (contact["events"] == int((kept["collision_with"] != "none").sum())).all()


def test_outcome_probabilities_name_the_swept_settings_of_each_group():
    """outcome_probabilities.csv holds every parameter constant within each group: a swept
    policy or driver too (the groups were told apart by their names only)."""
    from eoam_sumo.batch.probabilities import outcome_probabilities

    results = _draws({"paper": {"policy": "paper"}, "safe": {"policy": "safe"}})
    results["case_id"] = [f"{p}_v120_mu0.3_d{k % DRAWS}" for k, p in enumerate(results["policy"])]
    results["driver"] = "eoam"
    table = outcome_probabilities(results)
    assert {"policy", "driver"} <= set(table.columns)
    assert set(zip(table["group"], table["policy"])) == {
        ("paper_v120_mu0.3", "paper"),
        ("safe_v120_mu0.3", "safe"),
    }
