"""`eoam-sumo batch` exit status on real co-simulations: 0 when every case ran, 1 when at
least one failed (results.csv and the report, images included, still written), the failed
count last on stderr.

A case fails at run time here because its oncoming car would start beyond the end of the
ego's road (4 km): a per-case error the matrix check cannot see without starting SUMO.
"""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.batch.results import RESULTS_FILE
from eoam_sumo.batch.runner import EXIT_CASES_FAILED
from eoam_sumo.cli import main
from tests.builders import write_matrix

pytestmark = pytest.mark.sumo


@pytest.mark.parametrize(
    "oncoming, status, failed",
    [
        ('["none"]', 0, 0),
        ('["none", 5000]', EXIT_CASES_FAILED, 1),
        ("[5000]", EXIT_CASES_FAILED, 1),  # every case failed
    ],
)
def test_exit_status_counts_failed_cases(capsys, tmp_path, monkeypatch, oncoming, status, failed):
    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)  # the repository's tables
    matrix = write_matrix(
        tmp_path / "m.toml",
        f"ego_speed_kmh = [90]\nmu = [1.0]\noncoming_start_m = {oncoming}\n",
        scenario="max_time_s = 5.0\n",
    )
    out = tmp_path / "out"
    got = main(["batch", str(matrix), "--out", str(out), "--no-progress"])
    captured = capsys.readouterr()
    assert got == status, captured.err
    results = pd.read_csv(out / RESULTS_FILE, dtype=str, keep_default_na=False)
    cases = oncoming.count(",") + 1
    assert len(results) == cases
    assert (results["status"] == "failed").sum() == failed
    assert (out / "table2.md").is_file()
    for image in ("table2.png", "margins.png"):  # drawn by the command from the results
        assert (out / image).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ok = results[results["status"] == "ok"]
    assert (ok["outcome"] != "").all()
    for case_dir in ok["case_dir"]:
        assert (out / case_dir / "summary.json").is_file()
    assert f"{cases} cases, {cases - failed} ok, {failed} failed" in captured.out
    assert "Traceback" not in captured.err
    if failed:
        bad = results[results["status"] == "failed"]
        assert bad["error"].str.contains("oncoming_start_m=5000").all()
        lines = captured.err.splitlines()
        assert lines[-1] == (
            f"eoam-sumo: {failed} of {cases} cases failed; their errors are in "
            f"the 'error' column of {out / RESULTS_FILE}"
        )
        assert f"failed: {bad['case_id'].iloc[0]}: InputError" in captured.err
    else:
        assert captured.err == ""
