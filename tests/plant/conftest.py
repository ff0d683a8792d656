"""Shared plant fixtures: ONE compiled plant per test session, built under a temporary dir."""

import pytest

from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.plant import Plant
from eoam_sumo.vehicle_files import load_vehicle


@pytest.fixture(scope="session")
def params():
    return ego_e_class_sedan()


@pytest.fixture(scope="session")
def r13h_params():
    """The sedan with its brake split and yaw inertia corrected (vehicles/sedan-r13h.toml)."""
    return load_vehicle("sedan-r13h")


@pytest.fixture(scope="session")
def r13h_plant(r13h_params, plant_cache_dir):
    return Plant(r13h_params, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir)


@pytest.fixture(scope="session")
def plant_cache_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("plant_cache")


@pytest.fixture(scope="session")
def plant(params, plant_cache_dir):
    compiled = Plant(params, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir)
    assert compiled.backend == "compiled-c"
    return compiled
