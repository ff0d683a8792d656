"""Bad input on every CLI path: exit status 2, one line on stderr naming the culprit."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from eoam_sumo.cli import main
from tests.builders import write_matrix

ROOT = Path(__file__).resolve().parents[1]
SCEN = ROOT / "scenarios"


def _copy_scenario(tmp_path: Path) -> Path:
    """A private copy of the baseline scenario (sumocfg, routes, vTypes, net, parking)."""
    dst = tmp_path / "scen"
    shutil.copytree(SCEN, dst)
    shutil.copytree(ROOT / "networks", tmp_path / "networks")
    return dst / "baseline.sumocfg"


def _check(capsys, argv, needle):
    status = main(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.startswith("eoam-sumo")]
    assert status == 2, err
    assert len(lines) == 1 and needle in lines[0], err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["run", "nope.sumocfg"], "nope.sumocfg"),
        (["run", str(SCEN / "baseline.sumocfg"), "--mu", "0"], "mu 0"),
        (["run", str(SCEN / "baseline.sumocfg"), "--mu", "1.3"], "1.3"),
        (["run", str(SCEN / "baseline.sumocfg"), "--speed-kmh", "abc"], "abc"),
        (["run", str(SCEN / "baseline.sumocfg"), "--oncoming-m", "-10"], "-10"),
        (["run", str(SCEN / "baseline.sumocfg"), "--oncoming-m", "far"], "far"),
        (["run", str(SCEN / "baseline.sumocfg"), "--speed-kmh", "300"], "300"),
        (["run", str(SCEN / "baseline.sumocfg"), "--frobnicate"], "--frobnicate"),
        (["run", str(SCEN / "baseline.sumocfg"), "--driver", "human"], "human"),
        (["run", str(SCEN / "baseline.sumocfg"), "--sumo-step-s", "0.015"], "--sumo-step-s"),
        (["batch", str(SCEN / "table2.toml"), "--sumo-step-s", "0.2"], "--sumo-step-s"),
        (["bench", "--studies", "--sumo-steps", "0.01", "0.3"], "--sumo-steps"),
        (["tables", "--jobs", "0"], "0"),
        (["batch", "missing.toml"], "missing.toml"),
        (["plot", "no_such_folder"], "no_such_folder"),
        (["launch"], "launch"),
    ],
)
def test_bad_arguments(capsys, tmp_path, argv, needle):
    _check(capsys, argv + (["--out", str(tmp_path / "o")] if argv[0] == "run" else []), needle)


def test_protocol_sumo_step_out_of_range_writes_nothing(capsys, tmp_path):
    out = tmp_path / "p"
    _check(capsys, ["protocol", "unr152", "--out", str(out), "--sumo-step-s", "0"], "--sumo-step-s")
    assert not out.exists()


def test_malformed_sumocfg(capsys, tmp_path):
    cfg = tmp_path / "broken.sumocfg"
    cfg.write_text("<configuration><input><net-file value='x.net.xml'/>")
    _check(capsys, ["run", str(cfg), "--out", str(tmp_path / "o")], "broken.sumocfg")


@pytest.mark.parametrize("victim", ["baseline.rou.xml", "../networks/highway.net.xml"])
def test_malformed_route_or_net_file(capsys, tmp_path, victim):
    cfg = _copy_scenario(tmp_path)
    target = (cfg.parent / victim).resolve()
    target.write_text(target.read_text()[:200])  # cut off mid-element
    _check(capsys, ["run", str(cfg), "--out", str(tmp_path / "o")], target.name)


def test_sumocfg_without_ego(capsys, tmp_path):
    cfg = _copy_scenario(tmp_path)
    _check(capsys, ["run", str(cfg), "--ego", "hero", "--out", str(tmp_path / "o")], "hero")


def test_a_flow_as_the_ego_is_named_as_such(capsys, tmp_path):
    cfg = _copy_scenario(tmp_path)
    routes = cfg.parent / "baseline.rou.xml"
    text = routes.read_text()
    start = text.index('<vehicle id="ego"')
    end = text.index("</vehicle>", start) + len("</vehicle>")
    flow = '<flow id="ego" type="ego" route="eastbound" begin="1" end="10" number="2"/>'
    routes.write_text(text[:start] + flow + text[end:])
    _check(capsys, ["run", str(cfg), "--out", str(tmp_path / "o")], "a flow cannot be the ego")


def test_unwritable_output_folder(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    _check(
        capsys,
        ["run", str(SCEN / "baseline.sumocfg"), "--out", str(blocker / "sub")],
        str(blocker),
    )


@pytest.mark.parametrize(
    "text, needle",
    [
        ("[scenario\nsumocfg = 1", "m.toml"),
        (
            '[scenario]\nsumocfg = "baseline.sumocfg"\n[sweep]\nego_sped_kmh = [120]\n',
            "ego_sped_kmh",
        ),
        (
            (
                '[scenario]\nsumocfg = "baseline.sumocfg"\n[sweep]\n'
                "ego_speed_kmh = [120]\nmu = [2.0]\n"
            ),
            "mu",
        ),
        (
            (
                '[scenario]\nsumocfg = "baseline.sumocfg"\n[sweep]\n'
                "ego_speed_kmh = [120]\nmu = [1.0]\n"
                "oncoming_start_m = [-3]\n"
            ),
            "oncoming_start_m",
        ),
        ('[scenario]\nsumocfg = "baseline.sumocfg"\n[weather]\nrain = true\n', "weather"),
    ],
)
def test_bad_matrix(capsys, tmp_path, text, needle):
    matrix = tmp_path / "m.toml"
    shutil.copy(SCEN / "baseline.sumocfg", tmp_path / "baseline.sumocfg")
    matrix.write_text(text)
    _check(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], needle)


def test_results_already_written_survive_a_bad_resume(capsys, tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.csv").write_text("case_id,outcome\nx,green\n")
    _check(
        capsys,
        ["batch", str(tmp_path / "missing.toml"), "--out", str(out), "--resume"],
        "missing.toml",
    )
    assert (out / "results.csv").read_text() == "case_id,outcome\nx,green\n"


def test_python_dash_m_behaves_the_same(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "eoam_sumo", "run", str(SCEN / "baseline.sumocfg"), "--mu", "9"],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "9" in proc.stderr


def _matrix(folder: Path, cfg: Path, sweep: str, name: str = "m.toml") -> Path:
    return write_matrix(folder / name, sweep, cfg, scenario="max_time_s = 5.0\n")


@pytest.mark.parametrize(
    "sweep, key, value",
    [
        ("ego_speed_kmh = [120, 250]\nmu = [1.0]\n", "ego_speed_kmh", "value 250 "),
        ("ego_speed_kmh = [120]\nmu = [1.0, 0.05]\n", "mu", "value 0.05 "),
    ],
)
def test_batch_outside_the_tables_is_refused_before_any_case_runs(
    capsys, tmp_path, monkeypatch, sweep, key, value
):
    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)  # the repository's tables (20-175 km/h)
    matrix = _matrix(tmp_path, SCEN / "baseline.sumocfg", sweep)
    out = tmp_path / "o"
    status = main(["batch", str(matrix), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert status == 2, err
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert str(matrix) in lines[0] and f"[sweep] {key} {value}" in lines[0], err
    assert not out.exists()  # nothing ran, nothing written


def test_batch_bad_input_leaves_an_earlier_results_file_alone(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.csv").write_text("case_id,outcome\nx,green\n")
    matrix = _matrix(tmp_path, SCEN / "baseline.sumocfg", "ego_speed_kmh = [300]\nmu = [1.0]\n")
    _check(capsys, ["batch", str(matrix), "--out", str(out), "--resume"], "300")
    assert (out / "results.csv").read_text() == "case_id,outcome\nx,green\n"


def test_batch_tables_folder_that_cannot_be_read(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("EOAM_TABLES_DIR", str(tmp_path / "no_tables"))
    matrix = _matrix(tmp_path, SCEN / "baseline.sumocfg", "ego_speed_kmh = [120]\nmu = [1.0]\n")
    _check(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], "no_tables")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("breakage", ["no ego", "malformed sumocfg", "malformed route file"])
def test_batch_scenario_is_checked_before_any_case_runs(capsys, tmp_path, breakage):
    cfg = _copy_scenario(tmp_path)
    routes = cfg.parent / "baseline.rou.xml"
    if breakage == "no ego":
        routes.write_text(routes.read_text().replace('id="ego"', 'id="hero"'))
        needle = "no vehicle 'ego'"
    elif breakage == "malformed sumocfg":
        cfg.write_text(cfg.read_text()[:300])
        needle = str(cfg)
    else:
        routes.write_text(routes.read_text()[:200])
        needle = "baseline.rou.xml"
    matrix = _matrix(tmp_path, cfg, "ego_speed_kmh = [120]\nmu = [1.0]\n")
    _check(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], needle)
    _check(capsys, ["batch", str(matrix), "--out", str(tmp_path / "o")], f"{matrix}: [scenario]")
    assert not (tmp_path / "o").exists()


def _tables_copy(tmp_path: Path) -> Path:
    dst = tmp_path / "tables"
    shutil.copytree(ROOT / "tables", dst)
    return dst


@pytest.mark.parametrize(
    "damage",
    ["summary", "timeseries-header-only", "timeseries-empty", "timeseries-cut", "npz-missing"],
)
def test_plot_of_a_damaged_folder_names_the_file(tmp_path, capsys, damage):
    """A damaged run or tables folder: one line and exit 2, not a traceback."""
    if damage == "npz-missing":
        folder = _tables_copy(tmp_path)
        (folder / "lookup_tables.npz").unlink()
        _check(capsys, ["plot", str(folder), "--out", str(tmp_path / "png")], "lookup_tables.npz")
        return
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "summary.json").write_text('{"outcome": "green", "mu": 1.0, "modes_visited": [0]}')
    from eoam_sumo.sim.runlog import COLUMNS

    header = ",".join(COLUMNS) + "\n"
    row = ",".join("" if c == "sector" else "0" for c in COLUMNS) + "\n"
    (folder / "timeseries.csv").write_text(header + row + row)
    if damage == "summary":
        (folder / "summary.json").write_text("{oops")
    elif damage == "timeseries-header-only":
        (folder / "timeseries.csv").write_text(header)
    elif damage == "timeseries-empty":
        (folder / "timeseries.csv").write_text("")
    else:
        (folder / "timeseries.csv").write_text(header + row + "1.2e")  # cut mid-number
    name = "summary.json" if damage == "summary" else "timeseries.csv"
    _check(capsys, ["plot", str(folder), "--out", str(tmp_path / "png")], name)


@pytest.mark.parametrize(
    "grid,needle",
    [(["--speeds-kmh", "1"], "speeds_kmh holds 1.0"), (["--mu", "0.001"], "mus holds 0.001")],
)
def test_tables_grid_values_the_optimisation_cannot_solve_are_refused(
    tmp_path, capsys, grid, needle
):
    _check(capsys, ["tables", "--out", str(tmp_path / "t"), *grid], needle)


def test_a_tables_folder_mixing_two_builds_is_refused(tmp_path, capsys):
    import json

    folder = _tables_copy(tmp_path)
    meta = json.loads((folder / "metadata.json").read_text())
    meta["grids"]["mu"] = meta["grids"]["mu"][1:]  # as if the metadata came from another build
    (folder / "metadata.json").write_text(json.dumps(meta))
    _check(
        capsys,
        [
            "run",
            str(SCEN / "baseline.sumocfg"),
            "--tables",
            str(folder),
            "--out",
            str(tmp_path / "run"),
        ],
        "mixes two builds",
    )


@pytest.mark.sumo
def test_gui_without_a_display_fails_at_once(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if not sys.platform.startswith("linux"):
        pytest.skip("the display check is for Linux")
    _check(
        capsys,
        ["run", str(SCEN / "baseline.sumocfg"), "--gui", "--out", str(tmp_path / "run")],
        "DISPLAY is not set",
    )
