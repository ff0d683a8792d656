"""The committed tables (tables/): physics of the boundaries, metadata, interpolation API."""

import csv
import dataclasses
import itertools
import json
import math
import shutil

import numpy as np
import pytest

from eoam_sumo import __version__
from eoam_sumo.decision.dmm import BoundaryCurve
from eoam_sumo.errors import InputError
from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.tables import (
    DESIGN_FIELDS,
    LookupTables,
    PhaseBoundaries,
    default_tables_dir,
)
from eoam_sumo.params import G_MPS2, describe, ego_e_class_sedan

P = ego_e_class_sedan()
S = DesignSettings()
W = 0.5 * (P.width_m + S.obstacle_width_m)
DIR = default_tables_dir()
COLS = (
    "stop_distance_m",
    "stop_distance_buffered_m",
    "clear_distance_const_m",
    "clear_distance_opt_m",
    "clear_distance_buffered_m",
)


def _rows():
    with open(DIR / "phase_boundaries.csv") as f:
        lines = [ln for ln in f if not ln.startswith("#")]
    out = {}
    for r in csv.DictReader(lines):
        out[(float(r["mu"]), float(r["speed_kmh"]))] = {k: float(v) for k, v in r.items()}
    return out


ROWS = _rows()
MUS = sorted({k[0] for k in ROWS}, reverse=True)
SPEEDS = sorted({k[1] for k in ROWS})


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(DIR)


def test_committed_grid_is_the_default_grid():
    assert MUS == [1.0, 0.7, 0.3, 0.1]
    assert list(S.speeds_kmh) == SPEEDS
    meta = json.loads((DIR / "metadata.json").read_text())
    assert meta["package_version"] == __version__
    wanted = describe(P)
    assert {k: meta["vehicle"][k]["value"] for k in DESIGN_FIELDS} == {
        k: wanted[k]["value"] for k in DESIGN_FIELDS
    }
    assert meta["solver"]["options"]["ipopt.print_level"] == 0


def test_stopping_distance_is_eq_33_and_above_the_friction_floor():
    """B0 is eq. 33 at limit braking's deceleration, the design's share of the no-lock one."""
    for (mu, kmh), r in ROWS.items():
        v = kmh / 3.6
        decel = max_decel_no_lock_mps2(P, mu)
        assert r["max_decel_mps2"] == pytest.approx(decel, abs=1e-4)
        braking = S.limit_brake_fraction * decel
        assert r["stop_distance_m"] == pytest.approx(v * v / (2 * braking), abs=2e-4)
        assert r["stop_distance_m"] >= v * v / (2 * mu * G_MPS2)


def test_clearing_distances_respect_the_point_mass_floors():
    """The optimum uses at most ``friction_use`` of the friction: its floor is that share's.
    Planned within 0.9 of each axle's friction it was never longer than the constant-speed
    quintic (at 0.8 mu g, kinematic) by more than 1 %; a clearing distance scales with
    1 / sqrt(share), so within ``friction_use`` by at most 1.01 sqrt(0.9 / friction_use)
    (0.8: 7.1 %; measured 6.1 %, dry road at 175 km/h)."""
    for (mu, kmh), r in ROWS.items():
        v = kmh / 3.6
        assert r["clear_distance_const_m"] >= v * math.sqrt(2 * W / (mu * G_MPS2))
        floor = v * math.sqrt(2 * W / (S.friction_use * mu * G_MPS2))
        assert r["clear_distance_opt_m"] >= floor - W
        longest = 1.01 * math.sqrt(0.9 / S.friction_use) * r["clear_distance_const_m"]
        assert r["clear_distance_opt_m"] <= longest


def test_optimised_clearing_is_within_1_3_of_the_point_mass_bound_from_60_kmh():
    ratios = [
        r["clear_distance_opt_m"] / (kmh / 3.6 * math.sqrt(2 * W / (S.friction_use * mu * G_MPS2)))
        for (mu, kmh), r in ROWS.items()
        if kmh >= 60
    ]
    assert max(ratios) <= 1.3
    assert min(ratios) >= 1.0


def test_boundaries_grow_with_speed_and_with_falling_friction():
    for col in COLS:
        for mu in MUS:
            values = [ROWS[(mu, v)][col] for v in SPEEDS]
            assert all(b > a for a, b in itertools.pairwise(values)), (col, mu)
        for v in SPEEDS:
            values = [ROWS[(mu, v)][col] for mu in MUS]
            assert all(b > a for a, b in itertools.pairwise(values)), (col, v)


def test_steering_needs_less_distance_than_braking_from_90_kmh():
    for (_, kmh), r in ROWS.items():
        if kmh >= 90:
            assert r["clear_distance_opt_m"] < r["stop_distance_m"]
            assert r["clear_distance_buffered_m"] < r["stop_distance_buffered_m"]


def test_buffers_and_ttc_follow_the_design_settings():
    for (mu, kmh), r in ROWS.items():
        v = kmh / 3.6
        assert r["stop_distance_buffered_m"] == pytest.approx(
            r["stop_distance_m"] + S.brake_buffer_time_s * v + S.brake_buffer_m, abs=2e-4
        )
        assert r["clear_distance_buffered_m"] == pytest.approx(
            r["clear_distance_opt_m"] + S.steer_buffer_time_s * v + S.steer_buffer_m, abs=2e-4
        )
        assert r["ttc_s"] == {1.0: 2.5, 0.7: 2.5, 0.3: 5.0, 0.1: 20.0}[mu]


def test_boundaries_at_grid_points_equal_the_csv_and_interpolate_linearly(tables):
    b = tables.boundaries
    for (mu, kmh), r in list(ROWS.items())[::7]:
        got = b.at(mu, kmh / 3.6)
        assert got.stop_m == pytest.approx(r["stop_distance_m"])
        assert got.clear_opt_m == pytest.approx(r["clear_distance_opt_m"])
        assert got.clear_const_m == pytest.approx(r["clear_distance_const_m"])
        assert got.stop_buffered_m == pytest.approx(r["stop_distance_buffered_m"])
        assert got.clear_buffered_m == pytest.approx(r["clear_distance_buffered_m"])
        assert got.ttc_s == r["ttc_s"]
    mid = b.at(0.5, 92.5 / 3.6)
    corners = [ROWS[(m, v)]["clear_distance_opt_m"] for m in (0.3, 0.7) for v in (90.0, 95.0)]
    assert mid.clear_opt_m == pytest.approx(sum(corners) / 4)
    assert mid.ttc_s == pytest.approx(3.75)


def test_boundaries_outside_the_grid(tables):
    b = tables.boundaries
    # below the grid: B0 = v^2 / (2 a) (a quarter at half the lowest speed), the clearing
    # boundaries scaled linearly to 0 (a half), the TTC kept
    low, first = b.at(1.0, 10.0 / 3.6), ROWS[(1.0, 20.0)]
    assert low.stop_m == pytest.approx(first["stop_distance_m"] / 4)
    assert low.clear_opt_m == pytest.approx(first["clear_distance_opt_m"] / 2)
    assert low.clear_buffered_m == pytest.approx(first["clear_distance_buffered_m"] / 2)
    assert low.ttc_s == 2.5
    assert b.at(0.3, 0.0)[:4] == pytest.approx((0.0, S.brake_buffer_m, 0.0, 0.0), abs=1e-3)
    assert b.at(0.3, -3.0) == b.at(0.3, 0.0)
    assert b.at(1.0, 300 / 3.6) == b.at(1.0, 175 / 3.6)
    assert b.at(1.2, 90 / 3.6) == b.at(1.0, 90 / 3.6)


def test_trajectory_matches_the_stored_rows_and_is_linear_between(tables):
    with np.load(DIR / "lookup_tables.npz") as data:
        names = ("y_m", "ax_mps2", "yaw_rad", "curvature_1pm", "steer_rad", "sideslip_rad")
        stored = np.stack([data[n] for n in names])
        lengths = data["length_m"]
        step = float(data["dx_step_m"])
        mu_grid, v_grid = list(data["mu_grid"]), list(data["speed_grid_mps"])
    i, j = mu_grid.index(0.7), 14
    traj = tables.trajectory(0.7, v_grid[j])
    assert traj.length_m == pytest.approx(lengths[i, j])
    for k in (0, 1, 17, 40, int(lengths[i, j] / step)):
        assert traj.at(k * step) == pytest.approx(tuple(stored[:, i, j, k]), abs=1e-12)
        a, b = stored[:, i, j, k], stored[:, i, j, k + 1]
        assert traj.at((k + 0.25) * step) == pytest.approx(tuple(a + 0.25 * (b - a)), abs=1e-12)
    assert traj.at(-1.0) == traj.at(0.0)
    assert traj.at(1e4) == (S.lane_change_m, 0.0, 0.0, 0.0, 0.0, 0.0)
    # half-way between two grid speeds: the mean of the two rows
    half = tables.trajectory(0.7, 0.5 * (v_grid[j] + v_grid[j + 1]))
    mean = 0.5 * (stored[:, i, j, 20] + stored[:, i, j + 1, 20])
    assert half.at(20 * step) == pytest.approx(tuple(mean), abs=1e-12)
    # below the lowest grid speed: clamped to it
    assert tables.trajectory(1.0, 1.0).at(3.0) == tables.trajectory(1.0, v_grid[0]).at(3.0)


def test_rows_past_the_end_hold_the_final_values():
    with np.load(DIR / "lookup_tables.npz") as npz:
        data = {k: npz[k] for k in npz.files}
    step = float(data["dx_step_m"])
    for i in range(len(data["mu_grid"])):
        for j in range(len(data["speed_grid_mps"])):
            end = math.ceil(data["length_m"][i, j] / step) + 1
            assert np.all(data["y_m"][i, j, end:] == S.lane_change_m)
            for name in ("ax_mps2", "yaw_rad", "curvature_1pm", "steer_rad", "sideslip_rad"):
                assert np.all(data[name][i, j, end:] == 0.0)
            # and the manoeuvre itself ends in the next lane, parallel
            assert data["y_m"][i, j, end - 2] == pytest.approx(S.lane_change_m, abs=0.03)
            # (planned within 0.8 of the friction, mu 0.3 / 20 km/h turns straight in its last
            # metre: 0.012 rad one sample before the end)
            assert abs(data["yaw_rad"][i, j, end - 2]) < 0.015


def test_path_yaw_and_curvature_tables_agree_with_the_path(tables):
    """Within a manoeuvre: dy/dx = tan(yaw) and d(yaw)/dx = curvature / cos(yaw)."""
    with np.load(DIR / "lookup_tables.npz") as data:
        step = float(data["dx_step_m"])
        for i, j in ((0, 5), (2, 20), (3, 31)):
            n = int(data["length_m"][i, j] / step)
            y, yaw, k = (data[name][i, j, :n] for name in ("y_m", "yaw_rad", "curvature_1pm"))
            dydx = np.gradient(y, step)
            assert np.abs(dydx - np.tan(yaw)).max() < 0.02
            dyaw = np.gradient(yaw, step)
            # mu 1.0 / 45 km/h within 0.8 of the friction: 0.1000 near its end
            assert np.abs(dyaw - k / np.cos(yaw))[2:-2].max() < 0.11 * np.abs(k).max()


def test_max_decel_is_the_no_lock_limit(tables):
    for mu in (1.0, 0.5, 0.1):
        assert tables.max_decel_mps2(mu) == max_decel_no_lock_mps2(P, mu)


def test_other_vehicle_parameters_are_refused():
    other = dataclasses.replace(P, mass_kg=1800.0)
    with pytest.raises(InputError, match=r"mass_kg.*eoam-sumo tables"):
        LookupTables.load(DIR, params=other)


def test_missing_or_broken_tables_are_input_errors(tmp_path):
    with pytest.raises(InputError, match=r"metadata\.json"):
        LookupTables.load(tmp_path / "nowhere")
    broken = tmp_path / "broken"
    shutil.copytree(DIR, broken)
    (broken / "metadata.json").write_text("{not json")
    with pytest.raises(InputError, match="malformed JSON"):
        LookupTables.load(broken)
    partial = tmp_path / "partial"
    shutil.copytree(DIR, partial)
    (partial / "phase_boundaries.csv").write_text("mu,speed_kmh\n1.0,zz\n")
    with pytest.raises(InputError, match=r"phase_boundaries\.csv"):
        PhaseBoundaries.load(partial)


@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
@pytest.mark.parametrize("kmh", [5.0, 10.0, 15.0, 19.0])
def test_braking_boundaries_below_the_grid_are_the_closed_form(tables, mu, kmh):
    """Below 20 km/h of closing speed: B0 = v^2 / (2 a) (eq. 33) with limit braking's share of
    the csv's deceleration at this mu, Bb = B0 + t_b v + c_b (sec. 6.2) with the design's
    buffers; the DMM's curve agrees."""
    v = kmh / 3.6
    stop = v * v / (2.0 * S.limit_brake_fraction * ROWS[(mu, 20.0)]["max_decel_mps2"])
    buffered = stop + S.brake_buffer_time_s * v + S.brake_buffer_m
    got = tables.boundaries.at(mu, v)
    assert got.stop_m == pytest.approx(stop, rel=1e-3)
    assert got.stop_buffered_m == pytest.approx(buffered, rel=1e-3)
    # the clearing boundaries have no closed form: scaled linearly to 0 from the lowest row
    low = ROWS[(mu, 20.0)]
    assert got.clear_opt_m == pytest.approx(low["clear_distance_opt_m"] * kmh / 20.0)
    assert got.clear_buffered_m == pytest.approx(low["clear_distance_buffered_m"] * kmh / 20.0)
    curve = BoundaryCurve(tables.boundaries, mu, tables.speed_grid_mps)
    row = curve.at(v)
    assert row.stop_m == pytest.approx(stop, rel=2e-3, abs=1e-3)
    assert row.stop_buffered_m == pytest.approx(buffered, rel=1e-3)


def test_runs_outside_the_tables_are_refused(tables):
    tables.check_run(1.0, 5 / 3.6)  # the design range starts at 5 km/h
    tables.check_run(0.1, 10 / 3.6)
    with pytest.raises(InputError, match=r"4\.0 km/h is outside the design range \[5, 175\]"):
        tables.check_run(1.0, 4 / 3.6)
    tables.check_run(1.0, 175 / 3.6)
    tables.check_run(1.2, 55 / 3.6)
    with pytest.raises(InputError, match=r"180\.0 km/h"):
        tables.check_run(1.0, 180 / 3.6)
    with pytest.raises(InputError, match=r"mu 0\.05"):
        tables.check_run(0.05, 90 / 3.6)


def test_default_tables_dir_env_override(monkeypatch, tmp_path):
    monkeypatch.setenv("EOAM_TABLES_DIR", str(tmp_path))
    assert default_tables_dir() == tmp_path
    monkeypatch.delenv("EOAM_TABLES_DIR")
    assert (default_tables_dir() / "phase_boundaries.csv").is_file()


def test_cached_tables_are_read_again_when_a_file_changes(tmp_path):
    """A batch worker keeps the tables it read while their files are unchanged; a rebuilt
    file (another size or modification time) is read again, and the kept arrays are
    read-only (shared by every run of the process)."""
    import os

    folder = tmp_path / "tables"
    shutil.copytree(default_tables_dir(), folder)
    first = LookupTables.cached(folder)
    assert LookupTables.cached(folder) is first
    with pytest.raises(ValueError, match="read-only"):
        first.length_m[0, 0] = 1.0
    npz = folder / "lookup_tables.npz"
    stat = npz.stat()
    os.utime(npz, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))
    again = LookupTables.cached(folder)
    assert again is not first and np.array_equal(again.length_m, first.length_m)
    (folder / "metadata.json").unlink()
    with pytest.raises(InputError, match="metadata"):
        LookupTables.cached(folder)
