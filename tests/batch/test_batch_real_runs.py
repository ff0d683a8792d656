"""Real co-simulation batches: jobs, Dask, interruption and resume, a broken case, plots.

One small matrix (2 speeds x 2 frictions on the baseline scenario) is run once with one job
as the reference; every other way of running it must give the same results.csv apart from
the timing columns. The lookup tables are built for the test (a small grid around the
matrix's speeds, a few seconds) and found through ``EOAM_TABLES_DIR`` by the batch, its
worker processes, the command-line subprocess and the phase plot.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch.case import run_matrix_case
from eoam_sumo.batch.results import TIMING_COLUMNS
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.colours import OUTCOMES
from eoam_sumo.errors import InputError
from eoam_sumo.offline.build import build_tables
from eoam_sumo.plotting.dispatch import plot_folder
from tests.builders import write_matrix

pytestmark = pytest.mark.sumo
CASES = 4
POLL_LIMIT_S = 600.0  # give up waiting for the first row (a broken build, not a timing check)


def corrupt_one(task):
    """Test-only hook: the 90 km/h, mu 0.3 case runs a corrupted copy of the scenario."""
    case = task.case
    if case.ego_speed_kmh == 90 and case.mu == 0.3:
        broken = Path(task.case_dir) / "broken.sumocfg"
        broken.parent.mkdir(parents=True, exist_ok=True)
        text = case.sumocfg.read_text()
        broken.write_text(text[: len(text) // 2])  # cut in the middle of an element
        task = dataclasses.replace(task, case=dataclasses.replace(case, sumocfg=broken))
    return run_matrix_case(task)


def _write_matrix(folder: Path) -> Path:
    return write_matrix(
        folder / "small.toml",
        "ego_speed_kmh = [120, 90]\nmu = [1.0, 0.3]\n",
        scenario="max_time_s = 25.0\n",
        paper_table=True,
    )


def _stable(results_csv: Path) -> pd.DataFrame:
    frame = pd.read_csv(results_csv, dtype=str, keep_default_na=False)
    return frame.drop(columns=list(TIMING_COLUMNS))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The matrix run once with one job: (matrix path, batch folder, results frame)."""
    root = tmp_path_factory.mktemp("reference")
    tables = build_tables(
        root / "tables", speeds_kmh=[80, 100, 130], mus=[0.3, 1.0], progress=False
    )
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("EOAM_TABLES_DIR", str(tables))
        matrix = _write_matrix(root)
        results = run_batch(matrix, root / "out", jobs=1, progress=False)
        yield matrix, root / "out", results


def test_reference_batch_is_complete_and_consistent(reference):
    _, out, results = reference
    assert len(results) == CASES
    assert (results["status"] == "ok").all(), results["error"].tolist()
    assert set(results["outcome"]) <= set(OUTCOMES)
    # a case cut off by the matrix's short time limit mid-manoeuvre is unfinished, never green
    cut = results[results["outcome"] == "unfinished"]
    assert (cut["end_cause"] == "time_limit").all()
    for _, row in results.iterrows():
        summary = json.loads((out / row["case_dir"] / "summary.json").read_text())
        assert summary["outcome"] == row["outcome"]
        assert summary["case"]["case_id"] == row["case_id"]
        assert row["mu_at_start"] == pytest.approx(row["mu"])
        assert row["ego_initial_speed_mps"] == pytest.approx(row["ego_speed_kmh"] / 3.6)
        ts = pd.read_csv(out / row["case_dir"] / "timeseries.csv")
        assert len(ts) > 100 and ts["mode"].max() >= 1  # a logged run with a manoeuvre
    md = (out / "table2.md").read_text(encoding="utf-8")
    agree = sum(results["outcome"] == results["paper_outcome"])
    assert f"**{agree}/{CASES} cells agree.**" in md


def test_two_jobs_and_a_dask_cluster_give_the_same_results(reference, tmp_path):
    matrix, out, _ = reference
    want = _stable(out / "results.csv")
    run_batch(matrix, tmp_path / "jobs2", jobs=2, progress=False)
    pd.testing.assert_frame_equal(_stable(tmp_path / "jobs2" / "results.csv"), want)
    run_batch(matrix, tmp_path / "dask", jobs=2, scheduler="local", progress=False)
    pd.testing.assert_frame_equal(_stable(tmp_path / "dask" / "results.csv"), want)
    # the Dask workers sent the case files back: same time series as the local run
    for case_dir in want["case_dir"]:
        a = pd.read_csv(out / case_dir / "timeseries.csv")
        b = pd.read_csv(tmp_path / "dask" / case_dir / "timeseries.csv")
        pd.testing.assert_frame_equal(a, b)


def _rows(results_csv: Path) -> int:
    if not results_csv.is_file():
        return 0
    return max(results_csv.read_text().count("\n") - 1, 0)


@pytest.mark.parametrize("how", ["sigterm", "sigkill-group"])
def test_killed_batch_resumes_to_the_same_results(reference, tmp_path, how):
    matrix, out, _ = reference
    batch = tmp_path / "batch"
    cmd = [
        sys.executable,
        "-m",
        "eoam_sumo",
        "batch",
        str(matrix),
        "--out",
        str(batch),
        "--jobs",
        "1",
        "--no-progress",
    ]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    started = time.monotonic()
    while _rows(batch / "results.csv") < 1 and proc.poll() is None:
        assert time.monotonic() - started < POLL_LIMIT_S, "no row was ever written"
        time.sleep(0.02)
    if how == "sigterm":
        proc.send_signal(signal.SIGTERM)  # the batch process only; it stops its workers
    else:
        os.killpg(proc.pid, signal.SIGKILL)  # the batch and its workers, no clean-up at all
    _, stderr = proc.communicate()
    assert proc.returncode == (130 if how == "sigterm" else -signal.SIGKILL), stderr
    done = _rows(batch / "results.csv")
    assert 1 <= done < CASES  # interrupted half-way, the finished rows kept
    assert not (batch / "table2.md").exists()
    run_batch(matrix, batch, jobs=1, resume=True, progress=False)
    pd.testing.assert_frame_equal(_stable(batch / "results.csv"), _stable(out / "results.csv"))


def test_broken_case_is_a_failed_row_and_the_others_complete(reference, tmp_path):
    matrix, out, _ = reference
    results = run_batch(matrix, tmp_path / "b", jobs=2, progress=False, case_func=corrupt_one)
    want = _stable(out / "results.csv")
    got = _stable(tmp_path / "b" / "results.csv")
    broken = got["case_id"] == "onc-none_v90_mu0.3"
    assert got.loc[broken, "status"].item() == "failed"
    assert got.loc[broken, "error"].item() != ""
    assert results.loc[broken.to_numpy(), "outcome"].item() == ""
    pd.testing.assert_frame_equal(got[~broken], want[~broken])


def test_plots_of_a_run_folder_and_a_batch_folder(reference, tmp_path):
    _, out, results = reference
    case_dir = out / results["case_dir"].iloc[0]
    run_pngs = plot_folder(case_dir, tmp_path / "run")
    assert sorted(p.name for p in run_pngs) == [
        "dynamics.png",
        "gg.png",
        "phase_trace.png",
        "steering.png",
        "traffic.png",
    ]
    batch_pngs = plot_folder(out, tmp_path / "batch")
    assert sorted(p.name for p in batch_pngs) == [
        "lateral_offsets_120kmh.png",
        "lateral_offsets_90kmh.png",
        "margins.png",
        "table2.png",
    ]
    tables_pngs = plot_folder(out.parent / "tables", tmp_path / "tables")
    assert tables_pngs
    for png in run_pngs + batch_pngs + tables_pngs:
        assert png.parent.parent == tmp_path
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    with pytest.raises(InputError, match="not a run"):
        plot_folder(tmp_path, tmp_path / "nothing")
