"""Bad input (vehicle values, crashes on input, matrix checks): each refused with
exit status 2 and exactly one line on stderr naming the file, key and value; nothing written
before is lost. Every refusal here comes before SUMO or the plant starts."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from eoam_sumo.cli import main
from eoam_sumo.params import VEHICLE_RANGES, VehicleParams, ego_e_class_sedan
from eoam_sumo.seeds import SEED_MAX, check_seed, sumo_seed
from eoam_sumo.sim.runlog import COLUMNS
from eoam_sumo.sim.trafficlog import TRAFFIC_COLUMNS
from eoam_sumo.vehicle_files import catalogue, load_vehicle, vehicle_toml
from tests.builders import write_matrix

ROOT = Path(__file__).resolve().parents[1]
SCEN = ROOT / "scenarios"
NOT_UTF8 = b"\xff\xfe caf\xe9\n"


def _refused(capsys, argv: list[str], *needles: str) -> str:
    """Run the command line: status 2, one line on stderr holding every needle."""
    status = main(argv)
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert status == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], err
    return lines[0]


# --- 6. vehicle files --------------------------------------------------------------------


def _vehicle_file(tmp_path: Path, **values) -> Path:
    """The sedan's file with ``values`` written over its own (no dataclass check on the way)."""
    text = vehicle_toml(ego_e_class_sedan())
    for key, value in values.items():
        text = re.sub(rf"(\[{key}\]\nvalue = )[^\n]*", rf"\g<1>{value!r}", text)
    path = tmp_path / "car.toml"
    path.write_text(text)
    return path


ZERO_OR_TINY = [
    ("mass_kg", 0.0),
    ("mass_kg", 1e-300),
    ("cg_to_front_m", 0.0),
    ("cg_to_rear_m", 0.0),
    ("wheel_radius_m", 0.0),
    ("wheel_inertia_kgm2", 0.0),
    ("max_brake_force_n", 0.0),
    ("cornering_stiffness_front_npr", 0.0),
    ("cornering_stiffness_rear_npr", 0.0),
    ("steer_lag_s", 0.0),
    ("drive_lag_s", 0.0),
    ("brake_lag_s", 0.0),
    ("esc_lag_s", 0.0),
    ("track_m", 0.0),
    ("yaw_inertia_kgm2", 0.0),
    ("relaxation_length_long_m", 0.0),
    ("relaxation_length_lat_m", 0.0),
    ("brake_front_share", 1.5),
    ("mass_kg", math.inf),
]


@pytest.mark.parametrize("key, value", ZERO_OR_TINY)
def test_a_vehicle_value_outside_its_physical_range_is_refused_naming_file_and_key(
    capsys, tmp_path, key, value
):
    path = _vehicle_file(tmp_path, **{key: value})
    out = tmp_path / "o"
    argv = ["vehicle-test", "brake", "--vehicle", str(path), "--out", str(out)]
    _refused(capsys, argv, str(path), key, repr(value))
    assert not out.exists()


@pytest.mark.parametrize(
    "command",
    [
        ["run", str(SCEN / "baseline.sumocfg")],
        ["protocol", "unr152"],
        ["tables"],
    ],
)
def test_every_command_taking_a_vehicle_refuses_a_bad_one(capsys, tmp_path, command):
    path = _vehicle_file(tmp_path, mass_kg=0.0)
    _refused(capsys, [*command, "--vehicle", str(path), "--out", str(tmp_path / "o")], "mass_kg")


def test_a_matrix_vehicle_outside_its_range_is_refused(capsys, tmp_path):
    path = _vehicle_file(tmp_path, relaxation_length_lat_m=0.0)
    matrix = write_matrix(
        tmp_path / "m.toml",
        "ego_speed_kmh = [100]\nmu = [1.0]\n",
        scenario=f'vehicle = "{path.as_posix()}"\n',
    )
    _refused(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "m.toml", "relaxation")


@pytest.mark.parametrize("name", sorted(VEHICLE_RANGES))
def test_each_range_refuses_just_outside_and_names_field_unit_and_value(name):
    """Below the low end (or negative when it is 0) and above the high end: ValueError with
    the field's name, the value and its unit."""
    low, high = VEHICLE_RANGES[name]
    unit = next(f.metadata["unit"] for f in dataclasses.fields(VehicleParams) if f.name == name)
    for value in (low - max(abs(low) * 0.01, 1e-3), high * 1.01 + 1e-3, math.nan):
        with pytest.raises(
            ValueError, match=rf"{name} = {re.escape(repr(value))} {re.escape(unit)}"
        ):
            dataclasses.replace(ego_e_class_sedan(), **{name: value})


def test_every_catalogue_vehicle_lies_within_the_ranges():
    for name in catalogue():
        params = load_vehicle(name)
        for field, (low, high) in VEHICLE_RANGES.items():
            assert low <= getattr(params, field) <= high, (name, field)


@pytest.mark.parametrize(
    "values, needle",
    [
        ({"length_m": 3.0}, "length_m = 3.0 m is shorter"),
        ({"track_m": 1.9}, "track_m = 1.9 m exceeds width_m"),
        ({"yaw_inertia_kgm2": 400.0}, "dynamic index"),
        ({"mass_kg": 9000.0, "yaw_inertia_kgm2": 4175.0 * 9000 / 1723}, "front tyre"),
    ],
)
def test_inconsistent_values_are_refused_naming_the_relation(values, needle):
    with pytest.raises(ValueError, match=re.escape(needle)):
        dataclasses.replace(ego_e_class_sedan(), **values)


# --- 7. crashes on input -----------------------------------------------------------------


@pytest.mark.parametrize(
    "option, value",
    [
        ("--speed-kmh", "1e308"),
        ("--speed-kmh", "0.5"),
        ("--speed-kmh", "301"),
        ("--speed-kmh", "inf"),
        ("--mu", "1e-300"),
        ("--mu", "0.01"),
    ],
)
def test_vehicle_test_speed_or_friction_outside_its_range_is_refused(
    capsys, tmp_path, option, value
):
    out = tmp_path / "o"
    argv = ["vehicle-test", "brake", option, value, "--out", str(out)]
    _refused(capsys, argv, option, value)
    assert not out.exists()


def test_ramp_steer_that_cannot_reach_the_fit_range_reports_no_gradient(capsys, tmp_path):
    """ISO 4138's gradients are fitted over 0.1-0.4 g; on mu 0.1 the road cannot give that:
    the run is written, the gradients are null with the reason, the status 0."""
    out = tmp_path / "o"
    status = main(["vehicle-test", "ramp-steer", "--mu", "0.1", "--out", str(out)])
    assert status == 0, capsys.readouterr().err
    figures = json.loads((out / "summary.json").read_text())["figures"]
    assert figures["understeer_gradient_deg_per_g"] is None
    assert figures["steer_angle_gradient_deg_per_g"] is None
    assert "0.1-0.4 g" in figures["not_measured"]
    assert figures["peak_lateral_acceleration_g"] < 0.1


def _run_folder(tmp_path: Path, nan_column: str | None = None, traffic_nan: str | None = None):
    """A small run folder (summary, three rows of time series, a traffic log), a NaN in row 2
    of ``nan_column`` of the time series or of ``traffic_nan`` of the traffic log."""
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "summary.json").write_text('{"outcome": "green", "mu": 1.0, "modes_visited": [0]}')
    rows = []
    for k in range(3):
        cells = {c: ("" if c == "sector" else "0") for c in COLUMNS}
        cells.update(time_s=f"{k * 0.01:g}", x_m=f"{k * 0.3:g}", vx_mps="30")
        if nan_column and k == 1:
            cells[nan_column] = "nan"
        rows.append(",".join(cells[c] for c in COLUMNS))
    (folder / "timeseries.csv").write_text(",".join(COLUMNS) + "\n" + "\n".join(rows) + "\n")
    traffic = []
    for k in range(3):
        cells = dict(zip(TRAFFIC_COLUMNS, [f"{k * 0.01:g}", "ego", "passenger", "ego"]))
        cells.update(x_m=f"{k * 0.3:g}", y_m="0", heading_rad="0", speed_mps="30")
        cells.update(length_m="4.9", width_m="1.85")
        if traffic_nan and k == 1:
            cells[traffic_nan] = "nan"
        traffic.append(",".join(cells[c] for c in TRAFFIC_COLUMNS))
    (folder / "traffic.csv").write_text(
        ",".join(TRAFFIC_COLUMNS) + "\n" + "\n".join(traffic) + "\n"
    )
    return folder


@pytest.mark.parametrize("command", ["plot", "animate"])
@pytest.mark.parametrize("column", ["time_s", "x_m", "yaw_rad"])
def test_a_nan_in_the_time_series_is_refused_naming_file_column_and_row(
    capsys, tmp_path, command, column
):
    folder = _run_folder(tmp_path, nan_column=column)
    argv = [
        command,
        str(folder),
        "--out",
        str(tmp_path / ("a.gif" if command == "animate" else "p")),
    ]
    _refused(capsys, argv, "timeseries.csv", f"column {column} is nan in row 2")


@pytest.mark.parametrize("column", ["time_s", "x_m", "y_m"])
def test_a_nan_in_the_traffic_log_is_refused_by_animate(capsys, tmp_path, column):
    folder = _run_folder(tmp_path, traffic_nan=column)
    argv = ["animate", str(folder), "--out", str(tmp_path / "a.gif")]
    _refused(capsys, argv, "traffic.csv", f"column {column} is nan in row 2")


def _matrix_text(scenario: str = "", sweep: str = "ego_speed_kmh = [100]\nmu = [1.0]\n") -> str:
    cfg = (SCEN / "baseline.sumocfg").as_posix()
    return f'[scenario]\nsumocfg = "{cfg}"\n{scenario}[sweep]\n{sweep}'


@pytest.mark.parametrize(
    "scenario, sweep, needle",
    [
        ('abs = ["on"]\n', "", "abs = ['on']"),
        ("esc = {on = true}\n", "", "esc = {'on': True}"),
        ("abs_esc = []\n", "", "abs_esc = []"),
        ("abs = 1\n", "", "abs = 1"),
        ("", 'abs = [["on"]]\n', "abs value ['on']"),
        ("", "esc = [{a = 1}]\n", "esc value {'a': 1}"),
    ],
)
def test_equipment_keys_of_the_wrong_type_are_refused(capsys, tmp_path, scenario, sweep, needle):
    matrix = tmp_path / "m.toml"
    matrix.write_text(_matrix_text(scenario, "ego_speed_kmh = [100]\nmu = [1.0]\n" + sweep))
    _refused(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "m.toml", needle)


def test_non_utf8_matrix_is_refused_naming_it(capsys, tmp_path):
    matrix = tmp_path / "m.toml"
    matrix.write_bytes(_matrix_text().encode() + b"# \xe9\n")
    _refused(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "m.toml", "UTF-8")


def test_non_utf8_paper_table_is_refused_naming_it(capsys, tmp_path):
    table = tmp_path / "paper.csv"
    table.write_bytes(b"oncoming_start_m,ego_speed_kmh,mu,outcome\n\xe9,100,1.0,green\n")
    matrix = tmp_path / "m.toml"
    matrix.write_text(_matrix_text() + f'[paper]\ntable = "{table.as_posix()}"\n')
    _refused(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "paper.csv", "UTF-8")


def test_non_utf8_results_file_is_refused_by_plot_and_kept(capsys, tmp_path):
    batch = tmp_path / "batch"
    batch.mkdir()
    (batch / "results.csv").write_bytes(NOT_UTF8)
    _refused(capsys, ["plot", str(batch), "--out", str(tmp_path / "p")], "results.csv", "UTF-8")
    assert (batch / "results.csv").read_bytes() == NOT_UTF8


@pytest.mark.parametrize("name", ["phase_boundaries.csv", "metadata.json"])
def test_non_utf8_tables_files_are_refused_naming_them(capsys, tmp_path, name):
    tables = tmp_path / "tables"
    tables.mkdir()
    for shipped in ("phase_boundaries.csv", "metadata.json", "lookup_tables.npz"):
        shutil.copy(ROOT / "tables" / shipped, tables / shipped)
    (tables / name).write_bytes(NOT_UTF8)
    argv = [
        "run",
        str(SCEN / "baseline.sumocfg"),
        "--tables",
        str(tables),
        "--out",
        str(tmp_path / "o"),
    ]
    _refused(capsys, argv, name, "UTF-8")


def _nan_in_tables(tables: Path, name: str) -> str:
    """A NaN written into the shipped tables' ``name``; the text the refusal must hold."""
    if name == "phase_boundaries.csv":
        lines = (tables / name).read_text().splitlines()
        k = next(i for i, line in enumerate(lines) if line[:1].isdigit())
        header = next(line for line in lines if line.startswith("mu,")).split(",")
        cells = lines[k].split(",")
        cells[3] = "nan"
        lines[k] = ",".join(cells)
        (tables / name).write_text("\n".join(lines) + "\n")
        return f"column {header[3]} is nan"
    arrays = dict(np.load(tables / name))
    key = "ax_mps2"
    arrays[key] = arrays[key].copy()
    arrays[key].flat[2] = np.nan
    np.savez_compressed(tables / name, **arrays)
    return f"array {key} holds a NaN"


@pytest.mark.parametrize("name", ["phase_boundaries.csv", "lookup_tables.npz"])
def test_a_nan_in_the_lookup_tables_is_refused_naming_file_and_place(capsys, tmp_path, name):
    tables = tmp_path / "tables"
    tables.mkdir()
    for shipped in ("phase_boundaries.csv", "metadata.json", "lookup_tables.npz"):
        shutil.copy(ROOT / "tables" / shipped, tables / shipped)
    needle = _nan_in_tables(tables, name)
    out = tmp_path / "o"
    argv = ["run", str(SCEN / "baseline.sumocfg"), "--tables", str(tables), "--out", str(out)]
    _refused(capsys, argv, name, needle)
    assert not out.exists() or not any(out.iterdir())  # the run wrote nothing


def test_non_utf8_vehicle_file_is_refused_naming_it(capsys, tmp_path):
    path = tmp_path / "car.toml"
    path.write_bytes(NOT_UTF8)
    argv = ["vehicle-test", "brake", "--vehicle", str(path), "--out", str(tmp_path / "o")]
    _refused(capsys, argv, "car.toml", "UTF-8")


# --- 9. matrix checks --------------------------------------------------------------------


def _generated(scenario: str, sweep: str = "", sample: str = "") -> str:
    text = f'[scenario]\nroad = "motorway"\n{scenario}[sweep]\nego_speed_kmh = [100]\nmu = [1.0]\n'
    return text + sweep + (f"[sample]\ndraws = 2\n{sample}" if sample else "")


@pytest.mark.parametrize(
    "text, needles",
    [
        (_generated('los = "A"\n', sample="lanes = { choice = [1] }\n"), ("lanes 1", "sampled")),
        (_generated('los = "A"\n', sample="lanes = { choice = [3, 1] }\n"), ("lanes 1",)),
        (
            _generated('los = "A"\n', sample='curve_radius_m = { choice = ["none", 400] }\n'),
            ("curve radius", "curve_radius_m"),
        ),
        (
            _generated('los = "A"\n', sample="speed_limit_kmh = { uniform = [80, 250] }\n"),
            ("speed_limit_kmh", "250"),
        ),
        (_generated("", sweep='los = ["A", "A"]\n'), ("[sweep] los lists 'A' twice",)),
        (_generated('los = "B"\n', sweep="lanes = [3, 3]\n"), ("[sweep] lanes lists 3 twice",)),
        (
            _generated('los = "B"\nseed = 2147483648\n'),
            ("[scenario] seed = 2147483648", "2147483647"),
        ),
        (_generated('los = "B"\nseed = -1\n'), ("[scenario] seed = -1",)),
        (
            _generated(
                'los = "B"\n', sample="seed = 2147483648\nmu_belief = { uniform = [0.5, 1.0] }\n"
            ),
            ("[sample] seed = 2147483648",),
        ),
        (_generated('los = "B"\nmax_time_s = 1e308\n'), ("max_time_s = 1e+308",)),
    ],
)
def test_matrix_checks_refuse_before_any_case_runs(capsys, tmp_path, text, needles):
    matrix = tmp_path / "m.toml"
    matrix.write_text(text)
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.csv").write_text("case_id,outcome\nx,green\n")
    _refused(capsys, ["batch", str(matrix), "--out", str(out)], "m.toml", *needles)
    assert (out / "results.csv").read_text() == "case_id,outcome\nx,green\n"


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["scenario", "rural", "--los", "A", "--seed", "2147483648"], "seed = 2147483648"),
        (["scenario", "rural", "--los", "A", "--seed", "-1"], "seed = -1"),
        (["run", str(SCEN / "baseline.sumocfg"), "--seed", "2147483648"], "seed = 2147483648"),
        (["run", str(SCEN / "baseline.sumocfg"), "--max-time-s", "1e308"], "--max-time-s 1e+308"),
        (["protocol", "unr152", "--mu", "0.001"], "--mu 0.001"),
    ],
)
def test_seeds_time_limits_and_frictions_out_of_range_are_refused(capsys, tmp_path, argv, needle):
    out = tmp_path / "o"
    _refused(capsys, [*argv, "--out", str(out)], needle)
    assert not out.exists()


def test_seed_range_is_sumos_int_and_warm_up_seeds_stay_in_it():
    assert check_seed(SEED_MAX, "seed") == 2147483647
    assert sumo_seed(SEED_MAX, 1) == 0 and sumo_seed(7, 2) == 9
    for bad in (SEED_MAX + 1, -1, True, 1.0, "3"):
        with pytest.raises(ValueError, match="seed"):
            check_seed(bad, "seed")


@pytest.mark.parametrize("options", [{"speed_kmh": 1e308}, {"speed_kmh": 0.0}, {"mu": 1e-300}])
def test_vehicle_test_options_check_themselves(options):
    from eoam_sumo.vehicle_tests.common import VehicleTestOptions

    with pytest.raises(ValueError, match=next(iter(options))):
        VehicleTestOptions(**options)


def test_huge_swept_values_give_case_ids_a_file_system_takes(tmp_path):
    """1e308 written as its 309 digits made a case folder's name too long (a traceback)."""
    from eoam_sumo.matrix import load_matrix

    sweep = "ego_speed_kmh = [120]\nmu = [1.0]\naro_hold_s = [1e308, 2]\n"
    matrix = write_matrix(tmp_path / "m.toml", sweep + "oncoming_start_m = [1e20, 400]\n")
    ids = [case.case_id for case in load_matrix(matrix).cases()]
    assert "onc-1e20_v120_mu1.0_hold1e308" in ids and "onc-400_v120_mu1.0_hold2" in ids
    assert max(len(i) for i in ids) < 100


@pytest.mark.parametrize(
    "sweep, needle",
    [
        ("ego_speed_kmh = [100, 100.0]\nmu = [1.0]\n", "ego_speed_kmh lists 100.0 twice"),
        ("ego_speed_kmh = [100]\nmu = [1.0, 1]\n", "mu lists 1 twice"),
        ('ego_speed_kmh = [100]\nmu = [1.0]\noncoming_start_m = ["none", "none"]\n', "twice"),
        ("ego_speed_kmh = [100]\nmu = [1.0]\naro_hold_s = [2, 2]\n", "aro_hold_s lists 2 twice"),
        ('ego_speed_kmh = [100]\nmu = [1.0]\nabs = ["on", "on"]\n', "abs lists 'on' twice"),
        ('ego_speed_kmh = [100]\nmu = [1.0]\npolicy = ["safe", "safe"]\n', "policy lists"),
        (
            'ego_speed_kmh = [100]\nmu = [1.0]\nvehicle = ["van", "van"]\n',
            "vehicle lists two vehicles named 'van'",
        ),
    ],
)
def test_every_sweep_key_refuses_a_value_listed_twice(capsys, tmp_path, sweep, needle):
    matrix = tmp_path / "m.toml"
    matrix.write_text(_matrix_text(sweep=sweep))
    _refused(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "m.toml", needle)
