"""What the sensors know of the next lane: a per-step message from sensing
(``sensing.next_lane``) to the decision policy (``decision.policy``), carried in
``Perception.next_lane``."""

from __future__ import annotations

from collections.abc import Callable


class NextLaneView:
    """What the sensors know of the lane left of the ego's original lane (road frame of that
    lane; distances along the road from the ego's front bumper, or from its rear behind it).

    The covered length is worked out only when read (``coverage`` a function returning it):
    the policy needs it at a commit, and its geometry is the costly part."""

    __slots__ = (
        "_coverage",
        "_coverage_m",
        "nearest_ahead_m",
        "nearest_ahead_speed_mps",
        "nearest_behind_m",
        "nearest_behind_speed_mps",
        "opposing",
        "speed_limit_mps",
    )

    def __init__(
        self,
        opposing: bool,
        speed_limit_mps: float,
        *,
        coverage_ahead_m: float | None = None,
        coverage: Callable[[], float] | None = None,
        nearest_ahead_m: float | None = None,
        nearest_ahead_speed_mps: float | None = None,
        nearest_behind_m: float | None = None,
        nearest_behind_speed_mps: float | None = None,
    ):
        self.opposing = opposing  # the lane carries opposing traffic
        self.speed_limit_mps = speed_limit_mps  # its speed limit (net file)
        self._coverage_m = coverage_ahead_m
        self._coverage = coverage
        self.nearest_ahead_m = nearest_ahead_m  # gap to the nearest road user in it ahead
        self.nearest_ahead_speed_mps = nearest_ahead_speed_mps  # its road speed (< 0: towards)
        self.nearest_behind_m = nearest_behind_m  # gap to the nearest road user in it behind
        self.nearest_behind_speed_mps = nearest_behind_speed_mps

    @property
    def coverage_ahead_m(self) -> float:
        """Length ahead covered by the sensors without a gap."""
        if self._coverage_m is None:
            self._coverage_m = self._coverage() if self._coverage is not None else 0.0
        return self._coverage_m

    @property
    def known_free_ahead_m(self) -> float:
        """Covered and empty: the covered length or the gap to the nearest road user ahead."""
        cover = self.coverage_ahead_m
        return cover if self.nearest_ahead_m is None else min(cover, self.nearest_ahead_m)
