"""What the five tests share: their options, result, pass/fail criteria and the driver's
speed keeping."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from eoam_sumo.params import MU_MAX, VehicleParams
from eoam_sumo.plant import cruise_drive_force_n
from eoam_sumo.vehicle_tests.clauses import TEST_MU_MIN, TEST_SPEED_RANGE_KMH
from eoam_sumo.vehicle_tests.harness import PlantVehicle, Run, Sample, Vehicle

SPEED_GAIN_PER_S = 1.0
"""Speed keeping: drive force per speed error, as an acceleration per m/s [1/s]."""

SETTLE_S = 1.0
"""Straight running before a test's input begins [s]."""


@dataclass(frozen=True)
class VehicleTestOptions:
    """A test's options: the speed (None: the standard's), the road's friction."""

    speed_kmh: float | None = None
    mu: float = 1.0

    def __post_init__(self) -> None:
        low, high = TEST_SPEED_RANGE_KMH
        if self.speed_kmh is not None and not low <= self.speed_kmh <= high:
            raise ValueError(f"speed_kmh={self.speed_kmh!r} must be in [{low:g}, {high:g}] km/h")
        if not TEST_MU_MIN <= self.mu <= MU_MAX:
            raise ValueError(f"mu={self.mu!r} must be in [{TEST_MU_MIN:g}, {MU_MAX:g}]")

    def speed_mps(self, standard_kmh: float) -> float:
        return (standard_kmh if self.speed_kmh is None else self.speed_kmh) / 3.6


@dataclass(frozen=True)
class VehicleTestResult:
    """A test's runs (one time series each) and its summary (figures, criteria, clauses)."""

    test: str
    runs: tuple[Run, ...]
    summary: dict[str, Any] = field(default_factory=dict)


def criterion(
    name: str, value: float | None, limit: float, at_most: bool, clause: str
) -> dict[str, Any]:
    """One pass/fail line of a summary: ``value`` against ``limit`` (at most or at least)."""
    passed = None if value is None else (value <= limit if at_most else value >= limit)
    return {
        "name": name,
        "value": value,
        "limit": limit,
        "comparison": "<=" if at_most else ">=",
        "clause": clause,
        "passed": passed,
    }


def overall(criteria: list[dict[str, Any]]) -> bool | None:
    """All criteria passed (None when none could be judged)."""
    judged = [c["passed"] for c in criteria if c["passed"] is not None]
    return all(judged) if judged else None


def verdict(summary: Mapping[str, Any]) -> str:
    """``PASS``, ``FAIL``, ``NOT MEASURED`` (what the test is for could not be measured: the
    summary's ``not_measured`` says why) or ``figures only`` (the standard sets no pass mark)."""
    passed = summary.get("passed")
    if passed is not None:
        return "PASS" if passed else "FAIL"
    return "NOT MEASURED" if summary.get("not_measured") else "figures only"


def verdict_text(summary: Mapping[str, Any]) -> str:
    """The verdict with its reasons: why nothing was measured, why a criterion failed, or why
    figures carry no verdict (the summary's ``note``)."""
    word = verdict(summary)
    if word == "NOT MEASURED":
        reasons = [summary["not_measured"]]
    elif word == "figures only" and summary.get("note"):
        reasons = [summary["note"]]
    else:
        criteria = summary.get("criteria", [])
        reasons = [c["reason"] for c in criteria if c.get("passed") is False and c.get("reason")]
    return f"{word}: {'; '.join(reasons)}" if reasons else word


def header(test: str, params: VehicleParams, options: VehicleTestOptions, speed_mps: float) -> dict:
    """The summary's first fields: what was tested, how."""
    return {
        "test": test,
        "vehicle": params.name,
        "abs": params.abs_fitted,
        "esc": params.esc_fitted,
        "speed_kmh": round(speed_mps * 3.6, 6),
        "mu": options.mu,
    }


def vehicle_for(params: VehicleParams, vehicle: Vehicle | None) -> Vehicle:
    """The vehicle to drive: the one given (an oracle), else our plant with ``params``."""
    return PlantVehicle(params) if vehicle is None else vehicle


def speed_keeper(params: VehicleParams, target_mps: float) -> Callable[[Sample], float]:
    """Drive force [N] that holds ``target_mps``: the cruise force plus a proportional term."""
    cruise_n = cruise_drive_force_n(params, target_mps)

    def drive_force_n(sample: Sample) -> float:
        demand_n = cruise_n + params.mass_kg * SPEED_GAIN_PER_S * (target_mps - sample.vx_mps)
        return float(np.clip(demand_n, 0.0, params.max_drive_force_n))

    return drive_force_n


def rounded(value: float | None, digits: int = 4) -> float | None:
    return None if value is None else round(float(value), digits)
