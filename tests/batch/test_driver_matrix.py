"""The matrix key ``driver``: the ego's controller swept, given once or sampled; checked before
any case runs; the driver in the run, its reason and results.csv."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.batch.case import CaseParameters, CaseTask, case_settings
from eoam_sumo.batch.results import PARAM_COLUMNS
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.batch.vehicles_report import VEHICLES_MD
from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import load_matrix
from tests.builders import write_matrix

ONE_CASE = "ego_speed_kmh = [90]\nmu = [1.0]\n"


def test_a_swept_driver_follows_the_policy_in_the_case_id_and_reaches_the_run(tmp_path):
    matrix = write_matrix(
        tmp_path / "m.toml", 'policy = ["paper"]\ndriver = ["eoam", "r157-cc"]\n' + ONE_CASE
    )
    cases = load_matrix(matrix).cases()
    assert [c.case_id for c in cases] == [
        "paper_eoam_onc-none_v90_mu1.0",
        "paper_r157-cc_onc-none_v90_mu1.0",
    ]
    assert [case_settings(CaseTask(c, None)).driver for c in cases] == ["eoam", "r157-cc"]
    assert CaseParameters.of(cases[1]).driver == "r157-cc" and "driver" in PARAM_COLUMNS


def test_one_driver_for_every_case_keeps_the_ids_and_a_sampled_one_draws(tmp_path):
    given = write_matrix(tmp_path / "m.toml", ONE_CASE, scenario='driver = "rss"\n')
    (case,) = load_matrix(given).cases()
    assert (case.case_id, case.driver) == ("onc-none_v90_mu1.0", "rss")
    (plain,) = load_matrix(write_matrix(tmp_path / "p.toml", ONE_CASE)).cases()
    assert plain.driver == "eoam"  # the default: the paper's EOAM
    sampled = tmp_path / "s.toml"
    sampled.write_text(
        write_matrix(tmp_path / "x.toml", ONE_CASE).read_text()
        + '[sample]\ndraws = 40\nseed = 3\ndriver = { choice = ["fsm", "rss"] }\n'
    )
    drawn = {c.driver for c in load_matrix(sampled).cases()}
    assert drawn == {"fsm", "rss"}


@pytest.mark.parametrize(
    ("sweep", "scenario", "needle"),
    [
        ('driver = ["eoam", "human"]\n', "", "[sweep] driver value 'human' is not one of"),
        ('driver = ["rss", "rss"]\n', "", "[sweep] driver lists 'rss' twice"),
        ('driver = ["rss"]\n', 'driver = "fsm"\n', "'driver' is in [scenario] and [sweep]"),
        ("", 'driver = "careful"\n', "[scenario] driver = 'careful' must be one of"),
        ('driver = "rss"\n', "", "[sweep] driver must be a non-empty list"),
    ],
)
def test_a_bad_driver_is_one_line_with_exit_status_2(tmp_path, capsys, sweep, scenario, needle):
    matrix = write_matrix(tmp_path / "m.toml", sweep + ONE_CASE, scenario=scenario)
    with pytest.raises(InputError) as err:
        load_matrix(matrix)
    assert str(matrix) in str(err.value) and needle in str(err.value)
    out = tmp_path / "out"
    status = main(["batch", str(matrix), "--out", str(out), "--no-progress"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(lines) == 1 and needle in lines[0]
    assert not (out / "results.csv").exists()


@pytest.mark.sumo
def test_a_batch_compares_the_eoam_with_the_careful_driver_by_name(tmp_path):
    """A stalled car at 120 km/h on a wet road (mu 0.3, a stop needs about 190 m): the EOAM
    changes lanes; the R157 careful driver, which never steers, brakes in its lane and hits
    it. results.csv names each, the driver's reason names the driver, and the vehicles report
    counts them apart."""
    sweep = 'driver = ["eoam", "r157-cc"]\nego_speed_kmh = [120]\nmu = [0.3]\n'
    matrix = write_matrix(tmp_path / "m.toml", sweep)
    results = run_batch(matrix, tmp_path / "out", progress=False)
    rows = {r["driver"]: r for r in results.to_dict("records")}
    assert set(rows) == {"eoam", "r157-cc"}
    eoam, careful = rows["eoam"], rows["r157-cc"]
    assert eoam["status"] == careful["status"] == "ok"
    assert "2" in eoam["modes_visited"].split("-") and eoam["collision_with"] == "none"
    assert careful["modes_visited"] == "0-1" and careful["collision_with"] == "aro"
    assert careful["reason"].startswith("braking by the r157-cc reference driver")
    assert "DMM" not in careful["reason"]
    saved = pd.read_csv(tmp_path / "out" / "results.csv")
    assert sorted(saved["driver"]) == ["eoam", "r157-cc"]
    report = (tmp_path / "out" / VEHICLES_MD).read_text()
    assert "| r157-cc |" in report and "| paper |" in report
