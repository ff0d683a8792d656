"""Nothing lost: a batch, protocol or scenario folder is written by one process at
a time; a re-run replaces a finished folder only once complete; ``--resume`` keeps every
finished row; ``tables`` never writes over another vehicle's tables; unwritable outputs are
one line. Each case compares the folder before and after."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch import runner
from eoam_sumo.cli import main
from eoam_sumo.outputs.lock import locked
from tests.batch.test_batch_runner import fake_case
from tests.builders import write_matrix
from tests.outputs.test_output_folders import snapshot

ROOT = Path(__file__).resolve().parents[1]
SWEEP = 'ego_speed_kmh = [120, 90]\nmu = [1.0, 0.3]\noncoming_start_m = ["none", 400]\n'


def _one_line(capsys, status: int, *needles: str) -> str:
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert status == 2, err
    assert len(lines) == 1 and all(n in lines[0] for n in needles), err
    return lines[0]


def _leftovers(out: Path) -> list[str]:
    """Staging or set-aside folders of ``out`` left beside it."""
    return sorted(p.name for p in out.parent.glob(f"{out.name}.*"))


@pytest.fixture
def fake_batches(monkeypatch):
    """``eoam-sumo batch`` with the test case function (no SUMO)."""
    real = runner.run_batch
    monkeypatch.setattr(
        runner, "run_batch", lambda *a, **k: real(*a, **{**k, "case_func": fake_case})
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["batch", "MATRIX", "--no-progress"],
        ["protocol", "unr152", "--points", "stationary_v30", "--no-progress"],
        ["scenario", "rural", "--los", "A"],
    ],
)
def test_a_second_writer_is_refused_in_one_line(tmp_path, capsys, argv):
    out = tmp_path / "out"
    matrix = write_matrix(tmp_path / "m.toml", SWEEP)
    (out / "cases").mkdir(parents=True)
    (out / "results.csv").write_text("earlier\n")
    before = snapshot(out)
    argv = [str(matrix) if a == "MATRIX" else a for a in argv]
    with locked(out):
        status = main([*argv, "--out", str(out)])
    _one_line(capsys, status, str(out), f"process {os.getpid()}")
    assert snapshot(out) == before and _leftovers(out) == []


def test_an_interrupted_batch_rerun_leaves_the_finished_folder(
    tmp_path, capsys, monkeypatch, fake_batches
):
    matrix = write_matrix(tmp_path / "m.toml", SWEEP, paper_table=True)
    out = tmp_path / "out"
    assert main(["batch", str(matrix), "--out", str(out), "--no-progress"]) == 0
    before = snapshot(out)
    assert len(pd.read_csv(out / "results.csv")) == 8
    record = runner._record

    def interrupted(*args):
        record(*args)
        raise KeyboardInterrupt  # Ctrl-C once the new run has finished a case

    monkeypatch.setattr(runner, "_record", interrupted)
    assert main(["batch", str(matrix), "--out", str(out), "--no-progress"]) == 130
    assert snapshot(out) == before and _leftovers(out) == []
    monkeypatch.setattr(runner, "_record", record)
    smaller = write_matrix(tmp_path / "s.toml", "ego_speed_kmh = [120]\nmu = [1.0]\n")
    assert main(["batch", str(smaller), "--out", str(out), "--no-progress"]) == 0
    assert list(pd.read_csv(out / "results.csv")["case_id"]) == ["onc-none_v120_mu1.0"]
    assert not (out / "cases" / "onc-400_v90_mu0.3").exists() and _leftovers(out) == []


def test_resume_with_a_smaller_matrix_keeps_every_finished_row(tmp_path):
    matrix = write_matrix(tmp_path / "m.toml", SWEEP, paper_table=True)
    out = tmp_path / "out"
    first = runner.run_batch(matrix, out, progress=False, case_func=fake_case)
    rows = pd.read_csv(out / "results.csv", dtype=str, keep_default_na=False)
    smaller = write_matrix(
        tmp_path / "s.toml",
        'ego_speed_kmh = [120]\nmu = [1.0, 0.5]\noncoming_start_m = ["none"]\n',
        paper_table=True,
    )
    res = runner.run_batch(smaller, out, resume=True, progress=False, case_func=fake_case)
    assert list(res["case_id"]) == ["onc-none_v120_mu1.0", "onc-none_v120_mu0.5"]
    after = pd.read_csv(out / "results.csv", dtype=str, keep_default_na=False)
    assert list(after["case_id"]) == [
        "onc-none_v120_mu1.0",
        "onc-none_v120_mu0.5",
        *[c for c in first["case_id"] if c != "onc-none_v120_mu1.0"],
    ]
    kept = after.set_index("case_id").loc[rows["case_id"]].reset_index()
    pd.testing.assert_frame_equal(kept[rows.columns], rows)  # every earlier row as it was


def _tables_of(folder: Path, source: Path) -> dict[str, bytes]:
    folder.mkdir(parents=True)
    shutil.copy(source / "metadata.json", folder / "metadata.json")
    return snapshot(folder)


def test_tables_never_write_over_another_vehicles(tmp_path, capsys, monkeypatch):
    mine = tmp_path / "sedan.toml"  # a user's file named as the catalogue's sedan
    text = (ROOT / "vehicles" / "sedan.toml").read_text()
    mine.write_text(text.replace("value = 1723.0", "value = 1800.0", 1))
    base = tmp_path / "tables"
    monkeypatch.setenv("EOAM_TABLES_DIR", str(base))
    sedan = _tables_of(base, ROOT / "tables")
    # the default folder of a file named as a catalogue vehicle is its own: tables/sedan-file
    suv = _tables_of(base / "sedan-file", ROOT / "tables" / "suv")
    fast = ["--speeds-kmh", "60", "--mu", "1.0", "--no-progress"]
    status = main(["tables", "--vehicle", str(mine), *fast])
    _one_line(capsys, status, str(base / "sedan-file"), "Cadillac SRX", "--overwrite")
    status = main(["tables", "--vehicle", str(mine), "--out", str(base), *fast])
    _one_line(capsys, status, str(base), "not of 'E-class sedan'")
    assert snapshot(base) == {
        **sedan,
        **{f"sedan-file/{k}": v for k, v in suv.items()},
    }


@pytest.mark.parametrize("command", [["scenario", "rural", "--los", "A"], ["protocol", "unr152"]])
def test_unwritable_outputs_are_one_line(tmp_path, capsys, command):
    (tmp_path / "file").write_text("mine\n")
    for out in (tmp_path / "file", Path("/proc/eoam-x")):
        _one_line(capsys, main([*command, "--out", str(out)]), str(out), "cannot be written")
    assert (tmp_path / "file").read_text() == "mine\n"


def test_a_summary_that_is_a_folder_is_one_line_and_leaves_no_temporary_file(tmp_path, capsys):
    (tmp_path / "summary.json").mkdir()
    status = main(["vehicle-test", "brake", "--vehicle", "sedan", "--out", str(tmp_path)])
    _one_line(capsys, status, str(tmp_path / "summary.json"), "cannot be written")
    assert not list(tmp_path.glob("*.tmp"))


def _protocol(out: Path, *extra: str) -> list[str]:
    return [
        sys.executable,
        "-m",
        "eoam_sumo",
        "protocol",
        "unr152",
        "--points",
        "R152mstationary_v(20|25|30|35)",
        "--no-progress",
        "--out",
        str(out),
        *extra,
    ]


@pytest.mark.sumo
def test_an_interrupted_protocol_rerun_leaves_the_finished_folder(tmp_path):
    out = tmp_path / "out"
    subprocess.run(_protocol(out), check=True, capture_output=True)
    before = snapshot(out)
    # Ctrl-C as from a terminal: a suite started in the background ignores SIGINT, and the
    # rerun would inherit that and run to its end; it gets Python's own handler
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        rerun = subprocess.Popen(_protocol(out, "--mu", "0.3"), stderr=subprocess.PIPE, text=True)
    finally:
        signal.signal(signal.SIGINT, previous)
    # Ctrl-C once the new run has started writing (its results file made, no case finished)
    while rerun.poll() is None and not list(tmp_path.glob("out.partial-*/batch/results.csv")):
        time.sleep(0.02)
    rerun.send_signal(signal.SIGINT)
    _, err = rerun.communicate(timeout=120)
    assert rerun.returncode == 130, err
    assert snapshot(out) == before and _leftovers(out) == []
    frame = pd.read_csv(out / "results.csv")
    assert len(frame) == 4 and (frame["mu_at_start"] == 1.0).all()


@pytest.mark.sumo
def test_a_scenario_rerun_replaces_the_folder_whole_or_not_at_all(tmp_path, capsys, monkeypatch):
    from eoam_sumo.traffic_levels import build

    out = tmp_path / "scn"
    curved = ["scenario", "rural", "--los", "A", "--curve-radius-m", "500"]
    assert main(["scenario", "rural", "--los", "A", "--out", str(out)]) == 0
    before = snapshot(out)

    def interrupted(*args):
        raise KeyboardInterrupt  # Ctrl-C once the new network is written

    with monkeypatch.context() as patch:
        patch.setattr(build, "settled_traffic", interrupted)
        assert main([*curved, "--out", str(out)]) == 130
    assert snapshot(out) == before and _leftovers(out) == []  # not a new road with old routes
    assert main([*curved, "--out", str(out)]) == 0
    assert json.loads((out / "scenario.json").read_text())["spec"]["curve_radius_m"] == 500
    assert snapshot(out) != before and _leftovers(out) == []
    capsys.readouterr()


def test_a_run_of_a_file_that_is_no_scenario_writes_nothing(tmp_path, capsys):
    """A text file given as the sumocfg was refused only after ``--out`` had been made; a
    folder was "no such scenario file"."""
    text = tmp_path / "notes.txt"
    text.write_text("hello\n", encoding="utf-8")
    folder = tmp_path / "case.xosc"
    folder.mkdir()
    for scenario, needle in ((text, "notes.txt: malformed XML"), (folder, "a folder, not")):
        out = tmp_path / "out"
        assert main(["run", str(scenario), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert needle in err and len(err.strip().splitlines()) == 1
        assert not out.exists()


def test_a_protocol_and_an_r157_study_never_replace_each_others_folder(tmp_path, capsys):
    """Both write results.csv and scenarios/: each took the other's folder for its own and
    replaced it (a protocol's scorecard and batch/ gone after an r157-study into it)."""
    protocol = tmp_path / "protocol"
    (protocol / "batch").mkdir(parents=True)
    for name in ("results.csv", "scorecard.md", "scorecard.png"):
        (protocol / name).write_text("kept\n", encoding="utf-8")
    study = tmp_path / "study"
    (study / "runs").mkdir(parents=True)
    for name in ("results.csv", "r157_cut_in.png"):
        (study / name).write_text("kept\n", encoding="utf-8")
    before = {p: snapshot(p) for p in (protocol, study)}
    argv_study = ["r157-study", "--type", "deceleration", "--speeds-kmh", "60", "--out"]
    assert main([*argv_study, str(protocol)]) == 2
    assert "holds another command's output (batch, scorecard.md" in capsys.readouterr().err
    assert main(["protocol", "unr152", "--points", "v10_", "--out", str(study)]) == 2
    assert "holds another command's output (runs)" in capsys.readouterr().err
    assert {p: snapshot(p) for p in (protocol, study)} == before


def test_resume_reruns_a_finished_case_whose_folder_is_gone(tmp_path):
    """A case folder deleted after the run: --resume kept its row, not run again, and the
    report linked to a folder that did not exist."""
    matrix = write_matrix(tmp_path / "m.toml", SWEEP, paper_table=True)
    out = tmp_path / "out"
    runner.run_batch(matrix, out, progress=False, case_func=fake_case)
    gone = "onc-none_v120_mu1.0"
    assert (out / "cases" / gone).is_dir()
    shutil.rmtree(out / "cases" / gone)
    runner.run_batch(matrix, out, resume=True, progress=False, case_func=fake_case)
    assert (out / "cases" / gone).is_dir()  # run again
