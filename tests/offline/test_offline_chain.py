"""The speed chain of the tables build: the secant predictor and the halving of failed steps
(checked on a stand-in solver, without IPOPT)."""

import dataclasses

import numpy as np
import pytest

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.ocp import (
    OcpError,
    OcpSolution,
    chain_speeds_mps,
    predicted_guess,
    solve_chain,
)
from eoam_sumo.params import ego_e_class_sedan

N = 10


def _linear(speed_mps: float) -> OcpSolution:
    """A family whose speed-scaled states, controls and duration are linear in the speed."""
    t = np.linspace(0.0, 1.0, N + 1)[:, None]
    states = np.hstack([t * speed_mps, np.full((N + 1, 1), speed_mps), t * (3.0 + 0.1 * speed_mps)])
    states = np.hstack([states, np.zeros((N + 1, 4)) + 0.01 * speed_mps])
    colloc = np.repeat(states[:-1], 3, axis=0)
    controls = np.column_stack([np.full(N, 0.2 - 0.001 * speed_mps), np.full(N, -50.0 * speed_mps)])
    return OcpSolution(speed_mps, 0.5, 5.0 - 0.02 * speed_mps, states, controls, 10, colloc, 1.0)


def test_the_secant_prediction_is_exact_for_a_family_linear_in_the_speed():
    guess = predicted_guess([_linear(40.0), _linear(35.0)], 30.0)
    exact = _linear(30.0)
    assert guess.speed_mps == 30.0
    assert guess.duration_s == pytest.approx(exact.duration_s)
    assert guess.states == pytest.approx(exact.states)
    assert guess.controls == pytest.approx(exact.controls)
    assert guess.colloc_states == pytest.approx(exact.colloc_states)


def test_one_solution_gives_the_rescaled_guess():
    guess = predicted_guess([_linear(40.0)], 30.0)
    assert guess.states[:, 0] == pytest.approx(_linear(40.0).states[:, 0] * 0.75)
    assert guess.duration_s == _linear(40.0).duration_s


class _ReachLimitedSolver:
    """Stands in for ``LaneChangeOcp``: converges only within ``reach_mps`` of its last
    solution (or from the quintic guess at the first speed)."""

    def __init__(self, reach_mps: float, halvings: int):
        self.params = ego_e_class_sedan()
        # steps as asked (no intermediate speeds), to test the halving alone
        self.settings = DesignSettings(speed_halvings=halvings, chain_step_kmh=100.0)
        self.patient = False
        self.reach_mps = reach_mps
        self.last: float | None = None
        self.calls: list[float] = []

    def solve(self, speed_mps, mu, guess, step=1.0):
        self.calls.append(speed_mps)
        if self.last is not None and abs(speed_mps - self.last) > self.reach_mps + 1e-9:
            raise OcpError(f"mu={mu:g}, {speed_mps * 3.6:g} km/h did not converge")
        self.last = speed_mps
        return dataclasses.replace(_linear(speed_mps), mu=mu)


def test_a_failed_step_is_split_into_half_steps():
    solver = _ReachLimitedSolver(reach_mps=1.0, halvings=2)
    solutions = solve_chain(solver, 0.5, [30.0, 26.0])
    assert [s.speed_mps for s in solutions] == [30.0, 26.0]  # the half steps are not returned
    # 26 fails; 28 fails, 29 and 28 (from 29) converge; 26 (from 28) fails; 27 and 26 converge
    assert solver.calls == [30.0, 26.0, 28.0, 29.0, 28.0, 26.0, 27.0, 26.0]


def test_a_step_too_far_for_its_halvings_reaches_the_last_resort():
    solver = _ReachLimitedSolver(reach_mps=1.0, halvings=1)
    solver.patient = True  # the stand-in is its own last resort (and fails there too)
    with pytest.raises(OcpError, match=r"mu=0\.5, 100\.8 km/h did not converge"):
        solve_chain(solver, 0.5, [30.0, 26.0])
    # 26 fails; 28 (100.8 km/h) fails, then its last resort: direct, continuation
    assert solver.calls == [30.0, 26.0, 28.0, 28.0, 28.0]


def test_the_chain_steps_at_most_its_step_whatever_speeds_are_asked():
    """The route does not depend on the grid asked: the grid's ends alone walk the full grid's
    speeds (within their last bits), each asked speed flagged, highest first."""
    full = chain_speeds_mps([v / 3.6 for v in range(20, 176, 5)], 2.5)
    ends = chain_speeds_mps([20 / 3.6, 175 / 3.6], 2.5)
    assert [a for _, a in ends] == [True] + [False] * 61 + [True]
    assert [v for v, _ in ends] == pytest.approx([v for v, _ in full], rel=1e-12)
    steps = np.diff([v * 3.6 for v, _ in full])
    assert (steps < 0).all() and (-steps <= 2.5 + 1e-9).all()
    assert sum(a for _, a in full) == 32
    assert chain_speeds_mps([10.0], 2.5) == [(10.0, True)] and chain_speeds_mps([], 2.5) == []
