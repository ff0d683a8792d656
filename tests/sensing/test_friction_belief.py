"""The friction belief: known, a fixed assumption, and the estimator model (no SUMO)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.errors import InputError
from eoam_sumo.params import G_MPS2
from eoam_sumo.sensing.friction import EstimatorSettings, FrictionBelief, parse_mu_belief

DT = 0.01


def _drive(belief, true_mu, seconds, accel_mps2, t0=0.0):
    out = []
    for k in range(round(seconds / DT)):
        t = t0 + k * DT
        out.append((t, belief.mu(true_mu(t) if callable(true_mu) else true_mu, t, accel_mps2, 0.0)))
    return out


def test_known_and_fixed():
    assert FrictionBelief("known").mu(0.3, 0.0, 0.0, 0.0) == 0.3
    fixed = FrictionBelief(1.0)
    assert [fixed.mu(m, 0.01 * k, 5.0, 0.0) for k, m in enumerate((0.3, 0.1, 0.7))] == [1.0] * 3
    assert fixed.label == 1.0 and FrictionBelief("known").label == "known"


@pytest.mark.parametrize("bad", ["dry", "", 0.0, -0.2, 1.3, math.nan, True, [1.0]])
def test_bad_beliefs_are_input_errors(bad):
    with pytest.raises(InputError, match="mu_belief"):
        parse_mu_belief(bad)


def test_parse_accepts_numbers_as_text():
    assert parse_mu_belief("0.7") == 0.7 and parse_mu_belief(" Estimate ") == "estimate"


def test_estimate_holds_its_prior_while_cruising():
    """No excitation (cruising): nothing to learn from, the dry-road prior stays."""
    est = FrictionBelief("estimate", seed=1)
    values = {mu for _, mu in _drive(est, 0.3, 5.0, 0.2)}  # 0.2 m/s^2: utilisation 0.07
    assert values == {1.0}


def test_estimate_converges_to_the_delayed_true_friction_when_excited():
    st_ = EstimatorSettings(noise_sd=0.0)
    est = FrictionBelief("estimate", settings=st_)
    trace = _drive(est, 0.3, 3.0, 0.6 * 0.3 * G_MPS2)  # braking at 60 % of the friction
    # first-order convergence from 1.0 towards 0.3 at 0.1 s updates, time constant 0.5 s
    after_1s = trace[100][1]  # t = 1.00 s
    k_updates = 10  # updates at 0.0, 0.1, ..., 0.9 s seen by t = 1.0 s (inclusive)
    expected = 0.3 + 0.7 * math.exp(-0.1 / 0.5) ** (k_updates + 1)
    assert after_1s == pytest.approx(expected, abs=1e-9)
    assert trace[-1][1] == pytest.approx(0.3, abs=0.01)
    # the delay: a step in the true friction at 2 s is seen 0.3 s later
    est = FrictionBelief("estimate", settings=st_)
    trace = _drive(est, lambda t: 1.0 if t < 2.0 else 0.3, 2.5, 0.5 * G_MPS2 * 0.3)
    by_t = {round(t, 2): mu for t, mu in trace}
    assert by_t[2.2] == pytest.approx(1.0) and by_t[2.4] < 0.95


def test_estimate_bias_and_clip():
    est = FrictionBelief(
        "estimate", settings=EstimatorSettings(noise_sd=0.0, bias=-0.4), mu_min=0.1
    )
    cruising = _drive(est, 0.3, 0.5, 0.0)
    assert all(mu == pytest.approx(0.6) for _, mu in cruising)  # prior plus bias
    trace = _drive(est, 0.3, 5.0, 0.8 * 0.3 * G_MPS2, t0=0.5)
    assert trace[-1][1] == pytest.approx(0.1)  # -0.1 clipped to the tables' lowest


@given(st.integers(0, 2**31), st.floats(0.1, 1.2))
def test_same_seed_same_estimate(seed, mu):
    a = _drive(FrictionBelief("estimate", seed=seed), mu, 1.0, 0.9 * mu * G_MPS2)
    b = _drive(FrictionBelief("estimate", seed=seed), mu, 1.0, 0.9 * mu * G_MPS2)
    assert a == b
    assert all(0.1 <= v <= 1.2 for _, v in a)


def test_trace_and_at():
    est = FrictionBelief(0.5)
    assert est.at(0.0) is None
    est.mu(0.3, 1.0, 0.0, 0.0)
    assert est.at(0.5) is None and est.at(1.0) == 0.5 and est.at(9.0) == 0.5


@pytest.mark.parametrize("value", ["dry", "1.5", "0"])
def test_run_refuses_a_bad_belief_with_one_line(value, capsys, tmp_path):
    from pathlib import Path

    from eoam_sumo.cli import main

    cfg = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.sumocfg"
    assert main(["run", str(cfg), "--mu-belief", value, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "mu_belief" in err[0] and value in err[0]
