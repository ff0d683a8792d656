"""What a run changes in a scenario: :class:`ScenarioOverrides`."""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.params import MU_MAX
from eoam_sumo.sim.scenario.values import number


@dataclass(frozen=True)
class ScenarioOverrides:
    """Changes applied to a scenario's SUMO files at the start of a run; None keeps the files'.

    ``mu`` sets the friction of every lane; ``oncoming_start_m`` adds one oncoming car in the lane
    opposite the ego's, its front bumper that far ahead of the ego's front bumper along the road,
    at the constant ``oncoming_speed_mps``; ``aro_*`` replace the stop parameters of the vehicles
    tagged ``eoam.role=aro``.
    """

    ego_speed_mps: float | None = None
    mu: float | None = None
    oncoming_start_m: float | None = None
    oncoming_speed_mps: float = 20.0
    aro_hold_s: float | None = None
    aro_decel_mps2: float | None = None

    def __post_init__(self) -> None:
        if self.ego_speed_mps is not None:
            number("ego_speed_mps", self.ego_speed_mps, minimum=0.0)
        if self.mu is not None:
            number("mu", self.mu, minimum=0.0, inclusive=False, maximum=MU_MAX)
        if self.oncoming_start_m is not None:
            number("oncoming_start_m", self.oncoming_start_m, minimum=0.0)
        number("oncoming_speed_mps", self.oncoming_speed_mps, minimum=0.0)
        if self.aro_hold_s is not None:
            number("aro_hold_s", self.aro_hold_s, minimum=0.0)
        if self.aro_decel_mps2 is not None:
            number("aro_decel_mps2", self.aro_decel_mps2, minimum=0.0, inclusive=False)
