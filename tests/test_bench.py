"""The benchmark runs on tiny settings and writes every key, each one documented in
docs/performance.md (no timing is asserted)."""

from __future__ import annotations

import json
import math
import re
from importlib import machinery
from pathlib import Path

import pytest

from eoam_sumo.bench import TARGETS, run_bench
from eoam_sumo.sim import cosim

pytestmark = pytest.mark.sumo
PERFORMANCE = Path(__file__).resolve().parents[1] / "docs" / "performance.md"

KEYS = (
    "realtime_factor",
    "sumo_only_realtime_factor",
    "tables_wall_s",
    "batch_wall_s",
    "batch_cases",
    "jobs",
    "control_us_per_step",
    "plant_substeps_per_s",
    "peak_rss_mb",
    "cosim_over_sumo_cost",
    "traffic_vehicles",
    "traffic_cosim_wall_s",
    "traffic_sumo_only_wall_s",
    "floor_over_sumo_cost",
)


def test_quick_bench_writes_every_key(tmp_path):
    result = run_bench(tmp_path, quick=True)
    saved = json.loads((tmp_path / "bench.json").read_text())
    assert saved == json.loads(json.dumps(result))
    for key in KEYS:
        assert key in saved and math.isfinite(saved[key]) and saved[key] > 0, key
    assert saved["batch_cases"] == 2 and saved["jobs"] == 2
    loader = cosim.__spec__.loader  # what ran the step loop: an extension module or a source
    assert saved["compiled"] is isinstance(loader, machinery.ExtensionFileLoader)
    assert set(saved["targets"]) == set(TARGETS)
    assert math.isfinite(saved["traffic_us_per_user_step"])
    assert set(saved) - {"quick", "targets"} == _documented_keys()


def _documented_keys() -> set[str]:
    """The keys of docs/performance.md's table under "What is measured"."""
    text = PERFORMANCE.read_text(encoding="utf-8")
    section = text.split("## What is measured", 1)[1].split("\n## ", 1)[0]
    rows = [line.split("|")[1] for line in section.splitlines() if line.startswith("| `")]
    return {key for cell in rows for key in re.findall(r"`([a-z_0-9]+)`", cell)}
