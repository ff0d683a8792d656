"""The worker pool: long-lived workers, results per task, crashes, exceptions and timeouts.

The task functions below are test-only workers (the pool takes the task function as a
parameter); they are imported by name in the worker processes.
"""

from __future__ import annotations

import os
import signal
import time

import pytest

from eoam_sumo.batch import pool
from eoam_sumo.batch.pool import TaskResult, run_local, warm_workers


def square_with_pid(payload):
    return {"square": payload * payload, "pid": os.getpid()}


def misbehave(payload):
    kind, value = payload
    if kind == "segfault":
        os.kill(os.getpid(), signal.SIGSEGV)
    if kind == "exit":
        os._exit(3)
    if kind == "raise":
        raise ValueError(f"bad value {value}\nsecond line")
    if kind == "hang":
        time.sleep(600)
    if kind == "print":
        os.write(1, b"native code printing on stdout\n")
    return {"value": value, "pid": os.getpid()}


def _by_key(results):
    out = {}
    for r in results:
        assert isinstance(r, TaskResult)
        assert r.key not in out, f"task {r.key} reported twice"
        out[r.key] = r
    return out


def test_every_task_once_in_long_lived_workers():
    tasks = [(f"t{i}", i) for i in range(8)]
    results = _by_key(run_local(square_with_pid, tasks, jobs=2, timeout_s=120))
    assert set(results) == {k for k, _ in tasks}
    for key, payload in tasks:
        assert results[key].ok and results[key].value["square"] == payload * payload
    pids = {r.value["pid"] for r in results.values()}
    assert 1 <= len(pids) <= 2  # two workers ran eight tasks: none was started per task
    assert os.getpid() not in pids


def test_crash_exception_and_stdout_noise_cost_only_their_task():
    tasks = [
        ("a", ("ok", 1)),
        ("segv", ("segfault", 0)),
        ("b", ("ok", 2)),
        ("exit", ("exit", 0)),
        ("raise", ("raise", 7)),
        ("noise", ("print", 3)),
        ("c", ("ok", 4)),
    ]
    results = _by_key(run_local(misbehave, tasks, jobs=1, timeout_s=120))
    assert set(results) == {k for k, _ in tasks}
    assert [results[k].value["value"] for k in ("a", "b", "noise", "c")] == [1, 2, 3, 4]
    assert not results["segv"].ok and "died" in results["segv"].error
    assert "SIGSEGV" in results["segv"].error
    assert not results["exit"].ok and "exit status 3" in results["exit"].error
    err = results["raise"].error
    assert err.startswith("ValueError: bad value 7") and "\n" not in err
    # an exception does not cost the worker: the next task ran in the same process
    assert results["noise"].value["pid"] == results["c"].value["pid"]
    # the crash did: a new worker took over after it
    assert results["a"].value["pid"] != results["b"].value["pid"]


def test_hung_task_is_killed_at_its_timeout_and_the_rest_run():
    tasks = [("hang", ("hang", 0)), ("x", ("ok", 1)), ("y", ("ok", 2))]
    results = _by_key(run_local(misbehave, tasks, jobs=2, timeout_s=3.0))
    assert results["hang"].error == "timed out after 3 s (worker killed)"
    assert results["x"].value["value"] == 1 and results["y"].value["value"] == 2


def test_warm_workers_run_the_tasks_and_those_not_taken_are_closed():
    with warm_workers(3):
        warm = {w.proc.pid: w.proc for w in pool._warm}
        results = _by_key(run_local(square_with_pid, [("a", 2), ("b", 3)], jobs=1))
        assert results["a"].value["square"] == 4 and results["b"].value["square"] == 9
        assert results["a"].value["pid"] in warm  # a worker started before run_local
        assert results["a"].value["pid"] == results["b"].value["pid"]
        others = [p for pid, p in warm.items() if pid != results["a"].value["pid"]]
        assert all(p.poll() is None for p in others)  # not taken: still there in the block
    assert all(p.poll() is not None for p in warm.values())  # and closed after it
    assert not pool._warm


def test_worker_that_cannot_start_raises():
    with pytest.raises(RuntimeError, match="ended before its first task"):
        list(run_local(square_with_pid, [("t", 1)], preload=("no_such_module_for_eoam",)))


@pytest.mark.parametrize("kwargs", [{"jobs": 0}, {"jobs": 1.5}, {"timeout_s": 0.0}])
def test_bad_settings_are_rejected(kwargs):
    with pytest.raises(ValueError):
        list(run_local(square_with_pid, [("t", 1)], **kwargs))


def package_file(_payload):
    import eoam_sumo

    return eoam_sumo.__file__


def test_workers_import_the_parents_package_wherever_they_start(tmp_path, monkeypatch):
    """A worker started in a folder holding another ``eoam_sumo`` (a source checkout beside a
    compiled build) imports the parent's package, not that one."""
    decoy = tmp_path / "eoam_sumo"
    decoy.mkdir()
    (decoy / "__init__.py").write_text("raise ImportError('the decoy package was imported')\n")
    monkeypatch.chdir(tmp_path)
    import eoam_sumo

    results = _by_key(run_local(package_file, [("a", None)], jobs=1, timeout_s=120))
    assert results["a"].ok, results["a"].error
    assert results["a"].value == eoam_sumo.__file__


def test_workers_run_native_thread_pools_single_threaded_unless_told(monkeypatch):
    """Workers are the parallelism: OpenBLAS and OpenMP get one thread each in a worker,
    unless the caller's environment sets them."""
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    tasks = [("blas", "OPENBLAS_NUM_THREADS"), ("omp", "OMP_NUM_THREADS")]
    results = _by_key(run_local(os.getenv, tasks, jobs=1, timeout_s=120))
    assert results["blas"].value == "1"
    assert results["omp"].value == "3"


def test_no_more_workers_are_warmed_than_there_are_tasks(monkeypatch, tmp_path):
    """``protocol --jobs 3`` on one point starts one worker (and ``batch`` no more than its
    cases); ``--jobs`` itself is checked as before."""
    from eoam_sumo.cli import build_parser
    from eoam_sumo.protocols import command

    started = []

    class Counted:
        def __init__(self, preload):
            started.append(preload)

        def kill(self):
            pass

        def close(self):
            pass

    class Summary:
        failed = 0

        def line(self, out):
            return "ok"

    monkeypatch.setattr(pool, "_Worker", Counted)
    monkeypatch.setattr(command, "run_points", lambda args, points, out: Summary())
    args = build_parser().parse_args(
        ["protocol", "unr152", "--out", str(tmp_path / "p"), "--jobs", "3", "--points", "^"]
    )
    points = command.selected_points(args)
    args.points = f"^{points[0].point_id}$"
    assert command.run(args) == 0
    assert len(started) == 1
    with pytest.raises(ValueError, match="jobs=0"), warm_workers(0, (), tasks=5):
        pass
