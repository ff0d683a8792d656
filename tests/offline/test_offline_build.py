"""build_tables: a subset rebuild reproduces the committed tables; builds are deterministic."""

import csv

import numpy as np
import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.offline.build import build_tables
from eoam_sumo.offline.tables import LookupTables, PhaseBoundaries, default_tables_dir

COMMITTED = default_tables_dir()
SPEEDS_KMH = [60.0, 140.0]
MUS = [1.0, 0.3]
FILES = ("phase_boundaries.csv", "lookup_tables.npz", "metadata.json")


def _csv_rows(folder):
    with open(folder / "phase_boundaries.csv") as f:
        lines = [ln for ln in f if not ln.startswith("#")]
    return {(r["mu"], r["speed_kmh"]): r for r in csv.DictReader(lines)}


@pytest.fixture(scope="module")
def subset(tmp_path_factory):
    out = tmp_path_factory.mktemp("subset")
    build_tables(out, jobs=2, speeds_kmh=SPEEDS_KMH, mus=MUS, progress=False)
    return out


def test_subset_rebuild_reproduces_the_committed_boundaries(subset):
    ours, committed = _csv_rows(subset), _csv_rows(COMMITTED)
    assert len(ours) == len(SPEEDS_KMH) * len(MUS)
    for key, row in ours.items():
        for column, value in row.items():
            assert float(value) == pytest.approx(float(committed[key][column]), abs=1e-3), (
                key,
                column,
            )


def test_subset_rebuild_reproduces_the_committed_lookup_rows(subset):
    with (
        np.load(subset / "lookup_tables.npz") as ours,
        np.load(COMMITTED / "lookup_tables.npz") as committed,
    ):
        assert float(ours["dx_step_m"]) == float(committed["dx_step_m"])
        for i, mu in enumerate(ours["mu_grid"]):
            ci = list(committed["mu_grid"]).index(mu)
            for j, v in enumerate(ours["speed_grid_mps"]):
                cj = int(np.argmin(np.abs(committed["speed_grid_mps"] - v)))
                assert committed["speed_grid_mps"][cj] == pytest.approx(v)
                assert ours["length_m"][i, j] == pytest.approx(
                    committed["length_m"][ci, cj], abs=1e-4
                )
                n = ours["y_m"].shape[2]
                for name, tol in (
                    ("y_m", 1e-4),
                    ("yaw_rad", 1e-4),
                    ("curvature_1pm", 1e-4),
                    ("steer_rad", 1e-4),
                    ("ax_mps2", 1e-3),
                ):
                    diff = np.abs(ours[name][i, j] - committed[name][ci, cj, :n])
                    assert diff.max() <= tol, (mu, v, name)


def test_builds_are_byte_identical_whatever_the_number_of_jobs(subset, tmp_path):
    build_tables(tmp_path, jobs=1, speeds_kmh=SPEEDS_KMH, mus=MUS, progress=False)
    for name in FILES:
        assert (tmp_path / name).read_bytes() == (subset / name).read_bytes(), name


def test_built_folder_loads_and_names_its_grid(subset):
    tables = LookupTables.load(subset)
    assert tables.mu_grid == (0.3, 1.0)
    assert tables.speed_grid_mps == pytest.approx([60 / 3.6, 140 / 3.6])
    assert PhaseBoundaries.load(subset).at(0.3, 60 / 3.6).ttc_s == 5.0
    first = (subset / "phase_boundaries.csv").read_text().splitlines()[0]
    assert first.startswith("# eoam-sumo")


def test_bad_build_arguments_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="jobs"):
        build_tables(tmp_path, jobs=0)
    with pytest.raises(InputError, match="speeds_kmh"):
        build_tables(tmp_path, speeds_kmh=[-10.0])
    with pytest.raises(InputError, match="mus"):
        build_tables(tmp_path, mus=[1.0, 1.0])
    assert not list(tmp_path.iterdir())


def test_the_ice_chain_rebuilds_every_committed_cell_on_its_own_route(tmp_path):
    """mu 0.1 is the hardest chain: at 20 km/h its OCP has several local optima (24.02, 24.33
    and 24.95 m long were found), and which one a solve reaches depends on the route. The
    chain's steps are at most ``chain_step_kmh`` apart whatever speeds are asked, so the two
    ends of the grid alone take the full build's route and must give its cells: within 1e-3
    (the CSV's four decimals, plus IPOPT's tolerance), on any machine."""
    build_tables(tmp_path, jobs=1, speeds_kmh=[20.0, 175.0], mus=[0.1], progress=False)
    ours, committed = _csv_rows(tmp_path), _csv_rows(COMMITTED)
    assert set(ours) == {("0.10", "20.0"), ("0.10", "175.0")}
    for key, row in ours.items():
        for column, value in row.items():
            assert float(value) == pytest.approx(float(committed[key][column]), abs=1e-3), (
                key,
                column,
            )
