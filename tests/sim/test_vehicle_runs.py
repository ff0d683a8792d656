"""Runs with another vehicle: ``run --vehicle``, its tables folder (``tables/<name>``) and the
refusals, SUMO told its footprint and mass, and a high centre of gravity rolling over."""

from __future__ import annotations

import csv
import json
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from eoam_sumo.cli import main
from eoam_sumo.offline.build import build_tables
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.observers import StepObserver
from eoam_sumo.sim.runlog import write_run
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.vehicle import vehicle_tables, vehicle_tables_dir
from eoam_sumo.vehicle_files import default_vehicles_dir, load_vehicle, vehicle_toml

ROOT = Path(__file__).resolve().parents[2]
BASELINE = ROOT / "scenarios" / "baseline.sumocfg"
#: the sedan with its centre of gravity at 1.6 m, 5.30 m long and 2.00 m wide
TALL = replace(
    ego_e_class_sedan(), name="tall test car", cg_height_m=1.6, length_m=5.30, width_m=2.00
)
AT_165 = ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0)


def _one_error_line(capsys, argv) -> str:
    status = main(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.startswith("eoam-sumo")]
    assert status == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def _run_args(tmp_path: Path, vehicle: Path, tables: Path | None = None) -> list[str]:
    args = ["run", str(BASELINE), "--vehicle", str(vehicle), "--out", str(tmp_path / "out")]
    return args + (["--tables", str(tables)] if tables is not None else [])


def _blocks(params) -> dict[str, str]:
    """The vehicle file of ``params`` as its tables, by key."""
    blocks = vehicle_toml(params).strip().split("\n\n")
    return {b.split("]")[0].lstrip("["): b for b in blocks}


@pytest.mark.parametrize(
    ("key", "block"),
    [
        ("mass_kg", None),
        ("cg_height_m", '[cg_height_m]\nvalue = -1.6\nunit = "m"\nsource = "a typo"'),
    ],
    ids=["missing", "negative"],
)
def test_a_vehicle_file_with_a_missing_or_negative_value_exits_2(capsys, tmp_path, key, block):
    blocks = _blocks(TALL)
    if block is None:
        del blocks[key]
    else:
        blocks[key] = block
    path = tmp_path / "bad.toml"
    path.write_text("\n\n".join(blocks.values()) + "\n")
    line = _one_error_line(capsys, _run_args(tmp_path, path))
    assert repr(key) in line and str(path) in line
    assert not (tmp_path / "out" / "summary.json").exists()


def test_a_vehicle_without_tables_is_refused_in_one_line(capsys, tmp_path):
    path = tmp_path / "bare.toml"
    path.write_text(vehicle_toml(TALL))
    line = _one_error_line(capsys, _run_args(tmp_path, path, tmp_path / "tables"))
    assert "no lookup tables for vehicle" in line
    assert str(tmp_path / "tables" / "bare") in line


@pytest.fixture(scope="module")
def tall_tables(tmp_path_factory) -> tuple[Path, Path]:
    """(the tall car's vehicle file, a tables base folder holding its tables at 160 and 165
    km/h on mu 1.0 in ``tall/``)."""
    folder = tmp_path_factory.mktemp("tall")
    vehicle = folder / "tall.toml"
    vehicle.write_text(vehicle_toml(TALL))
    base = folder / "tables"
    build_tables(
        vehicle_tables_dir(str(vehicle), base), speeds_kmh=[160, 165], mus=[1.0], params=TALL
    )
    return vehicle, base


def test_the_folder_of_a_vehicle_is_its_name_under_the_tables_and_the_sedans_the_tables():
    base = Path("/t")
    assert vehicle_tables_dir("sedan", base) == base
    assert vehicle_tables_dir("suv", base) == base / "suv"
    assert vehicle_tables_dir("my/fleet/truck.toml", base) == base / "truck"
    # a user's file named as a catalogue vehicle never shares the catalogue vehicle's tables
    assert vehicle_tables_dir("my/fleet/van.toml", base) == base / "van-file"
    assert vehicle_tables_dir("my/fleet/sedan.toml", base) == base / "sedan-file"
    assert vehicle_tables_dir(str(default_vehicles_dir() / "van.toml"), base) == base / "van"


def test_a_vehicle_with_its_abs_switched_has_a_folder_of_its_own():
    """The ABS braking limit is the plant's, so ABS switched is another set of tables."""
    base = Path("/t")
    sedan, compact = load_vehicle("sedan"), load_vehicle("compact")
    assert vehicle_tables_dir("sedan", base, sedan) == base
    assert vehicle_tables_dir("sedan", base, replace(sedan, abs_fitted=True)) == base / "sedan-abs"
    assert vehicle_tables_dir("sedan", base, replace(sedan, esc_fitted=True)) == base
    assert vehicle_tables_dir("compact", base, compact) == base / "compact"
    off = replace(compact, abs_fitted=False)
    assert vehicle_tables_dir("compact", base, off) == base / "compact-noabs"


def test_tables_built_for_other_parameters_are_refused_in_one_line(capsys, tmp_path, tall_tables):
    _, base = tall_tables
    other = tmp_path / "tall.toml"  # the same name, a heavier car
    other.write_text(vehicle_toml(replace(TALL, mass_kg=2100.0)))
    line = _one_error_line(capsys, _run_args(tmp_path, other, base))
    assert str(base / "tall") in line and "mass_kg" in line


class _SumoSizes(StepObserver):
    """The ego's length, width and mass as SUMO has them once the run is set up."""

    def start(self, sim) -> None:
        body = sim.session.body(sim.settings.ego_id)
        self.sizes = (body.length_m, body.width_m, sim.session.mass_kg(sim.settings.ego_id))


@pytest.mark.sumo
def test_the_tall_car_rolls_over_in_its_lane_change_with_its_own_box(tmp_path, tall_tables):
    vehicle, base = tall_tables
    settings = RunSettings(vehicle=TALL, vehicle_id=str(vehicle), tables_dir=base)
    sizes = _SumoSizes()
    sim = CoSimulation(BASELINE, AT_165, settings, observers=[sizes])
    summary, log = sim.run()
    write_run(tmp_path, summary, log, "csv", sim.traffic, sim.session.ego_lane_centreline())
    assert sizes.sizes == (5.30, 2.00, TALL.mass_kg)
    with (tmp_path / "traffic.csv").open(newline="") as fh:
        ego_rows = [r for r in csv.DictReader(fh) if r["role"] == "ego"]
    assert ego_rows and {(r["length_m"], r["width_m"]) for r in ego_rows} == {("5.3", "2")}
    assert summary["vehicle"] == str(vehicle)
    assert 2 in summary["modes_visited"]  # the lane change had begun
    assert summary["outcome"] == "orange" and summary["collision_with"] == "none"
    assert "rollover: both inner" in summary["reason"] or "static stability" in summary["reason"]
    assert summary["end_cause"] == "rollover", summary["reason"]
    # both inner wheels lifted (no load left), or the static stability limit passed first
    assert summary["min_tyre_load_n"] == 0.0 or "static stability" in summary["reason"]
    assert summary["rollover_time_s"] is not None


@pytest.mark.sumo
def test_the_sedan_does_not_roll_over_in_the_same_case(tmp_path):
    out = tmp_path / "sedan"
    argv = ["run", str(BASELINE), "--speed-kmh", "165", "--mu", "1.0", "--out", str(out)]
    assert main([*argv, "--vehicle", "sedan"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["vehicle"] == "sedan" and summary["rollover_time_s"] is None
    assert summary["end_cause"] != "rollover" and summary["min_tyre_load_n"] > 1000.0
    assert "rollover" not in summary["reason"]
    shutil.rmtree(out)


@pytest.mark.parametrize("name", ["compact", "sedan-r13h", "suv", "van", "pickup"])
def test_every_catalogue_vehicle_ships_tables_built_from_its_file(name):
    """A changed vehicle file without rebuilt tables fails here, not in a user's run."""
    params = load_vehicle(name)
    tables = vehicle_tables(name, params, cached=False)
    assert tables.params == params


@pytest.mark.parametrize("name", ["compact", "suv", "van", "pickup"])
def test_the_catalogue_without_abs_ships_tables_of_its_own(name):
    params = replace(load_vehicle(name), abs_fitted=False, esc_fitted=False)
    tables = vehicle_tables(name, params, cached=False)
    assert tables.params == params and tables.max_decel_mps2(1.0) < 1.0 * 9.81


@pytest.mark.parametrize("name", ["sedan", "sedan-r13h"])
def test_the_sedans_with_abs_ship_tables_of_their_own(name):
    params = replace(load_vehicle(name), abs_fitted=True, esc_fitted=True)
    tables = vehicle_tables(name, params, cached=False)
    assert tables.max_decel_mps2(1.0) > vehicle_tables(
        "sedan", load_vehicle("sedan")
    ).max_decel_mps2(1.0)
