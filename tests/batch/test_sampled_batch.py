"""A sampled matrix run for real: same seed, same results.csv; no time series with
--timeseries none; outcome probabilities inside their intervals, summing to 1 per group;
parquet time series equal to the csv ones."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from eoam_sumo.batch.results import RESULTS_FILE, TIMING_COLUMNS, read_results
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.cli import main

pytestmark = pytest.mark.sumo

REPO = Path(__file__).resolve().parents[2]
MATRIX = f"""
[scenario]
sumocfg = "{REPO / "scenarios" / "baseline.sumocfg"}"
max_time_s = 20.0
radar_model = "automotive"

[sweep]
ego_speed_kmh = [90]
mu = [0.7, 0.3]

[sample]
draws = 3
seed = 5
oncoming_start_m = {{ uniform = [250, 450] }}
mu_belief = {{ choice = ["known", 1.0] }}
"""


def _run(tmp_path: Path, name: str, timeseries: str, scheduler: str | None = None):
    """The matrix through ``eoam-sumo batch`` (the engine, then the images)."""
    matrix = tmp_path / "sampled.toml"
    matrix.write_text(MATRIX)
    out = tmp_path / name
    args = ["batch", str(matrix), "--out", str(out), "--jobs", "2", "--no-progress"]
    args += ["--timeseries", timeseries] + (["--scheduler", scheduler] if scheduler else [])
    assert main(args) == 0
    return read_results(out / RESULTS_FILE), out


def test_sampled_matrix_is_reproducible_and_its_probabilities_are_consistent(tmp_path):
    """Twice with the same seed, the second time on a Dask cluster (--scheduler local):
    the same results.csv, timing columns aside."""
    first, out1 = _run(tmp_path, "a", "none")
    _, out2 = _run(tmp_path, "b", "none", scheduler="local")
    assert len(first) == 6 and (first["status"] == "ok").all()
    assert first["draw"].tolist() == [0, 1, 2, 0, 1, 2]
    assert first["oncoming_start_m"].between(250, 450).all()
    assert set(first["mu_belief"]) <= {"known", "1.0"}
    assert first["seed"].nunique() == 6 and (first["radar_model"] == "automotive").all()
    a, b = (
        pd.read_csv(out / "results.csv", dtype=str, keep_default_na=False).drop(
            columns=list(TIMING_COLUMNS)
        )
        for out in (out1, out2)
    )
    pd.testing.assert_frame_equal(a, b)
    # --timeseries none: summaries only
    for case_dir in first["case_dir"]:
        assert sorted(p.name for p in (out1 / case_dir).iterdir()) == ["summary.json"]
    assert not list(out1.rglob("timeseries.*")) and not list(out2.rglob("timeseries.*"))
    # outcome probabilities: per group of swept values, within their intervals, sum to 1
    probs = pd.read_csv(out1 / "outcome_probabilities.csv")
    assert list(probs.columns[-6:]) == ["outcome", "count", "n", "p", "ci_low", "ci_high"]
    assert set(probs["group"]) == {"v90_mu0.7", "v90_mu0.3"}
    assert ((probs["ci_low"] <= probs["p"]) & (probs["p"] <= probs["ci_high"])).all()
    for _, group in probs.groupby("group"):
        assert group["p"].sum() == pytest.approx(1.0, abs=1e-12)
        assert group["count"].sum() == 3 and (group["n"] == 3).all()
    observed = first.groupby(first["case_id"].str[:-3])["outcome"].value_counts()
    for (group, outcome), count in observed.items():
        row = probs[(probs["group"] == group) & (probs["outcome"] == outcome)]
        assert int(row["count"].iloc[0]) == count
    assert (out1 / "envelope.png").stat().st_size > 10_000
    assert not (out1 / "table2.md").exists() and not (out1 / "table2.png").exists()


def test_parquet_time_series_equal_the_csv_ones(tmp_path):
    pytest.importorskip("pyarrow")
    matrix = tmp_path / "one.toml"
    matrix.write_text(
        MATRIX.replace("draws = 3", "draws = 1").replace("mu = [0.7, 0.3]", "mu = [0.3]")
    )
    csv_out, pq_out = tmp_path / "csv", tmp_path / "pq"
    run_batch(matrix, csv_out, progress=False, timeseries="csv")
    results = run_batch(matrix, pq_out, progress=False, timeseries="parquet")
    case_dir = results["case_dir"].iloc[0]
    from_csv = pd.read_csv(csv_out / case_dir / "timeseries.csv")
    from_pq = pd.read_parquet(pq_out / case_dir / "timeseries.parquet")
    assert list(from_pq.columns) == list(from_csv.columns)
    for column in from_csv.columns:
        if column == "sector":
            assert from_pq[column].fillna("").tolist() == from_csv[column].fillna("").tolist()
        else:  # the csv keeps 9 significant digits
            np.testing.assert_allclose(
                from_pq[column].astype(float), from_csv[column], rtol=1e-8, atol=1e-12
            )
    assert not (pq_out / case_dir / "timeseries.csv").exists()


def test_plot_draws_a_sampled_batch_from_its_own_draws(tmp_path):
    """After --resume with fewer draws, results.csv keeps the larger matrix's extra draws
    behind the batch's own; plot counted them all (12 draws where the batch had 3)."""
    import pandas as pd

    from eoam_sumo.batch.probabilities import PROBABILITIES_FILE
    from eoam_sumo.plotting.batch_plots import _batch_rows

    ids = [f"v120_mu0.7_d{k}" for k in range(3)] + [f"v120_mu0.7_d{k}" for k in range(3, 6)]
    results = pd.DataFrame({"case_id": ids, "draw": range(6), "status": "ok"})
    (tmp_path / PROBABILITIES_FILE).write_text("group,outcome,n\nv120_mu0.7,green,3\n")
    assert list(_batch_rows(tmp_path, results)["case_id"]) == ids[:3]
    (tmp_path / PROBABILITIES_FILE).unlink()
    assert len(_batch_rows(tmp_path, results)) == 6


def test_run_with_a_row_s_values_repeats_its_draw(tmp_path):
    """docs/monte-carlo.md: ``eoam-sumo run ... --seed N`` with the row's values repeats one
    draw, the obstacle's drawn hold and deceleration included (``--aro-hold-s``,
    ``--aro-decel-mps2``: without them a draw of monte_carlo.toml could not be repeated)."""
    matrix = tmp_path / "m.toml"
    matrix.write_text(
        MATRIX.replace("mu = [0.7, 0.3]", "mu = [0.7]")
        .replace("draws = 3", "draws = 1")
        .replace(
            'mu_belief = { choice = ["known", 1.0] }',
            "aro_hold_s = { uniform = [1.0, 3.0] }\naro_decel_mps2 = { uniform = [5.0, 9.0] }",
        )
    )
    out = tmp_path / "b"
    assert (
        main(["batch", str(matrix), "--out", str(out), "--no-progress", "--timeseries", "none"])
        == 0
    )
    row = read_results(out / RESULTS_FILE).iloc[0]
    argv = ["run", str(REPO / "scenarios" / "baseline.sumocfg"), "--out", str(tmp_path / "r")]
    argv += ["--speed-kmh", repr(float(row["ego_speed_kmh"])), "--mu", repr(float(row["mu"]))]
    argv += ["--oncoming-m", repr(float(row["oncoming_start_m"])), "--seed", str(int(row["seed"]))]
    argv += [
        "--aro-hold-s",
        repr(float(row["aro_hold_s"])),
        "--aro-decel-mps2",
        repr(float(row["aro_decel_mps2"])),
    ]
    argv += [
        "--radar-model",
        "automotive",
        "--max-time-s",
        "20",
        "--sumo-step-s",
        repr(float(row["sumo_step_s"])),
    ]
    assert main(argv) == 0
    run = json.loads((tmp_path / "r" / "summary.json").read_text())
    for key in ("outcome", "collision_with", "impact_speed_mps", "trigger_time_s", "min_gap_aro_m"):
        assert run[key] == (None if pd.isna(row[key]) else row[key]), key
