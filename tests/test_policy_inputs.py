"""Policy and V2X settings as matrix keys and run options: accepted values reach every case,
bad ones are one clear line naming the key (exit 2); the report shows the sight distances."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch.policy_report import policy_line, policy_title, sight_markdown
from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import load_matrix

ROOT = Path(__file__).resolve().parents[1]
SWEEP = "[sweep]\nego_speed_kmh = [120]\nmu = [1.0, 0.3]\n"


def _matrix(tmp_path: Path, scenario: str) -> Path:
    (tmp_path / "s.sumocfg").write_text("<configuration/>")
    path = tmp_path / "m.toml"
    path.write_text(f'[scenario]\nsumocfg = "s.sumocfg"\n{scenario}\n{SWEEP}')
    return path


def test_policy_and_v2x_keys_reach_every_case(tmp_path):
    path = _matrix(
        tmp_path,
        'policy = "safe"\nv2x_range_m = 800\nv2x_latency_s = 0.2\n'
        "v2x_loss = 0.1\nv2x_penetration = 0.5",
    )
    cases = load_matrix(path).cases()
    assert {
        (c.policy, c.v2x_range_m, c.v2x_latency_s, c.v2x_loss, c.v2x_penetration) for c in cases
    } == {("safe", 800.0, 0.2, 0.1, 0.5)}
    default = load_matrix(_matrix(tmp_path, "")).cases()[0]
    assert (default.policy, default.v2x_range_m) == ("paper", 0.0)


def test_the_shipped_safe_matrices_load():
    assert {c.policy for c in load_matrix(ROOT / "scenarios/table2_safe.toml").cases()} == {"safe"}
    v2x = load_matrix(ROOT / "scenarios/table2_safe_v2x.toml").cases()
    assert len(v2x) == 64 and {c.v2x_range_m for c in v2x} == {1000.0}


@pytest.mark.parametrize(
    "scenario, needle",
    [
        ('policy = "careful"', "policy = 'careful' must be one of 'paper', 'safe'"),
        ('policy = "safe"\nv2x_loss = 1.0', "v2x_loss = 1.0 must be a number >= 0 and < 1"),
        ('policy = "safe"\nv2x_penetration = 1.5', "v2x_penetration = 1.5 must be a number"),
        ('policy = "safe"\nv2x_range_m = -5', "v2x_range_m = -5 must be a number >= 0"),
        ('policy = "safe"\nv2x_latency_s = "fast"', "v2x_latency_s = 'fast'"),
        ("v2x_range_m = 500", 'v2x_range_m = 500 needs policy = "safe"'),
        ('polcy = "safe"', "did you mean 'policy'"),
    ],
)
def test_bad_policy_or_v2x_keys_name_the_key(tmp_path, scenario, needle):
    with pytest.raises(InputError, match=r"m\.toml") as err:
        load_matrix(_matrix(tmp_path, scenario))
    assert needle in str(err.value)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--policy", "careful"], "invalid choice: 'careful'"),
        (["--v2x-range-m", "500"], "--v2x-range-m needs --policy safe"),
        (["--policy", "safe", "--v2x-loss", "1"], "--v2x-loss 1 must be in [0, 1)"),
        (["--policy", "safe", "--v2x-penetration", "2"], "--v2x-penetration 2 must be in [0, 1]"),
        (["--policy", "safe", "--v2x-range-m", "-1"], "--v2x-range-m -1 must be >= 0"),
    ],
)
def test_bad_run_options_exit_2_with_one_line(capsys, tmp_path, argv, needle):
    status = main(
        ["run", str(ROOT / "scenarios/baseline.sumocfg"), "--out", str(tmp_path / "o"), *argv]
    )
    err = capsys.readouterr().err
    assert status == 2
    assert needle in err and len(err.strip().splitlines()) == 1


def _results(**cols) -> pd.DataFrame:
    base = {
        "oncoming_start_m": [float("nan"), 300.0],
        "ego_speed_kmh": [120.0, 120.0],
        "mu": [1.0, 1.0],
        "policy": ["safe", "safe"],
        "radar_range_m": [float("nan")] * 2,
        "v2x_range_m": [1000.0, 1000.0],
        "v2x_latency_s": [0.1, 0.1],
        "v2x_loss": [0.0, 0.0],
        "v2x_penetration": [1.0, 1.0],
        "sight_gate": ["passed", "refused"],
        "sight_needed_m": [499.4, 499.4],
        "sight_known_free_m": [990.0, 192.0],
    }
    base.update(cols)
    return pd.DataFrame(base)


def test_the_report_names_the_policy_and_each_cells_sight_distance():
    res = _results()
    assert policy_title(res) == "Table 2, policy safe, V2X 1000 m"
    assert "V2X range 1000 m, latency 0.1 s, loss 0, penetration 1" in policy_line(res)
    md = sight_markdown(res)
    assert "| No oncoming | 120 km/h | 499 / 990 ✓ |" in md
    assert "| Oncoming, 300 m | 120 km/h | 499 / 192 ✗ |" in md
    paper = _results(policy=["paper"] * 2, v2x_range_m=[0.0, 0.0], sight_gate=["", ""])
    assert policy_title(paper) == "Table 2" and sight_markdown(paper) == ""
