"""The batch engine's bookkeeping with test-only case functions (no SUMO): rows, order,
failures, timeouts and resume. The real co-simulation runs are in test_batch_real_runs.py.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch import runner
from eoam_sumo.batch.results import COLUMNS, TIMING_COLUMNS
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.errors import InputError
from eoam_sumo.plotting.batch_plots import plot_batch_report
from tests.builders import BASELINE, write_matrix


def _fake_summary(case) -> dict:
    """A deterministic summary from the case's parameters."""
    colour = "green" if case.mu >= 0.5 else "yellow"
    return {
        "outcome": colour,
        "collision_with": "none" if colour == "green" else "aro",
        "impact_speed_mps": 0.0 if colour == "green" else round(case.ego_speed_kmh / 10, 3),
        "contact_kind": "none",
        "reason": f"fake run, mu {case.mu}",
        "modes_visited": [0, 1],
        "fcw_raised": True,
        "mu": case.mu,
        "min_gap_aro_m": None,
        "sim_time_s": 12.0,
        "wall_time_s": time.perf_counter() % 1.0,
        "realtime_factor": 1.0 + time.time() % 1.0,
    }


def fake_case(task):
    """Writes its files like the real case function (direct or returned) and counts calls."""
    summary = _fake_summary(task.case)
    files = {
        "summary.json": json.dumps(summary).encode(),
        "timeseries.csv": b"time_s,lateral_offset_m,mode\n0.0,0.0,0\n",
        "traffic.csv": b"time_s,id\n0.0,ego\n",
        "road.csv": b"s_m,x_m,y_m\n0.0,0.0,0.0\n",
    }
    if task.case_dir is None:
        return {"summary": summary, "files": files}
    task.case_dir.mkdir(parents=True, exist_ok=True)
    for name, data in files.items():
        (task.case_dir / name).write_bytes(data)
    with open(task.case_dir / "calls.txt", "a") as fh:
        fh.write("call\n")
    return {"summary": summary, "files": None}


def crash_one(task):
    """Dies in native-crash fashion for the 90 km/h, mu 0.3 case."""
    if task.case.ego_speed_kmh == 90 and task.case.mu == 0.3:
        os._exit(9)
    return fake_case(task)


def hang_one(task):
    if task.case.ego_speed_kmh == 120 and task.case.mu == 1.0:
        time.sleep(600)
    return fake_case(task)


def raise_one(task):
    if task.case.mu == 0.3:
        raise RuntimeError("SUMO said no\nsecond line")
    return fake_case(task)


@pytest.fixture
def matrix(tmp_path):
    return write_matrix(
        tmp_path / "m.toml",
        'ego_speed_kmh = [120, 90]\nmu = [1.0, 0.3]\noncoming_start_m = ["none", 400]\n',
        paper_table=True,
    )


def _stable(path: Path) -> pd.DataFrame:
    frame = pd.read_csv(path, dtype=str, keep_default_na=False)
    return frame.drop(columns=list(TIMING_COLUMNS))


def test_rows_in_matrix_order_whatever_the_jobs(tmp_path, matrix):
    one = run_batch(matrix, tmp_path / "j1", jobs=1, progress=False, case_func=fake_case)
    run_batch(matrix, tmp_path / "j2", jobs=2, progress=False, case_func=fake_case)
    assert list(one["case_id"]) == [
        "onc-none_v120_mu1.0",
        "onc-none_v120_mu0.3",
        "onc-none_v90_mu1.0",
        "onc-none_v90_mu0.3",
        "onc-400_v120_mu1.0",
        "onc-400_v120_mu0.3",
        "onc-400_v90_mu1.0",
        "onc-400_v90_mu0.3",
    ]
    a, b = _stable(tmp_path / "j1" / "results.csv"), _stable(tmp_path / "j2" / "results.csv")
    pd.testing.assert_frame_equal(a, b)
    assert tuple(pd.read_csv(tmp_path / "j1" / "results.csv").columns) == COLUMNS
    row = a.iloc[4]
    assert (row["oncoming_start_m"], row["modes_visited"], row["status"]) == ("400.0", "0-1", "ok")
    assert a.iloc[0]["oncoming_start_m"] == ""  # no oncoming car: empty
    # the paper's colours from the matrix's [paper] table
    assert list(a["paper_outcome"]) == [
        "green",
        "green",
        "green",
        "green",
        "green",
        "orange",
        "orange",
        "yellow",
    ]
    assert (tmp_path / "j2" / "cases" / "onc-400_v90_mu0.3" / "summary.json").is_file()
    assert (tmp_path / "j2" / "table2.md").is_file()
    assert not (tmp_path / "j2" / "table2.png").exists()  # the engine draws nothing
    images = plot_batch_report(one, tmp_path / "j1")  # what `eoam-sumo batch` draws
    assert [p.name for p in images] == ["table2.png", "margins.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in images)


def test_crash_and_exception_are_failed_rows_and_the_rest_complete(tmp_path, matrix):
    res = run_batch(matrix, tmp_path / "c", jobs=2, progress=False, case_func=crash_one)
    failed = res[res["status"] == "failed"]
    assert list(failed["case_id"]) == ["onc-none_v90_mu0.3", "onc-400_v90_mu0.3"]
    assert all(e == "worker process died (exit status 9)" for e in failed["error"])
    assert failed["outcome"].eq("").all()
    assert (res["status"] == "ok").sum() == 6
    res = run_batch(matrix, tmp_path / "e", jobs=1, progress=False, case_func=raise_one)
    failed = res[res["status"] == "failed"]
    assert len(failed) == 4
    assert set(failed["error"]) == {"RuntimeError: SUMO said no | second line"}
    md = (tmp_path / "e" / "table2.md").read_text(encoding="utf-8")
    assert "failed: RuntimeError: SUMO said no | second line" in md


def test_a_case_past_its_timeout_is_killed_and_recorded(tmp_path, matrix):
    res = run_batch(
        matrix, tmp_path / "t", jobs=2, timeout_s=10.0, progress=False, case_func=hang_one
    )
    failed = res[res["status"] == "failed"].set_index("case_id")["error"]
    assert dict(failed) == dict.fromkeys(
        ("onc-none_v120_mu1.0", "onc-400_v120_mu1.0"), "timed out after 10 s (worker killed)"
    )
    assert (res["status"] == "ok").sum() == 6


def test_resume_reruns_only_failed_and_missing_cases(tmp_path, matrix):
    ref = run_batch(matrix, tmp_path / "ref", jobs=1, progress=False, case_func=fake_case)
    out = tmp_path / "r"
    run_batch(matrix, out, jobs=2, progress=False, case_func=crash_one)
    # an interrupted batch: rows out of order, one row missing, the last one cut short
    lines = (out / "results.csv").read_text().splitlines(keepends=True)
    header, rows = lines[0], lines[1:]
    kept = [rows[5], rows[0], rows[3], rows[2], rows[1][: len(rows[1]) // 2]]
    (out / "results.csv").write_text(header + "".join(kept))
    res = run_batch(matrix, out, jobs=2, resume=True, progress=False, case_func=fake_case)
    pd.testing.assert_frame_equal(
        _stable(out / "results.csv"), _stable(tmp_path / "ref" / "results.csv")
    )
    assert (res["status"] == "ok").all()
    calls = {
        cid: (out / "cases" / cid / "calls.txt").read_text().count("call") for cid in ref["case_id"]
    }
    # rows 0, 2, 5 were kept: one call. Rows 1 (cut short), 4, 6 (missing) ran again: two.
    # Rows 3 and 7 had crashed before counting their first call: one, from the resume.
    ids = list(ref["case_id"])
    assert calls == {cid: 2 if i in (1, 4, 6) else 1 for i, cid in enumerate(ids)}


def test_dask_local_cluster_gives_the_same_results(tmp_path, matrix):
    run_batch(matrix, tmp_path / "j1", jobs=1, progress=False, case_func=fake_case)
    run_batch(
        matrix, tmp_path / "dask", jobs=2, scheduler="local", progress=False, case_func=crash_one
    )
    a = _stable(tmp_path / "j1" / "results.csv")
    b = _stable(tmp_path / "dask" / "results.csv")
    crashed = b["status"] == "failed"
    assert list(b.loc[crashed, "case_id"]) == ["onc-none_v90_mu0.3", "onc-400_v90_mu0.3"]
    pd.testing.assert_frame_equal(a[~crashed], b[~crashed])
    # files came back through Dask and were written on this side
    case_dir = tmp_path / "dask" / "cases" / "onc-none_v120_mu1.0"
    assert json.loads((case_dir / "summary.json").read_text())["outcome"] == "green"


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"jobs": 0}, "--jobs"),
        ({"timeout_s": 0.0}, "--timeout-s"),
        ({"scheduler": "tcp://127.0.0.1:9"}, "cannot connect to the Dask scheduler"),
    ],
)
def test_bad_settings_are_input_errors(tmp_path, matrix, kwargs, message, monkeypatch):
    monkeypatch.setattr(runner, "DASK_CONNECT_TIMEOUT_S", 1.0)
    with pytest.raises(InputError, match=message):
        run_batch(matrix, tmp_path / "x", progress=False, case_func=fake_case, **kwargs)


@pytest.mark.parametrize("change", ["radar_range_m = 300.0\n", "max_time_s = 50.0\n"])
def test_resume_reruns_cases_whose_scenario_settings_changed(tmp_path, matrix, change):
    """Same case ids but another radar range or time limit: the old rows are not kept."""
    out = tmp_path / "r"
    run_batch(matrix, out, jobs=1, progress=False, case_func=fake_case)
    changed = tmp_path / "changed.toml"
    changed.write_text(matrix.read_text().replace("[sweep]\n", change + "[sweep]\n", 1))
    run_batch(changed, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    calls = [
        len((p / "calls.txt").read_text().splitlines()) for p in sorted((out / "cases").iterdir())
    ]
    assert calls == [2] * 8  # every case ran again
    key, value = change.strip().split(" = ")
    assert set(pd.read_csv(out / "results.csv")[key]) == {float(value)}
    run_batch(changed, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    assert [
        len((p / "calls.txt").read_text().splitlines()) for p in sorted((out / "cases").iterdir())
    ] == [2] * 8  # now all kept


def test_meanwhile_runs_once_before_the_batch_returns_and_its_error_is_not_the_batch_s(
    tmp_path, matrix
):
    """``meanwhile`` runs exactly once, done by the time run_batch returns; an exception in
    it leaves the results as they would be."""
    calls = []

    def task():
        calls.append(1)
        raise RuntimeError("nothing to import")

    res = run_batch(
        matrix, tmp_path / "m", jobs=1, progress=False, case_func=fake_case, meanwhile=task
    )
    assert calls == [1]
    assert (res["status"] == "ok").all()


def _scenario_copy(folder: Path) -> Path:
    """The baseline scenario's files copied into ``folder`` (its sumocfg's paths kept)."""
    for name in ("scenarios", "networks"):
        (folder / name).mkdir(parents=True, exist_ok=True)
    for src in BASELINE.parent.glob("*.xml"):
        (folder / "scenarios" / src.name).write_bytes(src.read_bytes())
    for src in (BASELINE.parent.parent / "networks").glob("highway*.xml"):
        (folder / "networks" / src.name).write_bytes(src.read_bytes())
    cfg = folder / "scenarios" / BASELINE.name
    cfg.write_bytes(BASELINE.read_bytes())
    return cfg


def _calls(out: Path) -> list[int]:
    return [
        len((p / "calls.txt").read_text().splitlines()) for p in sorted((out / "cases").iterdir())
    ]


@pytest.mark.parametrize("edited", ["baseline.rou.xml", "vtypes.add.xml", "baseline.sumocfg"])
def test_resume_reruns_cases_whose_scenario_files_changed(tmp_path, edited):
    """A file the sumocfg names edited after the run: resumed, every case runs again (the
    row's ``inputs_sha256`` no longer matches), then no more."""
    cfg = _scenario_copy(tmp_path / "a")
    sweep = "ego_speed_kmh = [120, 90]\nmu = [1.0]\n"
    matrix = write_matrix(tmp_path / "a" / "m.toml", sweep, sumocfg=cfg)
    out = tmp_path / "out"
    run_batch(matrix, out, jobs=1, progress=False, case_func=fake_case)
    digests = set(pd.read_csv(out / "results.csv")["inputs_sha256"])
    assert len(digests) == 1 and len(digests.pop()) == 64
    run_batch(matrix, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    assert _calls(out) == [1, 1]  # the same files: kept
    path = cfg.parent / edited
    path.write_bytes(path.read_bytes().replace(b"<!--", b"<!-- edited", 1) + b"\n")
    run_batch(matrix, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    assert _calls(out) == [2, 2]
    run_batch(matrix, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    assert _calls(out) == [2, 2]  # the rows now hold the edited files' digest


def test_resume_with_another_timeseries_format_reruns_the_cases_without_it(tmp_path, matrix):
    """Resumed with ``--timeseries csv`` over a batch run with ``none``, the cases that have
    no time series run again (they were kept: a folder of mixed formats, some cases not
    plottable); resumed with ``none`` over csv cases, they are kept."""
    out = tmp_path / "t"
    run_batch(matrix, out, jobs=1, progress=False, case_func=fake_case, timeseries="none")
    for case in (out / "cases").iterdir():  # what a --timeseries none case holds
        for name in ("timeseries.csv", "traffic.csv", "road.csv"):
            (case / name).unlink()
    run_batch(matrix, out, jobs=1, resume=True, progress=False, case_func=fake_case)
    assert _calls(out) == [2] * 8
    run_batch(
        matrix, out, jobs=1, resume=True, progress=False, case_func=fake_case, timeseries="none"
    )
    assert _calls(out) == [2] * 8
