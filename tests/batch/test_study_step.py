"""SUMO's step of a study: ``--sumo-step-s`` over the matrix's ``[scenario] sumo_step_s`` over
the study's default, and results.csv naming the step every case ran at."""

from __future__ import annotations

from eoam_sumo.batch.case import CaseParameters
from eoam_sumo.batch.runner import plan_batch
from eoam_sumo.cli import build_parser
from eoam_sumo.sim.settings import REFERENCE_SUMO_STEP_S, STUDY_SUMO_STEP_S
from tests.builders import write_matrix

SWEEP = "ego_speed_kmh = [90, 120]\nmu = [1.0]\n"


def _steps(matrix, **kwargs) -> set:
    return {c.sumo_step_s for c in plan_batch(matrix, **kwargs).cases}


def test_the_option_beats_the_matrix_key_which_beats_the_study_default(tmp_path):
    plain = write_matrix(tmp_path / "plain.toml", SWEEP)
    keyed = write_matrix(tmp_path / "keyed.toml", SWEEP, scenario="sumo_step_s = 0.1\n")
    assert _steps(plain) == {None}  # the library's default: the run's, the 10 ms reference
    assert _steps(plain, default_sumo_step_s=STUDY_SUMO_STEP_S) == {STUDY_SUMO_STEP_S}
    assert _steps(keyed, default_sumo_step_s=STUDY_SUMO_STEP_S) == {0.1}
    assert _steps(keyed, sumo_step_s=0.02, default_sumo_step_s=STUDY_SUMO_STEP_S) == {0.02}
    assert _steps(plain, sumo_step_s=0.01, default_sumo_step_s=STUDY_SUMO_STEP_S) == {0.01}


def test_results_name_the_step_a_case_ran_at_never_an_empty_one(tmp_path):
    plain = write_matrix(tmp_path / "plain.toml", SWEEP)
    case = plan_batch(plain).cases[0]
    assert case.sumo_step_s is None and REFERENCE_SUMO_STEP_S == 0.01
    assert CaseParameters.of(case).sumo_step_s == REFERENCE_SUMO_STEP_S
    at_study = plan_batch(plain, default_sumo_step_s=STUDY_SUMO_STEP_S).cases[0]
    assert CaseParameters.of(at_study).sumo_step_s == 0.05


def test_the_help_names_each_commands_default():
    parser = build_parser()
    sub = parser._subparsers._group_actions[0].choices  # argparse keeps its subparsers so
    for command, default in (("run", "0.01"), ("batch", "0.05"), ("protocol", "0.05")):
        (action,) = [a for a in sub[command]._actions if "--sumo-step-s" in a.option_strings]
        assert f"default {default}" in action.help, command
