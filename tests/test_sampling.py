"""Monte Carlo sampling: distributions, the [sample] table, draws, Wilson intervals (no SUMO)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.errors import InputError
from eoam_sumo.matrix import load_matrix
from eoam_sumo.sampling import wilson_interval

ROOT = Path(__file__).resolve().parents[1]
CFG = ROOT / "scenarios" / "baseline.sumocfg"


def _matrix(
    tmp_path,
    sample: str,
    sweep: str = "ego_speed_kmh = [120, 90]\nmu = [1.0, 0.3]",
    scenario: str = "",
) -> Path:
    path = tmp_path / "m.toml"
    path.write_text(
        f'[scenario]\nsumocfg = "{CFG}"\n{scenario}\n[sweep]\n{sweep}\n[sample]\n{sample}\n'
    )
    return path


@pytest.mark.parametrize(
    ("count", "n", "low", "high"),
    [
        # Newcombe (1998), Statistics in Medicine 17:857-872, Table I, method 3 (Wilson score)
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ],
)
def test_wilson_interval_against_published_values(count, n, low, high):
    assert wilson_interval(count, n) == pytest.approx((low, high), abs=5e-5)


@given(st.integers(1, 10_000).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_wilson_interval_contains_p_and_stays_in_unit_interval(cn):
    count, n = cn
    low, high = wilson_interval(count, n)
    assert 0.0 <= low <= count / n <= high <= 1.0
    assert high - low > 0.0


def test_draws_are_seeded_and_in_their_usual_columns(tmp_path):
    path = _matrix(
        tmp_path,
        "draws = 5\nseed = 7\noncoming_start_m = { uniform = [250, 550] }\n"
        "mu_belief = { normal = [0.7, 0.2], clip = [0.3, 1.0] }\n"
        'radar_model = { choice = ["ideal", "automotive"] }',
    )
    cases = load_matrix(path).cases()
    assert len(cases) == 2 * 2 * 5
    assert cases[0].case_id == "v120_mu1.0_d0" and cases[-1].case_id == "v90_mu0.3_d4"
    assert [c.draw for c in cases[:5]] == list(range(5))
    assert all(250 <= c.oncoming_start_m <= 550 for c in cases)
    assert all(0.3 <= c.mu_belief <= 1.0 for c in cases)
    assert {c.radar_model for c in cases} == {"ideal", "automotive"}
    assert len({c.seed for c in cases}) == len(cases)  # every draw its own run seed
    assert load_matrix(path).cases() == cases  # same seed, same draws
    other = _matrix(tmp_path, "draws = 5\nseed = 8\noncoming_start_m = { uniform = [250, 550] }")
    assert [c.oncoming_start_m for c in load_matrix(other).cases()] != [
        c.oncoming_start_m for c in cases
    ]


def test_a_groups_draws_do_not_depend_on_the_other_groups(tmp_path):
    sample = "draws = 4\nseed = 1\naro_hold_s = { uniform = [0, 3] }"
    both = load_matrix(_matrix(tmp_path, sample)).cases()
    one = load_matrix(_matrix(tmp_path, sample, "ego_speed_kmh = [90]\nmu = [0.3]")).cases()
    assert [c for c in both if c.case_id.startswith("onc-none_v90_mu0.3")] == one


def test_uniform_draws_are_uniform(tmp_path):
    path = _matrix(
        tmp_path,
        "draws = 4000\nseed = 2\naro_hold_s = { uniform = [1, 3] }",
        "ego_speed_kmh = [120]\nmu = [1.0]",
    )
    values = np.array([c.aro_hold_s for c in load_matrix(path).cases()])
    assert values.mean() == pytest.approx(2.0, abs=0.03)
    assert values.std() == pytest.approx(2 / math.sqrt(12), rel=0.03)


def test_sampled_speed_and_friction_leave_the_sweep(tmp_path):
    path = _matrix(
        tmp_path,
        "draws = 3\nmu = { choice = [0.3, 0.7] }\n"
        "ego_speed_kmh = { normal = [100, 10], clip = [60, 140] }",
        'oncoming_start_m = ["none", 400]',
    )
    cases = load_matrix(path).cases()
    assert [c.case_id for c in cases[:3]] == ["onc-none_d0", "onc-none_d1", "onc-none_d2"]
    assert all(c.mu in (0.3, 0.7) and 60 <= c.ego_speed_kmh <= 140 for c in cases)


@pytest.mark.parametrize(
    ("sample", "message"),
    [
        ("seed = 1", "needs the key 'draws'"),
        ("draws = 0", "draws = 0"),
        ("draws = 2.5", "draws = 2.5"),
        ("draws = 2\nseed = -1", "seed = -1"),
        ("draws = 2\naro_hold_s = 3", "aro_hold_s = 3 must be a distribution"),
        ("draws = 2\naro_hold_s = { uniform = [3, 1] }", "aro_hold_s: uniform = [3, 1]"),
        ("draws = 2\naro_hold_s = { uniform = [-1, 1] }", "aro_hold_s: low -1.0: is outside"),
        ("draws = 2\naro_hold_s = { uniform = [1] }", "aro_hold_s: uniform = [1]"),
        (
            "draws = 2\naro_hold_s = { normal = [1, 0.5] }",
            "aro_hold_s: normal = [1, 0.5] needs clip",
        ),
        ("draws = 2\naro_hold_s = { normal = [1, 0], clip = [0, 2] }", "needs sd > 0"),
        ("draws = 2\naro_hold_s = { normal = [1, 1], clip = [-1, 2] }", "clip low -1.0"),
        ("draws = 2\naro_hold_s = { uniform = [0, 1], clip = [0, 1] }", "clip applies to a normal"),
        ("draws = 2\naro_hold_s = { gamma = [1, 1] }", "must name one of uniform, normal, choice"),
        ("draws = 2\naro_hold_s = { choice = [] }", "choice = [] must be a non-empty list"),
        ('draws = 2\nradar_model = { choice = ["ideal", "lidar"] }', "radar_model: choice 'lidar'"),
        ("draws = 2\nradar_model = { uniform = [0, 1] }", "radar_model: low 0.0"),
        ("draws = 2\nmu_belief = { uniform = [0.5, 1.5] }", "mu_belief: high 1.5"),
        ("draws = 2\ncolour = { choice = [1] }", "'colour' cannot be sampled"),
        ("draws = 2\nmu = { choice = [0.3] }", "'mu' is both in [sweep] and sampled"),
        ('draws = 2\npolicy = { choice = ["paper", "careful"] }', "policy: choice 'careful'"),
        ("draws = 2\nv2x_loss = { uniform = [0, 1] }", "v2x_loss: high 1.0: is outside [0, 1)"),
    ],
)
def test_bad_samples_name_key_and_value(tmp_path, sample, message):
    with pytest.raises(InputError, match=None) as err:
        load_matrix(_matrix(tmp_path, sample))
    assert message in str(err.value) and str(tmp_path / "m.toml") in str(err.value)


def test_scenario_settings_and_their_errors(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(
        f'[scenario]\nsumocfg = "{CFG}"\nmu_belief = 1.0\nradar_model = "automotive"'
        "\nseed = 3\n[sweep]\nego_speed_kmh = [120]\nmu = [0.3]\n"
    )
    (case,) = load_matrix(path).cases()
    assert (case.mu_belief, case.radar_model, case.seed, case.draw) == (1.0, "automotive", 3, None)
    for bad, message in (
        ('mu_belief = "dry"', "mu_belief 'dry'"),
        ('radar_model = "sonar"', "radar_model 'sonar'"),
        ("seed = -2", "seed = -2"),
    ):
        path.write_text(
            f'[scenario]\nsumocfg = "{CFG}"\n{bad}\n[sweep]\nego_speed_kmh = [120]\nmu = [0.3]\n'
        )
        with pytest.raises(InputError, match=None) as err:
            load_matrix(path)
        assert message in str(err.value)
    with pytest.raises(InputError, match=r"\[scenario\] seed with a \[sample\] table"):
        load_matrix(_matrix(tmp_path, "draws = 2", scenario="seed = 1"))


def test_policy_and_v2x_settings_can_be_sampled(tmp_path):
    path = _matrix(
        tmp_path,
        'draws = 20\nseed = 4\npolicy = { choice = ["paper", "safe"] }\n'
        "v2x_penetration = { uniform = [0.5, 1.0] }",
        "ego_speed_kmh = [120]\nmu = [0.3]",
    )
    cases = load_matrix(path).cases()
    assert {c.policy for c in cases} == {"paper", "safe"}
    assert all(0.5 <= c.v2x_penetration <= 1.0 for c in cases)


def test_a_draw_keeps_its_id_and_values_when_more_draws_are_asked(tmp_path):
    """Ids were zero-padded to the number of draws (_d0 with 6 draws, _d00 with 12): a study
    extended with --resume ran every draw again and kept the old rows as duplicates."""
    six = _matrix(tmp_path, "draws = 6\noncoming_start_m = { uniform = [250, 550] }")
    few = load_matrix(six).cases()
    twelve = _matrix(tmp_path, "draws = 12\noncoming_start_m = { uniform = [250, 550] }")
    many = {c.case_id: c for c in load_matrix(twelve).cases()}
    for case in few:
        assert many[case.case_id].oncoming_start_m == case.oncoming_start_m
        assert many[case.case_id].seed == case.seed
