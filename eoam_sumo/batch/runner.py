"""The batch engine: expand a matrix, run its cases in parallel, write results.csv and Table 2.

``results.csv`` is written row by row as cases finish (appended, flushed and synced), so an
interrupted batch loses nothing it has finished; at the end it is rewritten atomically (temp
file and ``os.replace``) in the matrix's order, so the final file does not depend on the
number of jobs or on the order cases finished. Only ``wall_time_s`` and ``realtime_factor``
differ between two runs of one matrix.

``resume`` keeps the rows of an existing results.csv whose status is ``ok`` and whose case
is still in the matrix (same case id and scenario file), and runs every other case again,
failed ones included.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import pandas as pd

from eoam_sumo.batch.case import (
    ALL_CASE_FILES,
    PRELOAD,
    TIMESERIES_FORMATS,
    CaseTask,
    run_matrix_case,
)
from eoam_sumo.batch.pool import TaskResult, run_dask, run_local
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import Case, Matrix, check_matrix, load_matrix

#: Exit status of ``eoam-sumo batch`` when at least one case failed (bad input is 2).
EXIT_CASES_FAILED = 1
RESULTS_FILE = "results.csv"
CASES_DIR = "cases"
#: results.csv columns: the case's parameters, its status, the summary fields, where it lives.
PARAM_COLUMNS = ("case_id", "ego_speed_kmh", "mu", "oncoming_start_m", "aro_hold_s",
                 "aro_decel_mps2", "max_time_s", "radar_range_m", "policy", "v2x_range_m",
                 "v2x_latency_s", "v2x_loss", "v2x_penetration", "mu_belief", "radar_model",
                 "seed", "draw")
SUMMARY_COLUMNS = (
    "outcome", "collision_with", "impact_speed_mps", "contact_kind", "contact_time_s",
    "reason", "modes_visited", "fcw_raised", "mu_at_start", "min_gap_aro_m",
    "max_abs_lat_accel_mps2", "max_lateral_offset_m", "final_lateral_offset_m",
    "final_speed_mps", "max_abs_heading_error_rad", "min_speed_mps", "left_road",
    "ego_initial_speed_mps", "trigger_time_s", "trigger_range_m", "mu_believed_at_trigger",
    "sim_time_s", "wall_time_s", "realtime_factor", "sight_gate", "sight_needed_m",
    "sight_known_free_m", "sight_time_s", "tie_break",
)
COLUMNS = (*PARAM_COLUMNS, "status", "paper_outcome", *SUMMARY_COLUMNS, "error", "case_dir",
           "sumocfg")
#: Columns that measure the machine, not the physics: they differ between runs.
TIMING_COLUMNS = ("wall_time_s", "realtime_factor")
NUMERIC_COLUMNS = (
    "ego_speed_kmh", "mu", "oncoming_start_m", "aro_hold_s", "aro_decel_mps2", "max_time_s",
    "radar_range_m", "impact_speed_mps", "contact_time_s", "mu_at_start", "min_gap_aro_m",
    "max_abs_lat_accel_mps2", "max_lateral_offset_m", "final_lateral_offset_m",
    "final_speed_mps", "max_abs_heading_error_rad", "min_speed_mps", "ego_initial_speed_mps",
    "sim_time_s", "wall_time_s", "realtime_factor", "v2x_range_m", "v2x_latency_s", "v2x_loss",
    "v2x_penetration", "sight_needed_m", "sight_known_free_m", "sight_time_s",
    "seed", "draw", "trigger_time_s", "trigger_range_m", "mu_believed_at_trigger",
)
#: How long to keep trying to reach a Dask scheduler [s].
DASK_CONNECT_TIMEOUT_S = 20.0
#: summary.json key -> results.csv column where the names differ (the case's own ``mu`` is
#: the requested friction; the summary's is the one measured under the ego at the start).
_RENAMED = {"mu": "mu_at_start"}


def case_dir_of(case_id: str) -> str:
    """Case folder relative to the batch folder (the ``case_dir`` column)."""
    return f"{CASES_DIR}/{case_id}"


def result_row(case: Case, result: TaskResult, paper_outcome: str | None = None) -> dict:
    """One results.csv row from a case and its task result (failed rows: empty summary);
    ``paper_outcome`` is the published colour of the case, if any."""
    row = dict.fromkeys(COLUMNS)
    row.update(case_id=case.case_id, paper_outcome=paper_outcome,
               ego_speed_kmh=case.ego_speed_kmh, mu=case.mu,
               oncoming_start_m=case.oncoming_start_m, aro_hold_s=case.aro_hold_s,
               aro_decel_mps2=case.aro_decel_mps2, max_time_s=case.max_time_s,
               radar_range_m=case.radar_range_m, policy=case.policy,
               v2x_range_m=case.v2x_range_m, v2x_latency_s=case.v2x_latency_s,
               v2x_loss=case.v2x_loss, v2x_penetration=case.v2x_penetration,
               mu_belief=case.mu_belief, radar_model=case.radar_model, seed=case.seed,
               draw=case.draw, case_dir=case_dir_of(case.case_id),
               sumocfg=str(case.sumocfg))
    summary = result.value.get("summary") if isinstance(result.value, dict) else None
    if not result.ok or not isinstance(summary, dict):
        row.update(status="failed",
                   error=_one_line(result.error or "the case function returned no summary"))
        return row
    row["status"] = "ok"
    for key, value in summary.items():
        column = _RENAMED.get(key, key)
        if column in SUMMARY_COLUMNS:
            row[column] = _cell(value)
    return row


def _one_line(text: str) -> str:
    return " | ".join(p.strip() for p in str(text).splitlines() if p.strip())


def _cell(value):
    if isinstance(value, (list, tuple)):
        return "-".join(str(v) for v in value)
    if isinstance(value, str):
        return _one_line(value)
    return value


def _csv_text(rows: list[dict], header: bool) -> str:
    return pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(index=False, header=header)


def _atomic_write(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def _read_rows(path: Path) -> pd.DataFrame:
    """results.csv as text cells; a last line cut short by an interruption is dropped."""
    text = path.read_text(encoding="utf-8")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    if not text.strip():
        return pd.DataFrame(columns=list(COLUMNS), dtype=str)
    try:
        frame = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read as a results file: {exc}") from exc
    if tuple(frame.columns) != COLUMNS:
        raise InputError(f"{path}: its columns are not those of this version's results.csv; "
                         "use another --out folder or remove the file")
    return frame


def read_results(path: Path) -> pd.DataFrame:
    """A results.csv with numbers as floats (empty = NaN) and every other column as text."""
    frame = _read_rows(Path(path))
    for column in NUMERIC_COLUMNS:
        frame[column] = pd.to_numeric(frame[column].replace("", None), errors="coerce")
    return frame


class _RowLog:
    """results.csv open for appending: one row per finished case, flushed and synced."""

    def __init__(self, path: Path, kept: pd.DataFrame):
        self.path = path
        kept_text = kept.to_csv(index=False) if len(kept) else _csv_text([], header=True)
        _atomic_write(path, kept_text)
        self.fh = open(path, "a", encoding="utf-8", newline="")  # noqa: SIM115 - closed in close()

    def add(self, row: dict) -> None:
        self.fh.write(_csv_text([row], header=False))
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


#: results.csv columns that, besides the case id, make a kept row the same case for --resume
RESUME_KEYS = ("sumocfg", "ego_speed_kmh", "mu", "oncoming_start_m", "aro_hold_s",
               "aro_decel_mps2", "max_time_s", "radar_range_m", "policy", "v2x_range_m",
               "v2x_latency_s", "v2x_loss", "v2x_penetration", "mu_belief", "radar_model",
               "seed")


def _case_keys(cases: list[Case]) -> dict[str, tuple[str, ...]]:
    """case_id -> its RESUME_KEYS as results.csv writes them."""
    frame = pd.DataFrame([(c.case_id, *(str(c.sumocfg) if k == "sumocfg" else getattr(c, k)
                                        for k in RESUME_KEYS)) for c in cases],
                         columns=["case_id", *RESUME_KEYS])
    text = pd.read_csv(io.StringIO(frame.to_csv(index=False)), dtype=str, keep_default_na=False)
    return {r[0]: tuple(r[1:]) for r in text.itertuples(index=False)}


def _kept_rows(path: Path, cases: list[Case]) -> pd.DataFrame:
    """Rows of an earlier run worth keeping: finished, and still the same case (same id, and
    the same RESUME_KEYS as written in results.csv: policy, V2X link, drawn values and seeds
    included)."""
    rows = _read_rows(path)
    want = _case_keys(cases)
    same = [want.get(cid) == key for cid, key in zip(
        rows["case_id"], zip(*(rows[k] for k in RESUME_KEYS)))]
    keep = (rows["status"] == "ok").to_numpy() & pd.Series(same, dtype=bool).to_numpy()
    return rows[keep].drop_duplicates("case_id", keep="last")


def _finalise(path: Path, cases: list[Case], paper: dict[str, str]) -> pd.DataFrame:
    """Rewrite results.csv atomically in the matrix's order, one row per case, with the
    paper's colours of the matrix as it is now."""
    rows = _read_rows(path).drop_duplicates("case_id", keep="last")
    order = {c.case_id: i for i, c in enumerate(cases)}
    rows = rows[rows["case_id"].isin(order)]
    rows = rows.iloc[rows["case_id"].map(order).argsort(kind="stable")].copy()
    rows["paper_outcome"] = [paper.get(cid, "") for cid in rows["case_id"]]
    _atomic_write(path, rows.to_csv(index=False))
    return read_results(path)


def _store_case_files(case_dir: Path, result: TaskResult, ok: bool) -> None:
    """Write the files a remote case sent back; a failed case leaves no older run's files."""
    files = result.value.get("files") if ok else None
    if files:
        case_dir.mkdir(parents=True, exist_ok=True)
        for name in ALL_CASE_FILES:
            if name not in files:
                (case_dir / name).unlink(missing_ok=True)
        for name, data in files.items():
            tmp = case_dir / (name + ".tmp")
            tmp.write_bytes(data)
            os.replace(tmp, case_dir / name)
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
            f"--scheduler needs dask.distributed, which is not installed: {exc}") from exc
    if scheduler == "local":
        with LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            yield client
        return
    try:
        client = Client(scheduler, timeout=f"{DASK_CONNECT_TIMEOUT_S}s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"cannot connect to the Dask scheduler {scheduler!r}: {exc}") from exc
    with client:
        yield client


def _results(to_run: list[Case], out_dir: Path, jobs: int, scheduler: str | None,
             timeout_s: float, case_func: Callable, tables_dir: Path | None,
             timeseries: str = "csv") -> Iterator[tuple[Case, TaskResult]]:
    by_id = {c.case_id: c for c in to_run}
    preload = PRELOAD if case_func is run_matrix_case else ()
    if scheduler is None:
        tasks = [(c.case_id, CaseTask(c, out_dir / case_dir_of(c.case_id), tables_dir,
                                      timeseries)) for c in to_run]
        with contextlib.closing(run_local(case_func, tasks, jobs, timeout_s, preload)) as it:
            for result in it:
                yield by_id[result.key], result
        return
    tasks = [(c.case_id, CaseTask(c, None, tables_dir, timeseries)) for c in to_run]
    with (_dask_client(scheduler, jobs) as client,
          contextlib.closing(run_dask(case_func, tasks, client, timeout_s, preload)) as it):
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
) -> pd.DataFrame:
    """Run every case of the matrix; return the final results (as :func:`read_results`).

    Writes ``out_dir/results.csv``, ``out_dir/cases/<case_id>/`` (time series and summary),
    ``table2.md`` and ``table2.png``. ``scheduler``: None for local worker processes,
    ``"local"`` for a Dask LocalCluster of ``jobs`` workers, else a Dask scheduler address.
    ``case_func`` runs one :class:`CaseTask` and returns ``{"summary", "files"}`` like
    :func:`run_matrix_case` (the default); it must be a module-level function.

    Bad input raises InputError before anything is written or run: the matrix itself
    (:func:`~eoam_sumo.matrix.load_matrix`), its scenario files and every swept speed and
    friction against the lookup tables in ``tables_dir`` (default: the co-simulation's,
    :func:`~eoam_sumo.matrix.check_matrix`). A case that fails is a ``failed`` row.
    """
    from tqdm import tqdm

    from eoam_sumo.batch.probabilities import write_probabilities
    from eoam_sumo.batch.report import write_report

    if not (isinstance(jobs, int) and jobs >= 1):
        raise InputError(f"--jobs {jobs!r} must be an integer >= 1")
    if not timeout_s > 0:
        raise InputError(f"--timeout-s {timeout_s!r} must be > 0")
    if timeseries not in TIMESERIES_FORMATS:
        raise InputError(f"--timeseries {timeseries!r} is not one of "
                         f"{', '.join(TIMESERIES_FORMATS)}")
    matrix: Matrix = load_matrix(Path(matrix_path))
    check_matrix(matrix, tables_dir)
    cases = matrix.cases()
    paper = matrix.paper_outcomes()
    out_dir = Path(out_dir)
    results_path = out_dir / RESULTS_FILE
    try:
        (out_dir / CASES_DIR).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"output folder {out_dir} cannot be written: {exc.strerror}") from exc
    kept = (_kept_rows(results_path, cases) if resume and results_path.is_file()
            else pd.DataFrame(columns=list(COLUMNS), dtype=str))
    done = set(kept["case_id"])
    to_run = [c for c in cases if c.case_id not in done]
    log = _RowLog(results_path, kept)
    bar = tqdm(total=len(cases), initial=len(done), unit="case", desc="cases", file=sys.stderr,
               disable=not progress, dynamic_ncols=True)
    failed = 0
    try:
        for case, result in _results(to_run, out_dir, jobs, scheduler, timeout_s, case_func,
                                     tables_dir, timeseries):
            row = result_row(case, result, paper.get(case.case_id))
            _store_case_files(out_dir / case_dir_of(case.case_id), result, row["status"] == "ok")
            log.add(row)
            failed += row["status"] != "ok"
            bar.set_postfix(failed=failed, refresh=False)
            bar.update(1)
    finally:
        bar.close()
        log.close()
    results = _finalise(results_path, cases, paper)
    if matrix.sample is None:
        write_report(out_dir, results)
    else:
        write_probabilities(out_dir, results)
    return results


def _raise_interrupt(signum, frame):
    raise KeyboardInterrupt


def run_batch_cli(args) -> int:
    """``eoam-sumo batch``: run the batch; SIGTERM stops it like Ctrl-C (rows kept).

    Returns 0 when every case ran, :data:`EXIT_CASES_FAILED` when at least one failed (after
    results.csv and the report are written; each failed case and then the count on stderr).
    Bad input raises InputError before any case runs (exit status 2 in ``cli.main``).
    """
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        results = run_batch(args.matrix, args.out, jobs=args.jobs, scheduler=args.scheduler,
                            resume=args.resume, timeout_s=args.timeout_s,
                            progress=not args.no_progress, timeseries=args.timeseries)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    failed = results[results["status"] != "ok"]
    results_path = Path(args.out) / RESULTS_FILE
    report = ("outcome probabilities in " + str(Path(args.out) / "outcome_probabilities.csv")
              if results["draw"].notna().any() else f"Table 2 in {Path(args.out) / 'table2.md'}")
    print(f"{len(results)} cases, {len(results) - len(failed)} ok, {len(failed)} failed; "
          f"results in {results_path}, {report}")
    if failed.empty:
        return 0
    for _, row in failed.iterrows():
        print(f"failed: {row['case_id']}: {row['error']}", file=sys.stderr)
    print(f"eoam-sumo: {len(failed)} of {len(results)} cases failed; their errors are in the "
          f"'error' column of {results_path}", file=sys.stderr)
    return EXIT_CASES_FAILED
