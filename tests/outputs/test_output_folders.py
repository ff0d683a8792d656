"""Output folders: one writer at a time (a ``flock`` the kernel releases when its process
dies), and a finished folder replaced only by a complete new one (staging and swap)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.outputs.lock import LOCK_NAME, locked, try_lock
from eoam_sumo.outputs.staging import OutputKind, output_folder

KIND = OutputKind("test", ("results.csv", "cases"))


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (its lock file aside) -> its bytes."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != LOCK_NAME
    }


def _finished(folder: Path) -> dict[str, bytes]:
    (folder / "cases" / "a").mkdir(parents=True)
    (folder / "cases" / "a" / "summary.json").write_text('{"outcome": "green"}\n')
    (folder / "results.csv").write_text("case_id,outcome\na,green\n")
    return snapshot(folder)


def _siblings(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.parent.iterdir() if p.name != folder.name)


def test_a_second_writer_is_refused_naming_the_folder_and_the_holder(tmp_path):
    out = tmp_path / "out"
    with locked(out):
        with pytest.raises(InputError) as refused, locked(out):
            pass
        assert str(out) in str(refused.value) and f"process {os.getpid()}" in str(refused.value)
        probe = "from eoam_sumo.outputs.lock import try_lock; import sys; " + (
            "sys.exit(0 if try_lock(__import__('pathlib').Path(sys.argv[1])) is None else 1)"
        )
        other = subprocess.run([sys.executable, "-c", probe, str(out)], check=False)
        assert other.returncode == 0  # another process is refused too
    with locked(out):  # released at the end of the block
        pass


def test_a_lock_dies_with_its_process(tmp_path):
    out = tmp_path / "out"
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from pathlib import Path; from eoam_sumo.outputs.lock import "
            "locked\nwith locked(Path(sys.argv[1])):\n    print('held', flush=True)\n"
            "    time.sleep(600)",
            str(out),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        assert try_lock(out) is None
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    fd = try_lock(out)  # no stale lock
    assert fd is not None
    os.close(fd)


def test_a_rerun_replaces_the_folder_only_once_complete(tmp_path):
    out = tmp_path / "out"
    old = _finished(out)
    with pytest.raises(KeyboardInterrupt), output_folder(out, KIND) as stage:
        assert stage != out
        (stage / "results.csv").write_text("case_id,outcome\na,red\n")
        raise KeyboardInterrupt
    assert snapshot(out) == old and _siblings(out) == []
    with output_folder(out, KIND) as stage:
        (stage / "results.csv").write_text("case_id,outcome\nb,red\n")
        assert snapshot(out) == old  # the old folder stays until the new one is complete
    assert snapshot(out) == {"results.csv": b"case_id,outcome\nb,red\n"}
    assert _siblings(out) == [] and (out / LOCK_NAME).is_file()


def test_new_empty_and_resumed_folders_are_written_in_place(tmp_path):
    with output_folder(tmp_path / "new", KIND) as folder:
        assert folder == tmp_path / "new"
    with output_folder(tmp_path / "new", KIND) as folder:  # only its lock file: empty
        assert folder == tmp_path / "new"
    _finished(tmp_path / "old")
    with output_folder(tmp_path / "old", KIND, in_place=True) as folder:
        assert folder == tmp_path / "old"


def test_a_folder_holding_other_files_is_refused_untouched(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    with pytest.raises(InputError, match="holds no test output"), output_folder(out, KIND):
        pass
    assert snapshot(out) == {"notes.txt": b"mine\n"}


def test_unwritable_folders_are_refused_in_one_line(tmp_path):
    (tmp_path / "file").write_text("")
    for out in (tmp_path / "file", tmp_path / "file" / "sub", Path("/proc/eoam-x")):
        with pytest.raises(InputError, match="cannot be written"), output_folder(out, KIND):
            pass


def test_a_dead_runs_staging_folder_is_removed_a_live_ones_kept(tmp_path):
    out = tmp_path / "out"
    _finished(out)
    dead, live = tmp_path / "out.partial-1", tmp_path / "out.partial-2"
    dead.mkdir()
    fd = try_lock(live)
    try:
        with output_folder(out, KIND) as stage:
            (stage / "results.csv").write_text("new\n")
        assert _siblings(out) == ["out.partial-2"]
    finally:
        os.close(fd)


def test_paths_recorded_inside_the_staging_folder_are_moved_with_it(tmp_path):
    out = tmp_path / "out"
    _finished(out)
    with output_folder(out, KIND) as stage:
        (stage / "cases" / "a").mkdir(parents=True)
        for name in ("results.csv", "cases/a/summary.json", "cases/a/other.txt"):
            (stage / name).write_text(f"{stage}/scenarios/a.sumocfg\n")
    for name in ("results.csv", "cases/a/summary.json"):
        assert (out / name).read_text() == f"{out}/scenarios/a.sumocfg\n"
    assert (out / "cases/a/other.txt").read_text().startswith(f"{out}.partial-")  # not a record


def test_an_atomic_write_that_fails_leaves_no_temporary_file(tmp_path):
    (tmp_path / "summary.json").mkdir()
    with pytest.raises(InputError, match=r"summary\.json cannot be written"):
        write_atomic(tmp_path / "summary.json", "{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_the_current_folder_is_replaced_by_its_real_path(tmp_path, monkeypatch):
    out = tmp_path / "out"
    _finished(out)
    monkeypatch.chdir(out)
    with output_folder(Path(), KIND) as stage:
        assert stage == out.resolve().with_name(f"out.partial-{os.getpid()}")
        (stage / "results.csv").write_text("new\n")
    assert snapshot(out) == {"results.csv": b"new\n"}


def test_a_failed_first_protocol_run_leaves_no_folder(tmp_path, monkeypatch):
    """``protocol`` into a new folder that fails (a scheduler it cannot reach) leaves no
    folder, nor the parents made for it; into an empty one, the folder as it was."""
    from eoam_sumo.cli import build_parser
    from eoam_sumo.protocols import command

    def fails(args, points, out):
        (out / "scenarios").mkdir()
        (out / "batch").mkdir()
        raise InputError("cannot connect to the Dask scheduler 'tcp://127.0.0.1:1'")

    monkeypatch.setattr(command, "run_points", fails)
    for out in (tmp_path / "new" / "p", tmp_path / "empty"):
        if out.name == "empty":
            out.mkdir()
        argv = ["protocol", "unr152", "--out", str(out), "--scheduler", "tcp://127.0.0.1:1"]
        with pytest.raises(InputError, match="Dask scheduler"):
            command.run(build_parser().parse_args(argv))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty"]
    assert [p.name for p in (tmp_path / "empty").iterdir()] == [LOCK_NAME]


def test_a_dead_runs_staging_folder_is_removed_by_a_resume_too(tmp_path):
    """``batch --resume`` writes in place: a killed run's ``.partial-PID`` stayed beside it."""
    out = tmp_path / "out"
    _finished(out)
    (tmp_path / "out.partial-1").mkdir()
    with output_folder(out, KIND, in_place=True) as folder:
        assert folder == out
    assert _siblings(out) == []
