"""Plain-Python reference plant: the same model and integrator, evaluated with Python floats.

Slow (pure Python) but independent of CasADi's code generation and of the C compiler; the
tests hold the compiled ``Plant`` to it.
"""

from __future__ import annotations

import numpy as np

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.integrator import advance
from eoam_sumo.plant.model import INPUT_NAMES, STATE_NAMES
from eoam_sumo.plant.ops import FLOAT_OPS
from eoam_sumo.plant.stepping import check_mu, stable_substeps, validate_step


class ReferencePlant:
    """Same interface as ``Plant``: ``step(x, u, mu) -> (x_next, y)`` over ``substeps * dt_s``."""

    def __init__(self, params: VehicleParams, dt_s: float = 1e-3, substeps: int = 10):
        validate_step(params, dt_s, substeps)
        self.params = params
        self.dt_s, self.substeps = stable_substeps(params, float(dt_s), substeps)

    @property
    def step_s(self) -> float:
        """Time advanced by one ``step`` call [s]."""
        return self.dt_s * self.substeps

    def step(self, x, u, mu: float) -> tuple[np.ndarray, np.ndarray]:
        xs = [float(v) for v in x]
        us = [float(v) for v in u]
        if len(xs) != len(STATE_NAMES) or len(us) != len(INPUT_NAMES):
            raise ValueError(
                f"x needs {len(STATE_NAMES)} and u {len(INPUT_NAMES)} values, "
                f"got {len(xs)} and {len(us)}"
            )
        x_next, y = advance(xs, us, check_mu(mu), self.params, self.dt_s, self.substeps, FLOAT_OPS)
        return np.array(x_next, dtype=float), np.array(y, dtype=float)
