"""Suite-wide fixtures: keep every file the tests make under pytest's temporary folders."""

from __future__ import annotations

import os

import pytest


@pytest.fixture(scope="session", autouse=True)
def _plant_cache_in_tmp(tmp_path_factory):
    """The compiled plant library goes to a temporary cache (inherited by subprocesses)."""
    old = os.environ.get("EOAM_SUMO_CACHE_DIR")
    os.environ["EOAM_SUMO_CACHE_DIR"] = str(tmp_path_factory.mktemp("plant-cache"))
    yield
    if old is None:
        os.environ.pop("EOAM_SUMO_CACHE_DIR", None)
    else:
        os.environ["EOAM_SUMO_CACHE_DIR"] = old
