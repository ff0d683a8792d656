"""Run many tasks in long-lived worker processes, surviving crashes and hung tasks.

libsumo holds one simulation per process and importing CasADi and libsumo is slow next to
a short case, so each worker is a separate Python interpreter that runs task after task. A worker
that dies (a segfault in native code, ``os._exit``) or runs one task past ``timeout_s`` (the
parent kills it) costs only that task, reported as a failed ``TaskResult``; a fresh worker
takes its place. An exception inside the task function is a failed result too, and the worker
lives on.

Workers are started with :mod:`subprocess` (a fresh interpreter, as multiprocessing's spawn
start method), so they can also be started from inside a daemonic Dask worker, which
multiprocessing forbids. Parent and worker talk through ``multiprocessing.connection``
framing over the worker's stdin and a duplicate of its original stdout; the worker points its
file descriptor 1 at its stderr, so whatever native code prints cannot corrupt the messages.
The worker's stderr goes to an anonymous temporary file whose last line is quoted when the
worker dies.

Two drivers share the worker: :func:`run_local` (N workers on this machine) and
:func:`run_dask` (each Dask worker thread keeps one worker process).
"""

from __future__ import annotations

import contextlib
import gc
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable, Generator, Iterable, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any

#: Native thread pools a worker runs with one thread each, unless the caller's environment
#: says otherwise: the workers are the parallelism, and OpenBLAS's idle threads spin on the
#: cores the other workers need.
SINGLE_THREADED = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
#: A worker's cyclic garbage collector: its first generation collected every this many net
#: allocations (Python's default is 700), the modules it preloaded frozen out of every
#: collection. A step of the co-simulation allocates thousands of short-lived objects and
#: frees nearly all of them by reference counting.
GC_THRESHOLDS = (50_000, 20, 100)
#: Longest wait for a new worker to import its modules and say it is ready [s].
STARTUP_TIMEOUT_S = 180.0
_STDERR_TAIL_BYTES = 4000


@dataclass(frozen=True)
class TaskResult:
    """Outcome of one task: ``value`` when it returned, ``error`` (one line) when it failed."""

    key: str
    value: Any = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


def _one_line(text: str) -> str:
    return " | ".join(part.strip() for part in str(text).strip().splitlines() if part.strip())


def _child_main() -> None:
    """Worker process: read tasks from stdin, send results on the duplicated stdout."""
    out = Connection(os.dup(1), readable=False)
    os.dup2(2, 1)  # native prints now go to the stderr log, not into the message stream
    inp = Connection(os.dup(0), writable=False)
    try:
        _, preload = inp.recv()
        for module in preload:
            __import__(module)
        gc.collect()
        gc.freeze()
        gc.set_threshold(*GC_THRESHOLDS)
        out.send(("ready",))
        while True:
            try:
                _, func, payload = inp.recv()
            except EOFError:
                return
            try:
                out.send(("ok", func(payload)))
            except Exception as exc:  # noqa: BLE001 - any task failure is a result to report
                traceback.print_exc(file=sys.stderr)
                out.send(("error", _one_line(f"{type(exc).__name__}: {exc}")))
    except (EOFError, BrokenPipeError):
        return


def _child_environment() -> dict[str, str]:
    """The worker's environment: the parent's, native thread pools single-threaded unless
    set there (:data:`SINGLE_THREADED`)."""
    env = dict(os.environ)
    for name in SINGLE_THREADED:
        env.setdefault(name, "1")
    return env


def _child_command() -> str:
    """The worker's program: the parent's package and ``sys.path`` set before anything of
    ours is imported.

    Python started with ``-c`` puts its working folder first on the path (``-P`` stops that),
    so a worker started in a source checkout would otherwise import the checkout's package,
    not the parent's (e.g. a compiled build on ``PYTHONPATH``). The folder holding the
    parent's package comes first, then the parent's path with the working folder made absolute.
    """
    import eoam_sumo

    root = os.path.dirname(os.path.dirname(os.path.abspath(eoam_sumo.__file__)))
    path = [root] + [os.path.abspath(p) if p else os.getcwd() for p in sys.path]
    return (
        f"import sys; sys.path[:] = {path!r}; "
        "from eoam_sumo.batch.pool import _child_main; _child_main()"
    )


class _Worker:
    """One worker process as seen by the parent: start, dispatch, receive, kill."""

    def __init__(self, preload: Sequence[str]):
        self.preload = tuple(preload)
        self.log = tempfile.TemporaryFile()  # noqa: SIM115 - lives as long as the worker
        self.proc = subprocess.Popen(
            [sys.executable, "-P", "-c", _child_command()],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
            env=_child_environment(),
        )
        stdin, stdout = self.proc.stdin, self.proc.stdout
        assert stdin is not None and stdout is not None  # both are pipes
        self.send_conn = Connection(os.dup(stdin.fileno()), readable=False)
        self.recv_conn = Connection(os.dup(stdout.fileno()), writable=False)
        stdin.close()
        stdout.close()
        self.ready = False
        self.dead = False
        self.key: str | None = None
        self.timeout_s = STARTUP_TIMEOUT_S
        self.deadline = time.monotonic() + STARTUP_TIMEOUT_S
        # died at once: end of file on its pipe reports it
        with contextlib.suppress(OSError):
            self.send_conn.send(("init", tuple(preload)))

    @property
    def busy(self) -> bool:
        return self.key is not None

    def dispatch(self, func: Callable, key: str, payload: Any, timeout_s: float) -> None:
        """Hand the worker a task; a worker that died meanwhile shows it on its next receive."""
        self.key, self.timeout_s = key, timeout_s
        self.deadline = time.monotonic() + timeout_s
        with contextlib.suppress(OSError):
            self.send_conn.send(("task", func, payload))

    def receive(self) -> TaskResult | None:
        """Read the message waiting on the pipe: None for 'ready', else the task's result.

        End of file means the worker died: RuntimeError if it had no task (it could not
        start), else a failed result for its task. The caller closes a dead worker.
        """
        try:
            msg = self.recv_conn.recv()
        except (EOFError, OSError):
            self.dead = True
            reason = self._death_reason()
            if not self.busy:
                raise RuntimeError(
                    f"a worker process ended before its first task: {reason}"
                ) from None
            key, self.key = self.key, None
            assert key is not None  # busy
            return TaskResult(key, error=f"worker process died ({reason})")
        if msg[0] == "ready":
            self.ready = True
            return None
        key, self.key = self.key, None
        assert key is not None  # a task's result comes only from a busy worker
        return TaskResult(key, value=msg[1]) if msg[0] == "ok" else TaskResult(key, error=msg[1])

    def expire(self) -> TaskResult:
        """Kill a worker past its deadline: a failed result for its task (RuntimeError if none)."""
        self.kill()
        if not self.busy:
            raise RuntimeError(f"a worker process did not start within {STARTUP_TIMEOUT_S:g} s")
        key, self.key = self.key, None
        assert key is not None  # busy
        return TaskResult(key, error=f"timed out after {self.timeout_s:g} s (worker killed)")

    def run(self, func: Callable, key: str, payload: Any, timeout_s: float) -> TaskResult:
        """Blocking: wait until ready, run one task; check ``alive`` afterwards."""
        while not self.ready:
            if not self.recv_conn.poll(max(self.deadline - time.monotonic(), 0.0)):
                self.expire()
            self.receive()
        self.dispatch(func, key, payload, timeout_s)
        if not self.recv_conn.poll(timeout_s):
            return self.expire()
        result = self.receive()
        assert result is not None  # ready, so this is the task's result
        return result

    @property
    def alive(self) -> bool:
        return not self.dead and self.proc.poll() is None

    def _death_reason(self) -> str:
        """Why the process ended (signal or exit status) and its last line on stderr."""
        try:
            code = self.proc.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            self.kill()
            code = self.proc.returncode
        if code < 0:
            try:
                how = signal.Signals(-code).name
            except ValueError:
                how = f"signal {-code}"
        else:
            how = f"exit status {code}"
        self.log.seek(0, os.SEEK_END)
        self.log.seek(max(self.log.tell() - _STDERR_TAIL_BYTES, 0))
        lines = [ln for ln in self.log.read().decode(errors="replace").splitlines() if ln.strip()]
        return how + (f"; last output: {lines[-1].strip()}" if lines else "")

    def kill(self) -> None:
        self.dead = True
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()

    def close(self, grace_s: float = 2.0) -> None:
        """Ask the worker to leave (end of its input), kill it if it does not, free the pipes."""
        if self.busy:
            self.kill()
        self.send_conn.close()
        try:
            self.proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            self.kill()
        self.recv_conn.close()
        self.log.close()


def run_local(
    func: Callable[[Any], Any],
    tasks: Iterable[tuple[str, Any]],
    jobs: int = 1,
    timeout_s: float = 300.0,
    preload: Sequence[str] = (),
) -> Generator[TaskResult, None, None]:
    """Run ``func(payload)`` for every ``(key, payload)`` in ``jobs`` worker processes.

    Yields one :class:`TaskResult` per task as tasks finish (completion order). ``func`` must
    be importable by module and name (a module-level function); ``preload`` names modules
    every worker imports before its first task, so start-up does not count against
    ``timeout_s``. A worker that cannot start raises RuntimeError: nothing could run.
    """
    _check(jobs, timeout_s)
    pending = deque(tasks)
    workers: list[_Worker] = []
    try:
        while pending or any(w.busy for w in workers):
            want = min(jobs, sum(w.busy for w in workers) + len(pending))
            while len(workers) < want:
                workers.append(_warm_worker(preload) or _Worker(preload))
            for w in workers:
                if w.ready and not w.busy and pending:
                    key, payload = pending.popleft()
                    w.dispatch(func, key, payload, timeout_s)
            if not pending:  # nothing left to hand out: let idle workers go
                for w in [w for w in workers if w.ready and not w.busy]:
                    workers.remove(w)
                    w.close()
            waiting = [w for w in workers if w.busy or not w.ready]
            wait_s = max(min(w.deadline for w in waiting) - time.monotonic(), 0.0)
            for conn in wait([w.recv_conn for w in workers], timeout=wait_s):
                w = next(w for w in workers if w.recv_conn is conn)
                result = w.receive()
                if not w.alive:
                    workers.remove(w)
                    w.close()
                elif pending and w.ready and not w.busy:  # its next task before the caller
                    key, payload = pending.popleft()  # records this result
                    w.dispatch(func, key, payload, timeout_s)
                if result is not None:
                    yield result
            now = time.monotonic()
            for w in [w for w in workers if (w.busy or not w.ready) and w.deadline <= now]:
                workers.remove(w)
                result = w.expire()
                w.close()
                yield result
    finally:
        for w in workers:
            w.close()


_warm: list[_Worker] = []


@contextlib.contextmanager
def warm_workers(
    jobs: int, preload: Sequence[str] = (), tasks: int | None = None
) -> Generator[None, None, None]:
    """Start ``jobs`` workers now (no more than ``tasks``, the tasks known to come), for the
    :func:`run_local` calls inside the block (with the same ``preload``) to take before
    starting their own: a worker imports its modules while the caller still prepares its
    tasks. Those not taken (no task left, or bad input found meanwhile) are killed when the
    block ends: they hold no task, and waiting for one still importing would keep a refusal
    waiting."""
    _check(jobs, 1.0)
    count = jobs if tasks is None else max(min(jobs, tasks), 0)
    started = [_Worker(preload) for _ in range(count)]
    _warm.extend(started)
    try:
        yield
    finally:
        for w in started:
            if w in _warm:
                _warm.remove(w)
                w.kill()
                w.close()


def _warm_worker(preload: Sequence[str]) -> _Worker | None:
    """A warm worker started with ``preload`` and still alive (taken off the list), or None."""
    for w in list(_warm):
        if w.preload == tuple(preload):
            _warm.remove(w)
            if w.alive:
                return w
            w.close()
    return None


def _check(jobs: int, timeout_s: float) -> None:
    if not (isinstance(jobs, int) and jobs >= 1):
        raise ValueError(f"jobs={jobs!r} must be an integer >= 1")
    if not timeout_s > 0:
        raise ValueError(f"timeout_s={timeout_s!r} must be > 0")


_thread_local = threading.local()


def _dask_task(
    func: Callable, key: str, payload: Any, timeout_s: float, preload: tuple[str, ...]
) -> TaskResult:
    """Dask task body: run one task in this Dask thread's own long-lived worker process."""
    worker = getattr(_thread_local, "worker", None)
    if worker is None or not worker.alive:
        worker = _thread_local.worker = _Worker(preload)
    result = worker.run(func, key, payload, timeout_s)
    if not worker.alive:
        worker.close()
        _thread_local.worker = None
    return result


def run_dask(
    func: Callable[[Any], Any],
    tasks: Iterable[tuple[str, Any]],
    client,
    timeout_s: float = 300.0,
    preload: Sequence[str] = (),
) -> Generator[TaskResult, None, None]:
    """Run the tasks on a ``dask.distributed.Client``, one Dask task per task.

    Each Dask worker thread keeps one worker process of this module, so crashes and
    timeouts are handled as in :func:`run_local` and a Dask worker never loads libsumo
    itself. Results are yielded with ``as_completed``; a Dask-level failure (a lost worker,
    a task that raised) is a failed result.
    """
    from dask.distributed import as_completed

    _check(1, timeout_s)
    futures = {}
    for key, payload in tasks:
        fut = client.submit(_dask_task, func, key, payload, timeout_s, tuple(preload), pure=False)
        futures[fut] = key
    for fut in as_completed(list(futures)):
        key = futures.pop(fut)
        try:
            result = fut.result()
        except Exception as exc:  # noqa: BLE001 - a cluster failure is a failed case
            error = f"dask task failed: {type(exc).__name__}: {exc}"
            result = TaskResult(key, error=_one_line(error))
        fut.release()
        yield result
