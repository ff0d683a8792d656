"""The compiled plant against the plain-Python reference, the VM fallback, and the build cache."""

import math
import pickle
import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.plant import OUTPUT_NAMES, STATE_NAMES, Plant, ReferencePlant, initial_state
from eoam_sumo.plant.codegen import build_library, find_compiler, python_include

FRONT_LOCKED = OUTPUT_NAMES.index("front_locked")


def manoeuvre(steps=400):
    """4 s at 10 ms: a lane-change-like steer, brake then drive; the surface turns to 0.3 at
    2 s, where the brake locks the front axle. Yields (u, mu) per step."""
    for k in range(steps):
        t = k * 0.01
        steer = math.radians(1.0) * math.sin(2 * math.pi * t / 3.0) if t < 3.0 else 0.0
        brake = 9000.0 if 1.0 <= t < 2.6 else 0.0
        drive = 2500.0 if t >= 3.0 else 0.0
        yield np.array([steer, drive, brake]), (0.8 if t < 2.0 else 0.3)


def run(plant_like):
    x = initial_state(10.0, -3.0, 0.2, 100.0 / 3.6)
    states, outs = [], []
    for u, mu in manoeuvre():
        x, y = plant_like.step(x, u, mu)
        states.append(x)
        outs.append(y)
    return np.array(states), np.array(outs)


@pytest.fixture(scope="module")
def compiled_run(plant):
    return run(plant)


def test_compiled_plant_matches_plain_python_reference(compiled_run, params):
    states, outs = compiled_run
    ref_states, ref_outs = run(ReferencePlant(params))
    assert outs[:, FRONT_LOCKED].any() and not outs[:, FRONT_LOCKED].all()
    np.testing.assert_allclose(states, ref_states, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(outs, ref_outs, rtol=1e-9, atol=1e-9)


def test_virtual_machine_fallback_gives_the_same_numbers(compiled_run, params):
    vm = Plant(params, use_compiler=False)
    assert vm.backend == "casadi-vm" and vm.library_path is None
    states, outs = run(vm)
    np.testing.assert_allclose(states, compiled_run[0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(outs, compiled_run[1], rtol=1e-12, atol=1e-12)


def test_the_integration_converges_when_the_step_is_halved(params):
    coarse, fine = ReferencePlant(params, 1e-3, 10), ReferencePlant(params, 5e-4, 20)
    xc = xf = initial_state(0.0, 0.0, 0.0, 25.0)
    for k in range(100):
        u = np.array([math.radians(3.0) * math.sin(2 * math.pi * k / 100), 1000.0, 0.0])
        xc, _ = coarse.step(xc, u, 0.9)
        xf, _ = fine.step(xf, u, 0.9)
    assert abs(xf[1]) > 0.1  # the manoeuvre moved the car sideways
    # second order in the body's motion; the wheels' Coulomb torques are split off (first order)
    np.testing.assert_allclose(xc[:6], xf[:6], rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(xc, xf, rtol=1e-4, atol=5e-3)


def test_second_plant_reuses_the_cached_library(plant, params, plant_cache_dir):
    again = Plant(params, cache_dir=plant_cache_dir)
    assert again.library_path == plant.library_path
    assert all(p.suffix == ".so" for p in plant_cache_dir.iterdir())  # no temporary files
    x = initial_state(0.0, 0.0, 0.0, 20.0)
    u = np.array([0.05, 0.0, 3000.0])
    np.testing.assert_array_equal(again.step(x, u, 0.5)[0], plant.step(x, u, 0.5)[0])


def test_pickled_plant_steps_identically(plant):
    clone = pickle.loads(pickle.dumps(plant))
    x = initial_state(0.0, 0.0, 1.0, 30.0)
    u = np.array([-0.03, 0.0, 12000.0])
    for a, b in zip(clone.step(x, u, 0.4), plant.step(x, u, 0.4)):
        np.testing.assert_array_equal(a, b)


def test_concurrent_builds_of_one_source_are_atomic(tmp_path):
    source = "double twice(double v) { return 2.0 * v; }\n"
    compiler = find_compiler()
    paths, errors = [], []

    def build():
        try:
            paths.append(build_library(source, tmp_path, compiler))
        except (OSError, RuntimeError) as err:  # reported by the assertion below
            errors.append(err)

    threads = [threading.Thread(target=build) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(set(paths)) == 1
    assert [p.name for p in tmp_path.iterdir()] == [paths[0].name]
    other = build_library(source.replace("2.0", "3.0"), tmp_path, compiler)
    assert other != paths[0]


def test_broken_compiler_falls_back_to_the_virtual_machine(params, tmp_path, monkeypatch):
    monkeypatch.setenv("CC", "false")  # exists, always fails
    with pytest.warns(RuntimeWarning, match="compilation failed"):
        broken = Plant(params, cache_dir=tmp_path)
    assert broken.backend == "casadi-vm"
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setenv("CC", "no-such-compiler-eoam")
    with pytest.warns(RuntimeWarning, match="no C compiler"):
        assert Plant(params, cache_dir=tmp_path).backend == "casadi-vm"


@pytest.mark.parametrize(
    "kwargs",
    [{"dt_s": 0.0}, {"dt_s": 0.02}, {"dt_s": float("nan")}, {"substeps": 0}, {"substeps": 2.0}],
)
def test_bad_step_settings_are_rejected(params, kwargs):
    with pytest.raises(ValueError):
        ReferencePlant(params, **kwargs)
    with pytest.raises(ValueError):
        Plant(params, use_compiler=False, **kwargs)


def test_bad_step_inputs_are_rejected(plant, params):
    x = initial_state(0.0, 0.0, 0.0, 10.0)
    for mu in (0.0, -0.5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="mu"):
            plant.step(x, np.zeros(3), mu)
        with pytest.raises(ValueError, match="mu"):
            ReferencePlant(params).step(x, np.zeros(3), mu)
    with pytest.raises(ValueError):
        plant.step(x[:5], np.zeros(3), 0.5)
    with pytest.raises(ValueError):
        ReferencePlant(params).step(x, np.zeros(2), 0.5)
    with pytest.raises(ValueError, match="speed_mps"):
        initial_state(0.0, 0.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="steer_lag_s"):
        ReferencePlant(params.__class__(steer_lag_s=0.0))


finite = st.floats(-1e4, 1e4, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(
    x=st.lists(finite, min_size=len(STATE_NAMES), max_size=len(STATE_NAMES)),
    u=st.tuples(finite, finite, finite),
    mu=st.floats(0.01, 1.5),
)
def test_the_extension_module_steps_as_the_ctypes_call_does(plant, x, u, mu):
    """Where Python's headers are installed, ``advance`` is the extension module's: the same
    C step, so the same numbers to the last bit as through ctypes, NaNs in the same places."""
    assert python_include() is not None  # this machine has them: the extension is used
    assert type(plant.advance).__name__ == "builtin_function_or_method"
    through_ctypes = Plant.advance.__get__(plant)
    got, want = plant.advance(x, u, mu), through_ctypes(x, u, mu)
    assert np.array_equal(got[0], want[0], equal_nan=True)
    assert np.array_equal(got[1], want[1], equal_nan=True)
    assert all(type(v) is float for v in got[0] + got[1])


def test_without_python_headers_the_plant_steps_through_ctypes(
    params, plant_cache_dir, monkeypatch
):
    from eoam_sumo.plant import compiled

    monkeypatch.setattr(compiled, "python_include", lambda: None)
    plain = Plant(params, cache_dir=plant_cache_dir)
    assert plain.backend == "compiled-c" and "advance" not in vars(plain)
    x = initial_state(0.0, 0.0, 0.0, 20.0)
    assert plain.advance(x, (0.01, 0.0, 0.0), 0.8)[0][0] > 0.0
