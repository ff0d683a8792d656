"""``batch`` over an .xosc: the cases of a variation file (every combination, those outside
the scenario's parameter constraints left out) and of a TOML sweep, and a small run."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.variations import is_xosc_batch, load_batch

DATA = Path(__file__).parents[1] / "data" / "openscenario"
CUT_IN = DATA / "alks" / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
CCRS_RANGE = DATA / "ncap/OpenSCENARIO/NCAP/CA-FC_2026/Variations/StandardRange/CCRs.xosc"
VARIATION = """<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="3" date="2026-11-28T00:00:00" description="t" author="t"/>
  <ParameterValueDistribution>
    <ScenarioFile filepath="{scenario}"/>
    <Deterministic>
      <DeterministicSingleParameterDistribution parameterName="Ego_InitSpeed_Ve0_kph">
        <DistributionRange stepWidth="20.0">
          <Range lowerLimit="20.0" upperLimit="60.0"/>
        </DistributionRange>
      </DeterministicSingleParameterDistribution>
      <DeterministicSingleParameterDistribution
          parameterName="CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph">
        <DistributionSet><Element value="-10"/><Element value="-50"/></DistributionSet>
      </DeterministicSingleParameterDistribution>
    </Deterministic>
  </ParameterValueDistribution>
</OpenSCENARIO>
"""


def test_a_variation_file_gives_every_combination_within_the_constraints(tmp_path: Path) -> None:
    """3 ego speeds x 2 relative speeds; the template constrains the relative speed to more
    than -ego speed (and the lateral speed below the cut-in car's speed): -50 km/h only
    with the 60 km/h ego, whose car then drives 10 km/h (2 m/s < 2.78 m/s)."""
    path = tmp_path / "v.xosc"
    path.write_text(VARIATION.format(scenario=CUT_IN), encoding="utf-8")
    assert is_xosc_batch(path)
    batch = load_batch(path)
    assert batch.scenario == CUT_IN.resolve()
    got = {
        (c["Ego_InitSpeed_Ve0_kph"], c["CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph"])
        for c in batch.cases
    }
    assert got == {("20.0", "-10"), ("40.0", "-10"), ("60.0", "-10"), ("60.0", "-50")}
    assert batch.left_out == 2


def test_a_toml_sweep_over_a_variation_file_replaces_its_axes(tmp_path: Path) -> None:
    matrix = tmp_path / "m.toml"
    matrix.write_text(
        f'[scenario]\nxosc = "{CCRS_RANGE}"\nsystem = "aeb"\n'
        "[sweep]\nEgo_speed_kph = [10, 20]\nImpactLocation = [50]\n",
        encoding="utf-8",
    )
    assert is_xosc_batch(matrix)
    batch = load_batch(matrix)
    assert [(c["Ego_speed_kph"], c["ImpactLocation"], c["Scenario_ID"]) for c in batch.cases] == [
        ("10.0", "50.0", "CCRs"),
        ("20.0", "50.0", "CCRs"),
    ]
    assert batch.system == "aeb"
    matrix.write_text(f'[scenario]\nxosc = "{CCRS_RANGE}"\nspeed = 3\n', encoding="utf-8")
    with pytest.raises(InputError, match="unknown key 'speed'"):
        load_batch(matrix)


@pytest.mark.sumo
def test_batch_runs_each_case_into_its_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two CCRs points braking only: the EOAM stops behind the car at 10 and 20 km/h (both
    cases in one worker: two libsumo sessions in one process)."""
    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    matrix = tmp_path / "m.toml"
    matrix.write_text(
        f'[scenario]\nxosc = "{CCRS_RANGE}"\nsystem = "aeb"\n'
        "[sweep]\nEgo_speed_kph = [10, 20]\nImpactLocation = [50]\n",
        encoding="utf-8",
    )
    out = tmp_path / "out"
    assert main(["batch", str(matrix), "--out", str(out), "--no-progress"]) == 0
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [(r["case_id"], r["param:Ego_speed_kph"], r["status"]) for r in rows] == [
        ("case00000", "10.0", "ok"),
        ("case00001", "20.0", "ok"),
    ]
    assert {r["collision_with"] for r in rows} == {"none"}
    assert all((out / "cases" / r["case_id"] / "summary.json").is_file() for r in rows)
    # plot took results.csv for a matrix's and refused it ("its columns are not those ...")
    assert main(["plot", str(out)]) == 0
    assert (out / "xosc_outcomes.png").stat().st_size > 10_000


def test_a_range_of_decimal_steps_gives_the_decimals(tmp_path: Path) -> None:
    """40.1 to 40.3 km/h by 0.1: 40.1 + 2 x 0.1 is 40.300000000000004 in binary floats."""
    text = VARIATION.format(scenario=CUT_IN).replace('stepWidth="20.0"', 'stepWidth="0.1"')
    text = text.replace(
        'lowerLimit="20.0" upperLimit="60.0"', 'lowerLimit="40.1" upperLimit="40.3"'
    )
    path = tmp_path / "v.xosc"
    path.write_text(text, encoding="utf-8")
    speeds = {c["Ego_InitSpeed_Ve0_kph"] for c in load_batch(path).cases}
    assert sorted(speeds) == ["40.1", "40.2", "40.3"]


def test_a_scenario_file_is_one_case_and_foreign_options_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    batch = load_batch(CUT_IN)
    assert (batch.scenario, batch.cases, batch.left_out) == (CUT_IN.resolve(), [{}], 0)
    for flag in (["--resume"], ["--scheduler", "local"], ["--after-stop-s", "1"]):
        assert main(["batch", str(CUT_IN), *flag, "--out", str(tmp_path / "o")]) == 2
        assert f"{flag[0]} does not apply to a batch over an .xosc" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("extra", "needle"),
    [("mu = 2.0\n", "mu = 2.0 must be in (0, 1.2]"), ("max_time_s = -1\n", "max_time_s = -1")],
)
def test_a_matrix_value_out_of_range_is_refused(tmp_path: Path, extra: str, needle: str) -> None:
    matrix = tmp_path / "m.toml"
    matrix.write_text(f'[scenario]\nxosc = "{CUT_IN}"\n{extra}', encoding="utf-8")
    with pytest.raises(InputError) as err:
        load_batch(matrix)
    assert needle in str(err.value)


def test_a_sweep_of_an_undeclared_parameter_names_the_matrix(tmp_path: Path) -> None:
    """It said ``--param Nope: ...``, an option the user never gave."""
    matrix = tmp_path / "m.toml"
    matrix.write_text(f'[scenario]\nxosc = "{CUT_IN}"\n[sweep]\nNope = [1]\n', encoding="utf-8")
    with pytest.raises(InputError, match=r"m.toml: \[sweep\] Nope: no such parameter declared"):
        load_batch(matrix)


@pytest.mark.parametrize(
    ("limits", "step", "expect"),
    [
        ('lowerLimit="60.0" upperLimit="60.0"', "20.0", "60.0"),
        ('lowerLimit="20.0" upperLimit="60.0"', "0", "is empty"),
        ('lowerLimit="20.0" upperLimit="60.0"', "20.0", "has many values"),
    ],
)
def test_run_reads_a_range_of_one_value_and_says_when_one_is_empty(tmp_path, limits, step, expect):
    """`run` on a variation file called every range "many values", one of a single value or
    none (a step of 0) too."""
    from eoam_sumo.openscenario.reader import read_scenario

    text = VARIATION.format(scenario=CUT_IN).replace('stepWidth="20.0"', f'stepWidth="{step}"')
    text = text.replace('lowerLimit="20.0" upperLimit="60.0"', limits)
    text = text.replace('<Element value="-50"/>', "")  # the set: one value
    path = tmp_path / "v.xosc"
    path.write_text(text, encoding="utf-8")
    if expect[0].isdigit():
        assert read_scenario(path).parameters["Ego_InitSpeed_Ve0_kph"] == expect
    else:
        with pytest.raises(InputError, match=expect):
            read_scenario(path)
