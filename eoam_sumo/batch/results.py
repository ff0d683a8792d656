"""results.csv of a batch: its columns (derived from the case parameters and the typed run
summary), a row from a case's result, reading it back, and the rows an earlier batch leaves
worth keeping.
"""

from __future__ import annotations

import csv
import io
import json
import math
import numbers
import os
import threading
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.batch.case import NUMERIC_PARAMETERS, PARAMETERS, CaseParameters
from eoam_sumo.batch.inputs import INPUTS_COLUMN
from eoam_sumo.batch.pool import TaskResult
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.matrix import Case
from eoam_sumo.sim.summary import FIELDS, NUMERIC_FIELDS, TIMING_FIELDS
from eoam_sumo.textfiles import read_utf8

RESULTS_FILE = "results.csv"
CASES_DIR = "cases"
#: summary.json key -> results.csv column where the names differ (the case's own ``mu`` is
#: the requested friction, empty for a case on each lane's own; the summary's is the one
#: measured under the ego at the start).
RENAMED = {"mu": "mu_at_start"}
#: results.csv columns: the case's parameters, its status, the summary fields, where it lives.
PARAM_COLUMNS = tuple(p for p in PARAMETERS if p != "sumocfg")
#: the summary's fields, but those that repeat a case parameter (policy, V2X settings)
SUMMARY_COLUMNS = tuple(c for c in (RENAMED.get(f, f) for f in FIELDS) if c not in PARAMETERS)
COLUMNS = (
    *PARAM_COLUMNS,
    "status",
    "paper_outcome",
    *SUMMARY_COLUMNS,
    "error",
    "case_dir",
    "sumocfg",
    INPUTS_COLUMN,
)
#: Columns that measure the machine, not the physics: they differ between runs.
TIMING_COLUMNS = TIMING_FIELDS
NUMERIC_COLUMNS = (
    *NUMERIC_PARAMETERS,
    *(c for c in (RENAMED.get(f, f) for f in NUMERIC_FIELDS) if c in SUMMARY_COLUMNS),
)


def case_dir_of(case_id: str) -> str:
    """Case folder relative to the batch folder (the ``case_dir`` column)."""
    return f"{CASES_DIR}/{case_id}"


def result_row(
    case: Case,
    result: TaskResult,
    paper_outcome: str | None = None,
    inputs_sha256: str | None = None,
) -> dict:
    """One results.csv row from a case and its task result (failed rows: empty summary);
    ``paper_outcome`` is the published colour of the case, if any; ``inputs_sha256`` the
    digest of its files as they were when it ran (:mod:`eoam_sumo.batch.inputs`)."""
    row = dict.fromkeys(COLUMNS)
    params = CaseParameters.of(case)
    row.update({p: getattr(params, p) for p in PARAMETERS})
    row.update(paper_outcome=paper_outcome, case_dir=case_dir_of(case.case_id))
    row[INPUTS_COLUMN] = inputs_sha256
    summary = result.value.get("summary") if isinstance(result.value, dict) else None
    if not result.ok or not isinstance(summary, dict):
        row.update(
            status="failed",
            error=_one_line(result.error or "the case function returned no summary"),
        )
        return row
    row["status"] = "ok"
    for key, value in summary.items():
        column = RENAMED.get(key, key)
        if column in SUMMARY_COLUMNS:
            row[column] = _cell(value)
    return row


def _one_line(text: str) -> str:
    return " | ".join(p.strip() for p in str(text).splitlines() if p.strip())


def _cell(value):
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True)
    if isinstance(value, (list, tuple)):
        return "-".join(str(v) for v in value)
    if isinstance(value, str):
        return _one_line(value)
    return value


def csv_text(rows: list[dict], header: bool) -> str:
    """Rows as results.csv text (with the header line if ``header``)."""
    return pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(index=False, header=header)


def row_text(row: dict) -> str:
    """One row as results.csv text, byte for byte ``csv_text([row], header=False)`` (pandas'
    text of a one-row frame: None and NaN empty, a bool ``True``/``False``, an integer in
    digits, a float in its shortest repr, text as it is, quoted where the csv module must)
    at a fiftieth of its cost: a batch adds one row per finished case."""
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow([_cell_text(row.get(c)) for c in COLUMNS])
    return out.getvalue()


def _cell_text(value) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        value = float(value)
        return "" if math.isnan(value) else repr(value)
    return str(value)


def read_rows(path: Path) -> pd.DataFrame:
    """results.csv as text cells; a last line cut short by an interruption is dropped."""
    text = read_utf8(path, "results file")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    if not text.strip():
        return pd.DataFrame(columns=list(COLUMNS), dtype=str)
    try:
        frame = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read as a results file: {exc}") from exc
    if tuple(frame.columns) != COLUMNS:
        raise InputError(
            f"{path}: its columns are not those of this version's results.csv; "
            "use another --out folder or remove the file"
        )
    return frame


def read_results(path: Path) -> pd.DataFrame:
    """A results.csv with numbers as floats (empty = NaN) and every other column as text."""
    frame = read_rows(Path(path))
    for column in NUMERIC_COLUMNS:
        frame[column] = pd.to_numeric(frame[column].replace("", None), errors="coerce")
    return frame


class RowLog:
    """results.csv open for appending: one row per finished case, written and flushed at
    once (a batch killed afterwards keeps it), and synced to disk by a thread of its own, so
    the caller (who hands the next case out) does not wait for the disk (an ``os.fsync``
    took 28 ms a row here). One sync covers every row written before it; ``close`` waits for
    the last."""

    def __init__(self, path: Path, kept: pd.DataFrame):
        self.path = path
        kept_text = kept.to_csv(index=False) if len(kept) else csv_text([], header=True)
        write_atomic(path, kept_text, durable=True)
        self.fh = open(path, "a", encoding="utf-8", newline="")  # noqa: SIM115 - closed in close()
        self._unsynced = threading.Event()
        self._closing = False
        self._error: OSError | None = None
        self._syncer = threading.Thread(target=self._sync_rows, name="results-sync", daemon=True)
        self._syncer.start()

    def add(self, row: dict) -> None:
        self.fh.write(row_text(row))
        self.fh.flush()
        self._unsynced.set()

    def _sync_rows(self) -> None:
        """Sync the file whenever rows were written since the last sync, until closed."""
        while True:
            self._unsynced.wait()
            self._unsynced.clear()
            if self._closing:
                return
            try:
                os.fsync(self.fh.fileno())
            except OSError as exc:  # reported by close()
                self._error = exc
                return

    def close(self) -> None:
        """Stop the syncing thread, sync what it has not and close the file."""
        self._closing = True
        self._unsynced.set()
        self._syncer.join()
        try:
            self.fh.flush()
            if self._error is None:
                os.fsync(self.fh.fileno())
        finally:
            self.fh.close()
        if self._error is not None:
            raise InputError(f"{self.path} cannot be written: {self._error.strerror}")


#: results.csv columns that, besides the case id, make a kept row the same case for --resume:
#: every case parameter but the draw's number (drawn values and seeds included).
RESUME_KEYS = tuple(p for p in PARAMETERS if p not in ("case_id", "draw"))


def _case_keys(cases: list[Case]) -> dict[str, tuple[str, ...]]:
    """case_id -> its ``RESUME_KEYS`` settings as results.csv writes them."""
    params = [asdict(CaseParameters.of(c)) for c in cases]
    frame = pd.DataFrame(
        [(p["case_id"], *(p[k] for k in RESUME_KEYS)) for p in params],
        columns=["case_id", *RESUME_KEYS],
    )
    text = pd.read_csv(io.StringIO(frame.to_csv(index=False)), dtype=str, keep_default_na=False)
    return {r[0]: tuple(r[1:]) for r in text.itertuples(index=False)}


def kept_rows(
    path: Path, cases: list[Case], inputs: dict[str, str], files: tuple[str, ...] = ()
) -> pd.DataFrame:
    """Rows of an earlier run worth keeping (``--resume``): the matrix's cases finished and
    still the same case (same id, the same parameters as written in results.csv, and the
    same bytes in its files: ``inputs``, case id -> ``inputs_sha256`` now) whose folder is
    still there with ``files`` in it (the case files of the ``--timeseries`` asked for now),
    then every row of a case not in the matrix (a larger matrix's, whose case folders
    stay)."""
    rows = read_rows(path)
    want = _case_keys(cases)
    same = [
        want.get(cid) == key and inputs.get(cid) == digest
        for cid, key, digest in zip(
            rows["case_id"], zip(*(rows[k] for k in RESUME_KEYS)), rows[INPUTS_COLUMN]
        )
    ]
    kept_dirs = [_has_files(path.parent / case_dir_of(cid), files) for cid in rows["case_id"]]
    keep = (
        (rows["status"] == "ok").to_numpy()
        & pd.Series(same, dtype=bool).to_numpy()
        & pd.Series(kept_dirs, dtype=bool).to_numpy()
    )
    others = (~rows["case_id"].isin(list(want))).to_numpy()
    return rows[keep | others].drop_duplicates("case_id", keep="last")


def _has_files(folder: Path, files: tuple[str, ...]) -> bool:
    return folder.is_dir() and all((folder / name).is_file() for name in files)


def finalise(path: Path, cases: list[Case], paper: dict[str, str]) -> pd.DataFrame:
    """Rewrite results.csv atomically: one row per case of the matrix in its order, with the
    paper's colours of the matrix as it is now, then the rows kept of cases not in it; return
    the matrix's rows (as :func:`read_results`)."""
    rows = read_rows(path).drop_duplicates("case_id", keep="last")
    order = {c.case_id: i for i, c in enumerate(cases)}
    mine = rows["case_id"].isin(order)
    ours = rows[mine]
    ours = ours.iloc[ours["case_id"].map(order).argsort(kind="stable")].copy()
    ours["paper_outcome"] = [paper.get(cid, "") for cid in ours["case_id"]]
    write_atomic(path, pd.concat([ours, rows[~mine]]).to_csv(index=False), durable=True)
    results = read_results(path)
    return results[results["case_id"].isin(order)].reset_index(drop=True)
