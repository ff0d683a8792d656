"""The batch engine: expand a matrix, run its cases in parallel, write results.csv and Table 2.

The engine writes data (results.csv, the cases' folders, table2.md or
outcome_probabilities.csv) and returns the results frame; the images are drawn from that
frame by the command line (``eoam-sumo batch``) through :mod:`eoam_sumo.plotting`.

``results.csv`` is written row by row as cases finish (appended, flushed and synced), so an
interrupted batch loses nothing it has finished; at the end it is rewritten atomically (temp
file and ``os.replace``) in the matrix's order, so the final file does not depend on the
number of jobs or on the order cases finished. Only ``wall_time_s`` and ``realtime_factor``
differ between two runs of one matrix.

``resume`` keeps the rows of an existing results.csv whose status is ``ok`` and whose case
is still in the matrix (same case id and parameters, the same bytes in its files:
``inputs_sha256``), and runs every other case of the matrix again, failed ones included;
the rows of cases not in the matrix stay, after the matrix's (the report and the returned
frame are the matrix's cases).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from eoam_sumo.batch.case import (
    ALL_CASE_FILES,
    CASE_FILES_OF,
    PRELOAD,
    TIMESERIES_FORMATS,
    CaseTask,
    run_matrix_case,
)
from eoam_sumo.batch.inputs import InputDigests
from eoam_sumo.batch.policy_report import policy_line, policy_title, sight_markdown
from eoam_sumo.batch.pool import TaskResult, run_dask, run_local
from eoam_sumo.batch.probabilities import write_probabilities
from eoam_sumo.batch.report import TABLE_MD, outcome_grid, table2_markdown
from eoam_sumo.batch.results import (
    CASES_DIR,
    COLUMNS,
    RESULTS_FILE,
    RowLog,
    case_dir_of,
    finalise,
    kept_rows,
    result_row,
)
from eoam_sumo.batch.vehicles_report import sweeps_vehicles, write_vehicles_report
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.matrix import Case, Matrix, check_matrix, load_matrix
from eoam_sumo.sim.settings import check_sumo_step_s

#: Exit status of ``eoam-sumo batch`` when at least one case failed (bad input is 2).
EXIT_CASES_FAILED = 1
#: How long to keep trying to reach a Dask scheduler [s].
DASK_CONNECT_TIMEOUT_S = 20.0


def _store_case_files(case_dir: Path, result: TaskResult, ok: bool) -> None:
    """Write the files a remote case sent back; a failed case leaves no older run's files."""
    files = result.value.get("files") if ok else None
    if files:
        case_dir.mkdir(parents=True, exist_ok=True)
        for name in ALL_CASE_FILES:
            if name not in files:
                (case_dir / name).unlink(missing_ok=True)
        for name, data in files.items():
            write_atomic(case_dir / name, data)
    elif not ok:
        for name in ALL_CASE_FILES:
            (case_dir / name).unlink(missing_ok=True)


@contextlib.contextmanager
def _dask_client(scheduler: str, jobs: int):
    """A Client on a new LocalCluster ('local') or on the scheduler at an address."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as exc:
        raise InputError(
            f"--scheduler needs dask.distributed, which is not installed: {exc}"
        ) from exc
    if scheduler == "local":
        with (
            LocalCluster(
                n_workers=jobs, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster,
            Client(cluster) as client,
        ):
            yield client
        return
    try:
        client = Client(scheduler, timeout=f"{DASK_CONNECT_TIMEOUT_S}s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"cannot connect to the Dask scheduler {scheduler!r}: {exc}") from exc
    with client:
        yield client


def _results(
    to_run: list[Case],
    out_dir: Path,
    jobs: int,
    scheduler: str | None,
    timeout_s: float,
    case_func: Callable,
    tables_dir: Path | None,
    timeseries: str = "csv",
) -> Iterator[tuple[Case, TaskResult]]:
    by_id = {c.case_id: c for c in to_run}
    preload = PRELOAD if case_func is run_matrix_case else ()
    if scheduler is None:
        tasks = [
            (c.case_id, CaseTask(c, out_dir / case_dir_of(c.case_id), tables_dir, timeseries))
            for c in to_run
        ]
        with contextlib.closing(run_local(case_func, tasks, jobs, timeout_s, preload)) as it:
            for result in it:
                yield by_id[result.key], result
        return
    tasks = [(c.case_id, CaseTask(c, None, tables_dir, timeseries)) for c in to_run]
    with (
        _dask_client(scheduler, jobs) as client,
        contextlib.closing(run_dask(case_func, tasks, client, timeout_s, preload)) as it,
    ):
        for result in it:
            yield by_id[result.key], result


def run_batch(
    matrix_path: Path,
    out_dir: Path,
    jobs: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    timeout_s: float = 300.0,
    progress: bool = True,
    *,
    case_func: Callable[[CaseTask], dict] = run_matrix_case,
    tables_dir: Path | None = None,
    timeseries: str = "csv",
    after_stop_s: float | None = None,
    plan: BatchPlan | None = None,
    sumo_step_s: float | None = None,
    meanwhile: Callable[[], object] | None = None,
) -> pd.DataFrame:
    """Run every case of the matrix; return the final results (as :func:`read_results`).

    Writes ``out_dir/results.csv``, ``out_dir/cases/<case_id>/`` (time series and summary)
    and ``table2.md`` (a sampled matrix: ``outcome_probabilities.csv`` instead); the images
    are drawn by ``eoam-sumo batch`` from the returned frame
    (:func:`eoam_sumo.plotting.batch_plots.plot_batch_report`). ``scheduler``: None for local
    worker processes, ``"local"`` for a Dask LocalCluster of ``jobs`` workers, else a Dask
    scheduler address. ``case_func`` runs one :class:`CaseTask` and returns
    ``{"summary", "files"}`` like :func:`run_matrix_case` (the default); it must be a
    module-level function.

    Bad input raises InputError before anything is written or run: the matrix itself
    (:func:`~eoam_sumo.matrix.load_matrix`), its scenario files and every swept speed and
    friction against the lookup tables in ``tables_dir`` (default: the co-simulation's,
    :func:`~eoam_sumo.matrix.check_matrix`). A case that fails is a ``failed`` row.
    ``after_stop_s`` and ``sumo_step_s`` set every case's (over the matrix's ``[scenario]``).
    ``plan``: the matrix already checked by :func:`plan_batch` (the command line checks it
    before it takes the output folder). ``meanwhile``: as :func:`run_cases`.
    """
    check_options(jobs, timeout_s, timeseries)
    plan = plan or plan_batch(matrix_path, tables_dir, after_stop_s, sumo_step_s)
    matrix, cases, paper = plan.matrix, plan.cases, plan.paper
    out_dir = _cases_folder(Path(out_dir))
    results = run_cases(
        cases,
        out_dir,
        jobs,
        scheduler,
        resume,
        timeout_s,
        progress,
        case_func=case_func,
        tables_dir=tables_dir,
        timeseries=timeseries,
        paper=paper,
        meanwhile=meanwhile,
    )
    if matrix.sample is None:
        write_report(out_dir, results)
        if sweeps_vehicles(results):
            write_vehicles_report(out_dir, results)
    else:
        write_probabilities(out_dir, results)
    return results


@dataclass(frozen=True)
class BatchPlan:
    """A checked matrix: its cases (``after_stop_s`` applied) and the paper's colours."""

    matrix: Matrix
    cases: list[Case]
    paper: dict[str, str]


def plan_batch(
    matrix_path: Path,
    tables_dir: Path | None = None,
    after_stop_s: float | None = None,
    sumo_step_s: float | None = None,
    default_sumo_step_s: float | None = None,
) -> BatchPlan:
    """The matrix loaded and checked (:func:`run_batch`'s bad input), nothing written.
    ``sumo_step_s`` sets every case's SUMO step; ``default_sumo_step_s`` only the cases the
    matrix leaves without one (None: the run's default, the 10 ms reference)."""
    if after_stop_s is not None and not after_stop_s >= 0.0:
        raise InputError(f"--after-stop-s {after_stop_s:g} must be >= 0")
    if sumo_step_s is not None:
        sumo_step_s = check_sumo_step_s(sumo_step_s, "--sumo-step-s")
    matrix: Matrix = load_matrix(Path(matrix_path))
    check_matrix(matrix, tables_dir)
    cases = matrix.cases()
    if after_stop_s is not None:
        cases = [replace(c, after_stop_s=after_stop_s) for c in cases]
    if sumo_step_s is not None:
        cases = [replace(c, sumo_step_s=sumo_step_s) for c in cases]
    elif default_sumo_step_s is not None:
        cases = [c if c.sumo_step_s else replace(c, sumo_step_s=default_sumo_step_s) for c in cases]
    return BatchPlan(matrix, cases, matrix.paper_outcomes())


def run_cases(
    cases: list[Case],
    out_dir: Path,
    jobs: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    timeout_s: float = 300.0,
    progress: bool = True,
    *,
    case_func: Callable[[CaseTask], dict] = run_matrix_case,
    tables_dir: Path | None = None,
    timeseries: str = "csv",
    paper: dict[str, str] | None = None,
    meanwhile: Callable[[], object] | None = None,
) -> pd.DataFrame:
    """Run ``cases`` (each with its own scenario file) into ``out_dir``: the cases' folders
    and ``results.csv`` in the cases' order; return the results (as ``read_results``).
    ``meanwhile`` (e.g. importing what draws the images) is called in a thread of its own
    once a core is free of cases (:class:`_Meanwhile`) and joined before returning."""
    check_options(jobs, timeout_s, timeseries)
    paper = paper or {}
    out_dir = _cases_folder(Path(out_dir))
    results_path = out_dir / RESULTS_FILE
    digests = InputDigests()  # the files as they are now, before any case runs
    inputs = {c.case_id: digests.of(c) for c in cases}
    kept = (
        kept_rows(results_path, cases, inputs, CASE_FILES_OF[timeseries])
        if resume and results_path.is_file()
        else pd.DataFrame(columns=list(COLUMNS), dtype=str)
    )
    done = set(kept["case_id"]) & {c.case_id for c in cases}
    to_run = [c for c in cases if c.case_id not in done]
    log = RowLog(results_path, kept)
    bar = _progress_bar(len(cases), len(done), progress)
    failed = 0
    side = _Meanwhile(meanwhile, len(to_run), jobs if scheduler is None else 0)
    try:
        for case, result in _results(
            to_run, out_dir, jobs, scheduler, timeout_s, case_func, tables_dir, timeseries
        ):
            row = result_row(case, result, paper.get(case.case_id), inputs[case.case_id])
            failed += _record(out_dir, log, row, result)
            bar.set_postfix(failed=failed, refresh=False)
            bar.update(1)
            side.finished_one()
    finally:
        bar.close()
        log.close()
        side.join()
    return finalise(results_path, cases, paper)


class _Meanwhile:
    """Runs a task in a thread of its own once this machine has a core the cases leave free,
    after the first case finished (the workers have started): at once when the workers
    (``jobs``; 0: none here) are fewer than the cores, else when fewer cases are left to
    finish than workers. Its exceptions are left to whoever does the work again (an import
    retried in the main thread raises there)."""

    def __init__(self, task: Callable[[], object] | None, cases: int, jobs: int):
        self._task, self._left, self._jobs = task, cases, jobs
        self._thread: threading.Thread | None = None
        self._spare_core = jobs < (os.cpu_count() or 1)

    def finished_one(self) -> None:
        self._left -= 1
        if self._spare_core or self._left < self._jobs:
            self._start()

    def _start(self) -> None:
        if self._task is not None and self._thread is None:
            self._thread = threading.Thread(target=self._run, args=(self._task,), daemon=True)
            self._thread.start()

    @staticmethod
    def _run(task: Callable[[], object]) -> None:
        with contextlib.suppress(Exception):
            task()

    def join(self) -> None:
        if self._thread is not None:
            self._thread.join()


#: The longest per-case time limit accepted [s]: a day (a larger one overflows the worker's
#: wait; 1e308 did).
MAX_TIMEOUT_S = 86400.0


def check_options(jobs: int, timeout_s: float, timeseries: str) -> None:
    """InputError for a job count, time limit or time-series format out of range."""
    if not (isinstance(jobs, int) and jobs >= 1):
        raise InputError(f"--jobs {jobs!r} must be an integer >= 1")
    if not 0 < timeout_s <= MAX_TIMEOUT_S:
        raise InputError(f"--timeout-s {timeout_s!r} is outside (0, {MAX_TIMEOUT_S:g}]")
    if timeseries not in TIMESERIES_FORMATS:
        raise InputError(
            f"--timeseries {timeseries!r} is not one of {', '.join(TIMESERIES_FORMATS)}"
        )


def _cases_folder(out_dir: Path) -> Path:
    """``out_dir`` with its ``cases/`` folder made; InputError if it cannot be written."""
    try:
        (out_dir / CASES_DIR).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output folder {out_dir} cannot be written: {exc.strerror}") from exc
    return out_dir


def _progress_bar(total: int, done: int, progress: bool) -> tqdm:
    """The cases' progress bar on stderr (disabled without ``progress``)."""
    return tqdm(
        total=total,
        initial=done,
        unit="case",
        desc="cases",
        file=sys.stderr,
        disable=not progress,
        dynamic_ncols=True,
    )


def _record(out_dir: Path, log: RowLog, row: dict, result: TaskResult) -> bool:
    """A finished case: its files into its folder, its row into results.csv; True if it
    failed."""
    ok = row["status"] == "ok"
    _store_case_files(out_dir / row["case_dir"], result, ok)
    log.add(row)
    return not ok


def write_report(out_dir: Path, results: pd.DataFrame) -> Path:
    """Write ``table2.md`` of a results frame into ``out_dir``; return its path."""
    grid = outcome_grid(results)
    text = table2_markdown(grid, policy_title(results))
    head, _, rest = text.partition("\n\n")
    sight = sight_markdown(results)
    text = f"{head}\n\n{policy_line(results)}\n\n{rest}" + (f"\n{sight}" if sight else "")
    return write_atomic(Path(out_dir) / TABLE_MD, text)
