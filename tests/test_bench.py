"""The benchmark runs on tiny settings and writes every key, each one documented in
docs/performance.md (no timing is asserted); ``--against``: the ratios from the medians, its
bad input, a quick comparison with HEAD."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import sys
from importlib import machinery
from pathlib import Path

import pytest

from eoam_sumo import bench
from eoam_sumo.bench import (
    AGAINST_TARGETS,
    TARGETS,
    _summarise,
    compare_against,
    export_revision,
    run_bench,
)
from eoam_sumo.errors import InputError
from eoam_sumo.sim import cosim

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


@pytest.mark.sumo
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


@pytest.mark.skipif(shutil.which("ldd") is None, reason="needs ldd to read the executable's links")
def test_the_interpreter_record_says_whether_its_core_is_a_shared_libpython():
    record = bench.interpreter()
    ldd = ["ldd", sys.executable]  # a static executable: exit status 1, no libpython
    linked = subprocess.run(ldd, check=False, capture_output=True, text=True).stdout
    assert record["shared_libpython"] is ("libpython" in linked)
    assert record["executable"] == sys.executable
    assert record["version"] == "{}.{}.{}".format(*sys.version_info[:3])
    core = "shared libpython" if record["shared_libpython"] else "core in the executable"
    assert bench.interpreter_text(record).endswith(core)


def test_summarise_takes_medians_per_tree_and_their_ratios():
    def probe(load, **figures):
        return {"load_avg_1min": load, "compiled": False, **figures}

    samples = {
        "previous": [
            probe(1.0, plant_us_per_step=5.0, plant_cpu_us_per_step=4.0),
            probe(2.0, plant_us_per_step=7.0, plant_cpu_us_per_step=6.0),
            probe(1.5, plant_us_per_step=6.0, plant_cpu_us_per_step=5.0),
            probe(1.0, batch_wall_s=10.0, batch_cpu_s=20.0),
        ],
        "current": [
            probe(3.0, plant_us_per_step=13.0, plant_cpu_us_per_step=9.0),
            probe(1.0, plant_us_per_step=11.0, plant_cpu_us_per_step=11.0),
            probe(2.0, plant_us_per_step=12.0, plant_cpu_us_per_step=10.0),
            probe(2.0, batch_wall_s=14.0, batch_cpu_s=22.0),
        ],
    }
    result = _summarise(samples)
    assert result["previous_plant_us_per_step"] == 6.0
    assert result["current_plant_us_per_step"] == 12.0
    assert result["plant_us_per_step_ratio"] == 2.0
    assert result["plant_cpu_us_per_step_ratio"] == 2.0
    assert result["batch_wall_ratio"] == pytest.approx(1.4)
    assert result["batch_cpu_ratio"] == pytest.approx(1.1)
    assert result["previous_load_avg_1min"] == [1.0, 2.0]
    assert result["current_load_avg_1min"] == [1.0, 3.0]
    met = {k: v["met"] for k, v in result["targets"].items()}
    assert met == {
        "plant_us_per_step_ratio": True,
        "plant_cpu_us_per_step_ratio": True,
        "batch_wall_ratio": False,
        "batch_cpu_ratio": True,
    }


def test_against_an_unknown_revision_is_one_line_and_exit_2(tmp_path):
    if not _in_git_checkout():
        pytest.skip("not a git checkout")
    with pytest.raises(InputError, match="unknown revision 'no-such-revision-xyz'"):
        export_revision("no-such-revision-xyz", tmp_path / "tree")
    command = ["bench", "--against", "no-such-revision-xyz", "--out", str(tmp_path / "out")]
    done = subprocess.run(
        [sys.executable, "-m", "eoam_sumo", *command],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1
    assert "unknown revision" in done.stderr


def test_against_outside_a_git_checkout_is_an_input_error(tmp_path, monkeypatch):
    monkeypatch.setattr(bench, "ROOT", tmp_path)  # tmp_path: in no git checkout
    with pytest.raises(InputError, match="is not a git checkout"):
        export_revision("HEAD", tmp_path / "tree")


@pytest.mark.sumo
def test_quick_against_head_writes_both_trees_and_the_ratios(tmp_path):
    if not _in_git_checkout():
        pytest.skip("not a git checkout")
    result = compare_against("HEAD", tmp_path, quick=True, pairs=1)
    saved = json.loads((tmp_path / "bench-against.json").read_text())
    assert saved == json.loads(json.dumps(result))
    for side in ("previous", "current"):
        for key in ("plant_us_per_step", "plant_cpu_us_per_step", "batch_wall_s", "batch_cpu_s"):
            assert math.isfinite(saved[f"{side}_{key}"]) and saved[f"{side}_{key}"] > 0
    assert set(saved["targets"]) == set(AGAINST_TARGETS)
    assert all(math.isfinite(saved[k]) and saved[k] > 0 for k in AGAINST_TARGETS)


def _in_git_checkout() -> bool:
    done = subprocess.run(
        ["git", "-C", str(bench.ROOT), "rev-parse", "--is-inside-work-tree"],
        capture_output=True,
        check=False,
    )
    return done.returncode == 0


def test_table2_changes_counts_colour_and_partner_changes_and_the_largest_figure_moves():
    import pandas as pd

    ref = pd.DataFrame(
        {
            "case_id": ["a", "b", "c"],
            "outcome": ["green", "red", "yellow"],
            "collision_with": ["none", "oncoming", "aro"],
            "impact_speed_mps": [0.0, 20.0, 5.0],
            "min_gap_aro_m": [4.0, float("nan"), 0.0],
        }
    )
    got = ref.copy()
    got.loc[1, ["outcome", "impact_speed_mps"]] = ["orange", 19.7]
    got.loc[2, ["collision_with", "min_gap_aro_m"]] = ["none", 0.25]
    got.loc[0, "min_gap_aro_m"] = 3.9
    cmp = bench.table2_changes(ref, got)
    assert cmp["cases"] == 3
    assert cmp["colour_changes"] == ["b: red -> orange"]
    assert cmp["partner_changes"] == ["c: aro -> none"]
    assert cmp["max_abs_delta"]["impact_speed_mps"] == pytest.approx(0.3)
    assert cmp["max_abs_delta"]["min_gap_aro_m"] == pytest.approx(0.25)  # nan left out
    assert cmp["max_abs_delta"]["sim_time_s"] == 0.0  # not in the frames


def test_studies_keys_are_documented():
    text = PERFORMANCE.read_text(encoding="utf-8")
    keys = ("bench-studies.json", "table2_wall_s", "load_avg_start", "table2_vs_reference")
    for key in (*keys, "study_rows", *STUDY_ROW_KEYS, *bench.STUDIES):
        assert key in text, key
    assert bench.load_average() == [] or len(bench.load_average()) == 3


STUDY_ROW_KEYS = (
    "study",
    "runs",
    "study_runs",
    "sumo_step_s",
    "jobs",
    "wall_s",
    "cpu_s",
    "cpu_s_per_run",
    "load_avg_end",
    "goal_wall_s",
    "cosim_over_sumo_cost",
    "cosim_over_sumo_cpu_cost",
    "out",
)


def test_every_study_names_an_existing_matrix_or_protocol():
    from eoam_sumo.matrix import load_matrix
    from eoam_sumo.protocols.points import PROTOCOLS

    for name, study in bench.STUDIES.items():
        if study.protocol:
            assert study.source in PROTOCOLS, name
        else:
            assert load_matrix(Path(study.source)).cases(), name
    sizes = {n: len(load_matrix(Path(s.source)).cases()) for n, s in bench.STUDIES.items()
             if not s.protocol}  # fmt: skip
    assert sizes == {"table2": 64, "traffic-levels": 312, "vehicles": 1536, "monte-carlo": 10000}


def test_quick_takes_runs_spread_over_the_study():
    assert bench._spread(list(range(10)), quick=True) == [0, 5]
    assert bench._spread([7], quick=True) == [7]
    assert bench._spread(list(range(10)), quick=False) == list(range(10))


def test_an_unknown_study_is_one_line_and_exit_2(tmp_path):
    out = tmp_path / "out"
    done = subprocess.run(
        [sys.executable, "-m", "eoam_sumo", "bench", "--study", "tabel2", "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "'tabel2'" in done.stderr
    assert "monte-carlo" in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()
    assert bench.check_studies([]) == tuple(bench.STUDIES)
    assert bench.check_studies(["vehicles", "table2", "vehicles"]) == ("vehicles", "table2")


def _rows_written(folder: Path) -> int:
    import pandas as pd

    return len(pd.read_csv(folder / "results.csv"))


@pytest.mark.sumo
def test_quick_studies_write_each_step_and_the_changes_against_the_first(tmp_path):
    result = bench.run_studies(tmp_path, (0.01, 0.1), 1, True, ("table2", "protocol"))
    saved = json.loads((tmp_path / "bench-studies.json").read_text())
    assert saved == json.loads(json.dumps(result))
    first, second = saved["studies"]
    assert (first["sumo_step_s"], second["sumo_step_s"]) == (0.01, 0.1)
    assert "table2_vs_reference" not in first
    cmp = second["table2_vs_reference"]
    assert cmp["cases"] == 2 and cmp["colour_changes"] == [] and cmp["partner_changes"] == []
    for row in saved["studies"]:
        assert row["table2_cases"] == 2 and row["table2_wall_s"] > 0 and row["table2_cpu_s"] > 0
        assert row["cosim_over_sumo_cost"] > 0 and row["loop_cpu_us_per_step"] > 0
    rows = saved["study_rows"]
    assert [(r["study"], r["sumo_step_s"]) for r in rows] == [
        ("table2", 0.01),
        ("protocol", 0.01),
        ("table2", 0.1),
        ("protocol", 0.1),
    ]
    for row in rows:
        assert set(STUDY_ROW_KEYS) <= set(row)
        assert row["runs"] == bench.QUICK_RUNS == _rows_written(Path(row["out"]))
        assert row["study_runs"] == {"table2": 64, "protocol": 274}[row["study"]]
        assert row["cpu_s_per_run"] == pytest.approx(row["cpu_s"] / row["runs"])
        step = next(s for s in saved["studies"] if s["sumo_step_s"] == row["sumo_step_s"])
        assert row["cosim_over_sumo_cost"] == step["cosim_over_sumo_cost"]
    assert (tmp_path / "table2_100ms" / "results.csv").is_file()
    assert (tmp_path / "protocol_10ms" / "scorecard.md").is_file()
    table = bench.format_study_table(result).splitlines()
    assert table[1] == bench.interpreter_text(saved["python"])
    assert table[2].split(" | ")[:6] == ["study", "runs", "sumo step s", "jobs", "wall s", "goal s"]
    assert table[3].startswith("table2 | 2 of 64 | 0.01 | 1 | ") and len(table) == 7
    assert "0.1 |" in bench.format_studies(result)
