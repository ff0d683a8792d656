"""A real batch without ``mu`` on a network whose two lanes have their own frictions (the
ego's 0.4, the opposite lane 0.7): every case runs on them, as ``run`` without ``--mu``;
its report, plots and ``--resume`` work on results whose ``mu`` is empty. The same matrix
with ``mu`` still sets every lane's friction."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.batch.results import RESULTS_FILE
from eoam_sumo.batch.runner import run_batch
from eoam_sumo.plotting import batch_plots
from eoam_sumo.plotting.dispatch import plot_folder
from tests.builders import write_matrix
from tests.test_matrix_network_friction import baseline_on_frictions

pytestmark = pytest.mark.sumo
EGO_LANE_MU, LEFT_LANE_MU = 0.4, 0.7
SCENARIO = "max_time_s = 12.0\nsumo_step_s = 0.05\n"


def must_not_run(task):
    """Test-only case function: a resumed batch whose cases are all kept runs none."""
    raise AssertionError(f"{task.case.case_id} ran again")


@pytest.fixture(scope="module")
def own_friction(tmp_path_factory):
    """(scenario, batch folder, results) of the matrix without mu: 120 and 90 km/h."""
    root = tmp_path_factory.mktemp("own-friction")
    cfg = baseline_on_frictions(root / "scenario", EGO_LANE_MU, LEFT_LANE_MU)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("EOAM_TABLES_DIR", raising=False)
        matrix = write_matrix(root / "m.toml", "ego_speed_kmh = [120, 90]\n", cfg, SCENARIO)
        results = run_batch(matrix, root / "out", jobs=1, progress=False)
        yield cfg, matrix, root / "out", results


def _series(out, case_id: str) -> pd.DataFrame:
    return pd.read_csv(out / "cases" / case_id / "timeseries.csv")


def test_cases_without_mu_run_on_each_lanes_own_friction(own_friction):
    _, _, out, results = own_friction
    assert results["case_id"].tolist() == ["onc-none_v120", "onc-none_v90"]
    assert (results["status"] == "ok").all(), results["error"].tolist()
    assert results["mu"].isna().all()  # none asked for
    assert results["mu_at_start"].tolist() == [EGO_LANE_MU, EGO_LANE_MU]  # not 1.0
    for case_id in results["case_id"]:
        mu = _series(out, case_id)["mu"]
        assert mu.iloc[0] == EGO_LANE_MU
        assert set(mu) <= {EGO_LANE_MU, LEFT_LANE_MU}
    text = (out / "results.csv").read_text().splitlines()
    assert text[1].startswith("onc-none_v120,120.0,,")  # the mu column empty


def test_its_report_plots_and_resume_work_without_mu(own_friction, tmp_path):
    _, matrix, out, results = own_friction
    table = (out / "table2.md").read_text()
    assert "network's surface mu" in table and "under the ego at its start: 0.4." in table
    assert "nan" not in table
    pngs = {p.name for p in plot_folder(out, tmp_path / "plots")}
    assert {"table2.png", "margins.png", "lateral_offsets_120kmh.png"} <= pngs
    before = (out / RESULTS_FILE).read_text()
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("EOAM_TABLES_DIR", raising=False)
        again = run_batch(matrix, out, jobs=1, resume=True, progress=False, case_func=must_not_run)
    assert again["mu_at_start"].tolist() == results["mu_at_start"].tolist()
    assert (out / RESULTS_FILE).read_text() == before


def test_a_swept_mu_sets_every_lanes_friction_where_none_keeps_the_networks(
    own_friction, tmp_path, monkeypatch
):
    cfg, _, _, own = own_friction
    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)
    matrix = write_matrix(tmp_path / "m.toml", "ego_speed_kmh = [90]\nmu = [1.0]\n", cfg, SCENARIO)
    results = run_batch(matrix, tmp_path / "out", jobs=1, progress=False)
    assert results["case_id"].tolist() == ["onc-none_v90_mu1.0"]
    assert results["mu"].tolist() == [1.0] and results["mu_at_start"].tolist() == [1.0]
    assert set(_series(tmp_path / "out", "onc-none_v90_mu1.0")["mu"]) == {1.0}
    assert own.loc[own["ego_speed_kmh"] == 90, "mu_at_start"].tolist() == [EGO_LANE_MU]


def test_the_lateral_offset_titles_name_only_what_varied(own_friction, tmp_path, monkeypatch):
    """Only the speed swept: the left panel's title is not "across frictions" (one ran)."""
    _, _, out, results = own_friction
    figures = []
    monkeypatch.setattr(batch_plots, "save", lambda fig, path: figures.append(fig) or path)
    batch_plots.plot_lateral_offsets(out, results, tmp_path, 120.0)
    titles = [ax.get_title() for ax in figures[0].axes]
    assert titles[0] == "120 km/h, no oncoming traffic"
    assert not any("across frictions" in t for t in titles)
