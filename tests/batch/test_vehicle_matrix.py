"""The matrix key ``vehicle``: swept, given once or sampled; checked before any case runs
(its file, its tables); the case's vehicle in the run and in results.csv."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from eoam_sumo.batch.case import CaseParameters, case_vehicle
from eoam_sumo.batch.results import COLUMNS, PARAM_COLUMNS
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import check_matrix, load_matrix
from eoam_sumo.offline.build import build_tables
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.vehicle_files import load_vehicle, vehicle_toml
from tests.builders import write_matrix

ROOT = Path(__file__).resolve().parents[2]
SEDAN_R13H = ROOT / "vehicles" / "sedan-r13h.toml"
TALL = replace(ego_e_class_sedan(), name="tall test car", cg_height_m=1.6)
ONE_CASE = "ego_speed_kmh = [165]\nmu = [1.0]\n"


def _tall(folder: Path, name: str = "tall.toml") -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(vehicle_toml(TALL))
    return path


def test_a_swept_vehicle_leads_the_case_id_and_reaches_the_run(tmp_path):
    _tall(tmp_path / "fleet")
    matrix = write_matrix(
        tmp_path / "m.toml", 'vehicle = ["sedan", "fleet/tall.toml"]\n' + ONE_CASE
    )
    cases = load_matrix(matrix).cases()
    assert [c.case_id for c in cases] == ["sedan_onc-none_v165_mu1.0", "tall_onc-none_v165_mu1.0"]
    assert cases[0].vehicle == "sedan"
    assert cases[1].vehicle == str((tmp_path / "fleet" / "tall.toml").resolve())
    assert case_vehicle(cases[1]) == TALL
    assert case_vehicle(cases[0]) == load_vehicle("sedan")
    assert CaseParameters.of(cases[1]).vehicle == cases[1].vehicle


def test_no_vehicle_named_is_the_papers_sedan_and_the_ids_stay(tmp_path):
    matrix = write_matrix(tmp_path / "m.toml", ONE_CASE)
    (case,) = load_matrix(matrix).cases()
    assert case.case_id == "onc-none_v165_mu1.0" and case.vehicle is None
    assert case_vehicle(case) == ego_e_class_sedan()
    assert CaseParameters.of(case).vehicle == "sedan"
    assert "vehicle" in PARAM_COLUMNS and COLUMNS.count("vehicle") == 1


def test_one_vehicle_for_every_case_and_a_sampled_one(tmp_path):
    _tall(tmp_path)
    given = write_matrix(tmp_path / "m.toml", ONE_CASE, scenario='vehicle = "tall.toml"\n')
    (case,) = load_matrix(given).cases()
    assert case.case_id == "tall_onc-none_v165_mu1.0"
    sampled = tmp_path / "s.toml"
    sampled.write_text(
        write_matrix(tmp_path / "x.toml", ONE_CASE).read_text()
        + '[sample]\ndraws = 40\nseed = 3\nvehicle = { choice = ["sedan", "tall.toml"] }\n'
    )
    cases = load_matrix(sampled).cases()
    assert {c.vehicle for c in cases} == {"sedan", str((tmp_path / "tall.toml").resolve())}
    assert all(c.case_id.startswith("onc-none_v165_mu1.0_d") for c in cases)


@pytest.mark.parametrize(
    ("sweep", "needle"),
    [
        ('vehicle = ["lorry"]\n', "'lorry': not in the catalogue"),
        ('vehicle = ["bad.toml"]\n', "key 'mass_kg' is missing"),
        ('vehicle = ["tall.toml", "other/tall.toml"]\n', "two vehicles named 'tall'"),
        ("vehicle = [3]\n", "not a catalogue name"),
        ('vehicle = "tall.toml"\n', "must be a non-empty list"),
    ],
)
def test_bad_vehicles_are_refused_naming_the_matrix_and_the_key(tmp_path, sweep, needle):
    _tall(tmp_path)
    _tall(tmp_path / "other")
    blocks = vehicle_toml(TALL).split("\n\n")
    (tmp_path / "bad.toml").write_text("\n\n".join(b for b in blocks if "[mass_kg]" not in b))
    matrix = write_matrix(tmp_path / "m.toml", sweep + ONE_CASE)
    with pytest.raises(InputError) as err:
        load_matrix(matrix)
    assert str(matrix) in str(err.value) and "vehicle" in str(err.value)
    assert needle in str(err.value)


def test_a_batch_with_a_vehicle_without_tables_is_refused_before_any_case(capsys, tmp_path):
    _tall(tmp_path)  # the shipped catalogue has its tables; a user's file has none
    matrix = write_matrix(tmp_path / "m.toml", 'vehicle = ["tall.toml"]\n' + ONE_CASE)
    with pytest.raises(InputError, match="no lookup tables for vehicle"):
        check_matrix(load_matrix(matrix), tmp_path / "tables")
    out = tmp_path / "out"
    status = main(["batch", str(matrix), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1, err
    assert "tall" in err and not (out / "results.csv").exists()


@pytest.mark.sumo
def test_a_batch_runs_each_case_with_its_vehicle(tmp_path):
    tall = _tall(tmp_path)
    tables = tmp_path / "tables"
    build_tables(tables / "tall", speeds_kmh=[160, 165], mus=[1.0], progress=False, params=TALL)
    matrix = write_matrix(tmp_path / "m.toml", 'vehicle = ["tall.toml"]\n' + ONE_CASE)
    results = run_batch(matrix, tmp_path / "out", progress=False, tables_dir=tables)
    (row,) = results.to_dict("records")
    assert row["status"] == "ok" and row["vehicle"] == str(tall.resolve())
    assert row["outcome"] == "orange" and "rollover: " in row["reason"]


def test_swept_equipment_and_policy_follow_the_vehicle_in_the_case_id(tmp_path):
    matrix = write_matrix(
        tmp_path / "m.toml",
        'vehicle = ["suv"]\nabs_esc = ["off", "on"]\npolicy = ["paper", "safe"]\n' + ONE_CASE,
    )
    cases = load_matrix(matrix).cases()
    assert [c.case_id for c in cases] == [
        "suv_abs-off_esc-off_paper_onc-none_v165_mu1.0",
        "suv_abs-off_esc-off_safe_onc-none_v165_mu1.0",
        "suv_abs-on_esc-on_paper_onc-none_v165_mu1.0",
        "suv_abs-on_esc-on_safe_onc-none_v165_mu1.0",
    ]
    assert [(c.abs_fitted, c.esc_fitted, c.policy) for c in cases] == [
        (False, False, "paper"),
        (False, False, "safe"),
        (True, True, "paper"),
        (True, True, "safe"),
    ]
    assert case_vehicle(cases[0]).abs_fitted is False and case_vehicle(cases[2]).esc_fitted


def test_equipment_given_once_keeps_the_ids_and_none_is_the_vehicles_own(tmp_path):
    given = write_matrix(tmp_path / "m.toml", ONE_CASE, scenario='abs = "on"\nesc = "off"\n')
    (case,) = load_matrix(given).cases()
    assert case.case_id == "onc-none_v165_mu1.0"
    assert (case.abs_fitted, case.esc_fitted) == (True, False)
    (plain,) = load_matrix(write_matrix(tmp_path / "p.toml", ONE_CASE)).cases()
    assert plain.abs_fitted is None and plain.esc_fitted is None
    swept = write_matrix(tmp_path / "s.toml", 'esc = ["on"]\nabs = ["off"]\n' + ONE_CASE)
    (one,) = load_matrix(swept).cases()
    assert one.case_id == "abs-off_esc-on_onc-none_v165_mu1.0"


@pytest.mark.parametrize(
    ("sweep", "scenario", "needle"),
    [
        ('abs = ["of"]\n', "", '[sweep] abs value \'of\' is not "on" or "off"'),
        ('abs = ["on", "on"]\n', "", "lists 'on' twice"),
        ('abs = ["on"]\n', 'abs = "off"\n', "'abs' is in [scenario] and [sweep]"),
        ('abs_esc = ["on"]\n', 'esc = "off"\n', "'abs_esc' switches both"),
        ('policy = ["paper", "fast"]\n', "", "[sweep] policy value 'fast'"),
        ('policy = ["safe"]\n', 'policy = "safe"\n', "'policy' is in [scenario] and [sweep]"),
        ('policy = ["paper", "safe"]\n', "v2x_range_m = 300\n", "V2X informs the safe policy"),
        ("abs = true\n", "", "must be a non-empty list"),
    ],
)
def test_bad_equipment_or_policy_is_one_line(tmp_path, sweep, scenario, needle):
    matrix = write_matrix(tmp_path / "m.toml", sweep + ONE_CASE, scenario=scenario)
    with pytest.raises(InputError) as err:
        load_matrix(matrix)
    assert str(matrix) in str(err.value) and needle in str(err.value)
    assert len(str(err.value).splitlines()) == 1


def test_equipment_is_not_sampled(tmp_path):
    sampled = tmp_path / "s.toml"
    sampled.write_text(
        write_matrix(tmp_path / "x.toml", ONE_CASE).read_text()
        + '[sample]\ndraws = 4\nseed = 3\nabs = { choice = ["on", "off"] }\n'
    )
    with pytest.raises(InputError, match="'abs' cannot be sampled") as err:
        load_matrix(sampled)
    assert len(str(err.value).splitlines()) == 1


def test_the_tables_check_uses_the_switched_abs_folder(tmp_path):
    """A vehicle whose ABS is switched from its file's needs tables/<name>-abs|-noabs."""
    _tall(tmp_path)
    sweep = 'vehicle = ["tall.toml"]\nabs = ["on"]\n'
    matrix = write_matrix(tmp_path / "m.toml", sweep + ONE_CASE)
    with pytest.raises(InputError, match="tall-abs") as err:
        check_matrix(load_matrix(matrix), tmp_path / "tables")
    assert "--abs on" in str(err.value)
