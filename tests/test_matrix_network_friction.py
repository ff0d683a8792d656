"""A matrix without ``mu``: every case on each lane's own friction, as ``run`` without
``--mu``. Loading, the check of the network's frictions against the lookup tables, the
refusal of a paper table, and the reports of results whose ``mu`` is empty (no SUMO)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from eoam_sumo.batch.probability_map import decided, probability_map
from eoam_sumo.batch.report import outcome_grid, table2_markdown
from eoam_sumo.batch.vehicles_report import cell_id
from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.matrix import check_matrix, load_matrix
from tests.builders import HIGHWAY_NET, SCENARIOS, write_matrix

NO_MU = "ego_speed_kmh = [120, 90]\noncoming_start_m = ['none', 400]\n"


def baseline_on_frictions(folder: Path, ego_lane_mu: float, left_lane_mu: float) -> Path:
    """The baseline scenario on a copy of the highway whose eastbound lane ``E0_0`` (the
    ego's) and opposite lane ``-E0_0`` have these frictions: ``frictions.sumocfg``."""
    net = HIGHWAY_NET.read_text()
    for lane, mu in (("E0_0", ego_lane_mu), ("-E0_0", left_lane_mu)):
        old = f'<lane id="{lane}" friction="1.00"'
        assert old in net
        net = net.replace(old, f'<lane id="{lane}" friction="{mu:.2f}"')
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "frictions.net.xml").write_text(net)
    cfg = (SCENARIOS / "baseline.sumocfg").read_text()
    for old, new in (
        ("../networks/highway.net.xml", str(folder / "frictions.net.xml")),
        ("parked.rou.xml,baseline.rou.xml", f"{SCENARIOS / 'parked.rou.xml'},"
         f"{SCENARIOS / 'baseline.rou.xml'}"),
        ("vtypes.add.xml,../networks/highway_parking.add.xml", f"{SCENARIOS / 'vtypes.add.xml'},"
         f"{HIGHWAY_NET.parent / 'highway_parking.add.xml'}"),
    ):  # fmt: skip
        assert old in cfg
        cfg = cfg.replace(old, new)
    (folder / "frictions.sumocfg").write_text(cfg)
    return folder / "frictions.sumocfg"


def test_a_matrix_without_mu_runs_every_case_on_the_lanes_own_friction(tmp_path):
    matrix = load_matrix(write_matrix(tmp_path / "m.toml", NO_MU))
    cases = matrix.cases()
    assert matrix.mus == ()
    assert [c.case_id for c in cases] == [
        "onc-none_v120",
        "onc-none_v90",
        "onc-400_v120",
        "onc-400_v90",
    ]
    assert {c.mu for c in cases} == {None}
    assert {c.overrides().mu for c in cases} == {None}  # no friction set over the network's
    with_mu = load_matrix(write_matrix(tmp_path / "w.toml", NO_MU + "mu = [0.7]\n"))
    assert {c.overrides().mu for c in with_mu.cases()} == {0.7}


def test_the_lane_the_ego_departs_on_is_checked_against_the_tables(tmp_path, monkeypatch):
    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)  # the repository's (mu 0.1 up)
    icy = baseline_on_frictions(tmp_path / "icy", ego_lane_mu=0.05, left_lane_mu=0.7)
    matrix = load_matrix(write_matrix(tmp_path / "m.toml", NO_MU, icy))
    with pytest.raises(InputError) as err:
        check_matrix(matrix)
    line = str(err.value)
    assert "\n" not in line
    assert line.startswith(f"{matrix.path}: no mu in [sweep]")
    assert "lane 'E0_0'" in line and str(tmp_path / "icy" / "frictions.net.xml") in line
    assert "friction 0.05, outside the lookup tables" in line
    # a swept mu sets every lane's: the net's 0.05 is never driven on
    check_matrix(load_matrix(write_matrix(tmp_path / "w.toml", NO_MU + "mu = [0.7]\n", icy)))
    # as `run`, only the friction under the ego at its start: an icy opposite lane runs
    left = baseline_on_frictions(tmp_path / "left", ego_lane_mu=0.4, left_lane_mu=0.05)
    check_matrix(load_matrix(write_matrix(tmp_path / "l.toml", NO_MU, left)))


def test_a_paper_table_without_mu_is_refused_and_nothing_written(capsys, tmp_path):
    matrix = write_matrix(tmp_path / "m.toml", NO_MU, paper_table=True)
    out = tmp_path / "out"
    status = main(["batch", str(matrix), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert str(matrix) in err and "[paper] table needs [sweep] mu" in err
    assert not out.exists()


def _results(mu: float | None, mu_at_start: float, speeds=(120.0, 90.0)) -> pd.DataFrame:
    """A results frame of finished cases without an oncoming car, one per speed."""
    n = len(speeds)
    return pd.DataFrame(
        {
            "case_id": [f"onc-none_v{v:g}" for v in speeds],
            "ego_speed_kmh": list(speeds),
            "mu": [np.nan if mu is None else mu] * n,
            "mu_at_start": [mu_at_start] * n,
            "oncoming_start_m": [np.nan] * n,
            "status": ["ok"] * n,
            "outcome": ["green", "yellow"][:n],
            "paper_outcome": [""] * n,
            "case_dir": [f"cases/onc-none_v{v:g}" for v in speeds],
            "reason": ["r"] * n,
            "modes_visited": ["0"] * n,
            "collision_with": ["none"] * n,
            "near_miss": [False] * n,
            "draw": [np.nan] * n,
        }
    )


def test_table2_of_cases_on_the_networks_friction_has_one_column_saying_so():
    grid = outcome_grid(_results(None, 0.4))
    assert grid.mus == (None,)
    assert sorted(grid.cells) == [(0, 0), (1, 0)]
    text = table2_markdown(grid)
    assert "| network's surface mu |" in text
    assert "under the ego at its start: 0.4." in text
    assert "nan" not in text
    assert "**No oncoming, 90 km/h, network's mu**" in text  # the yellow cell listed
    assert "network's" not in table2_markdown(outcome_grid(_results(0.4, 0.4)))


def test_reports_of_cases_on_the_networks_friction_read_the_friction_at_the_start():
    results = _results(None, 0.4)
    assert [cell_id(row) for _, row in results.iterrows()] == ["onc-none_v120", "onc-none_v90"]
    assert decided(results)["mu"].tolist() == [0.4, 0.4]  # the map's friction axis
    draws = pd.concat([_results(None, 0.4, speeds=(80.0 + k, 120.0)) for k in range(6)])
    draws["draw"] = range(len(draws))
    fitted = probability_map(draws)
    assert set(fitted["mu"]) == {0.4} and fitted["p"].notna().all()
