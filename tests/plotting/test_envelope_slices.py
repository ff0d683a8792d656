"""envelope.png draws a row of panels per slice of the probability map and outcome, named by
the slice's settings (two policies' draws are never one panel)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from eoam_sumo.plotting import envelope_plots

DRAWS = 15


def _two_policies() -> pd.DataFrame:
    rng = np.random.default_rng(3)
    n = 2 * DRAWS
    speed, mu = rng.uniform(90, 165, n), rng.uniform(0.1, 1.0, n)
    hit = rng.uniform(size=n) < 1 / (1 + np.exp(-(0.05 * (speed - 125) - 3 * (mu - 0.5))))
    policy = np.repeat(["paper", "safe"], DRAWS)
    return pd.DataFrame(
        {
            "case_id": [f"{p}_d{k % DRAWS}" for k, p in enumerate(policy)],
            "policy": policy,
            "ego_speed_kmh": speed,
            "mu": mu,
            "status": "ok",
            "collision_with": np.where(hit, "oncoming", "none"),
            "outcome": np.where(hit & (policy == "paper"), "red", np.where(hit, "yellow", "green")),
            "near_miss": "False",
        }
    )


def test_a_row_per_policy_and_outcome(monkeypatch, tmp_path):
    drawn = []

    def keep(rows, notes, title, path):
        drawn.append(rows)
        return path

    monkeypatch.setattr(envelope_plots, "_figure", keep)
    envelope_plots.plot_envelopes(_two_policies(), tmp_path)
    (rows,) = drawn
    named = [(name, outcome, len(draws), set(fitted["n"])) for name, draws, outcome, fitted in rows]
    assert named == [
        ("paper policy: ", "contact", DRAWS, {DRAWS}),
        ("safe policy: ", "contact", DRAWS, {DRAWS}),
        ("paper policy: ", "red", DRAWS, {DRAWS}),
        ("safe policy: ", "red", DRAWS, {DRAWS}),
    ]
    for name, draws, _, fitted in rows:
        assert set(draws["policy"]) == set(fitted["policy"]) == {name.split()[0]}
