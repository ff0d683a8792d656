"""A test's files: ``timeseries.csv`` per run, ``summary.json``.

A single-run test writes ``DIR/timeseries.csv``; the sine with dwell writes
``DIR/runs/<run>/timeseries.csv`` per run (``sis``, ``amp_1.5A``, ...)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from eoam_sumo.fileio import writable_dir, write_atomic
from eoam_sumo.vehicle_tests.common import VehicleTestResult, verdict
from eoam_sumo.vehicle_tests.harness import COLUMNS, Run


def run_path(out: Path, result: VehicleTestResult, run: Run) -> Path:
    """Where a run's time series goes."""
    if len(result.runs) == 1:
        return out / "timeseries.csv"
    return out / "runs" / run.label / "timeseries.csv"


def timeseries_csv(run: Run) -> str:
    """A run's time series as CSV text: ``COLUMNS``, one row per 10 ms."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(COLUMNS)
    columns = [run[name] for name in COLUMNS]
    for k in range(len(columns[0])):
        writer.writerow([f"{col[k]:.9g}" for col in columns])
    return buffer.getvalue()


def write_result(result: VehicleTestResult, out: Path) -> dict:
    """Write every run's CSV and ``summary.json`` (with the verdict and the runs' files) into
    ``out``; the summary as written."""
    out = writable_dir(out)
    files = {}
    for run in result.runs:
        path = run_path(out, result, run)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, timeseries_csv(run))
        files[run.label] = str(path.relative_to(out))
    summary = {**result.summary, "verdict": verdict(result.summary), "timeseries": files}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2) + "\n")
    return summary
