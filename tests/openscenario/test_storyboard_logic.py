"""The storyboard engine's pieces against their definitions (no SUMO): a condition's edge and
delay (OpenSCENARIO 1.2 sec. 7.4.1), the dynamics shapes, the gaps between entities."""

from __future__ import annotations

import itertools
import math
import tempfile
from pathlib import Path
from types import SimpleNamespace

import pytest

from eoam_sumo.openscenario.actors import Actor, lane_plus, longitudinal_gap_m
from eoam_sumo.openscenario.model import Body
from eoam_sumo.openscenario.motions import LateralMotion, shape_fraction
from eoam_sumo.openscenario.story import Condition
from eoam_sumo.openscenario.xmltree import Node, parse


def _time_condition(edge: str, delay: float, value: float) -> Condition:
    inner = Node(
        "SimulationTimeCondition", {"value": str(value), "rule": "greaterThan"}, Path("-"), 1
    )
    by_value = Node("ByValueCondition", {}, Path("-"), 1, [inner])
    attrib = {"name": "c", "conditionEdge": edge, "delay": str(delay)}
    return Condition(Node("Condition", attrib, Path("-"), 1, [by_value]))


def _run(cond: Condition, until_s: float) -> list[float]:
    world = SimpleNamespace(time_s=0.0)
    fired = []
    for k in range(round(until_s / 0.1) + 1):
        world.time_s = round(k * 0.1, 10)
        if cond.value(world):
            fired.append(world.time_s)
    return fired


def test_a_condition_without_edge_holds_while_true_and_its_delay_shifts_it() -> None:
    assert _run(_time_condition("none", 0.0, 1.0), 1.5) == [1.1, 1.2, 1.3, 1.4, 1.5]
    assert _run(_time_condition("none", 0.3, 1.0), 1.5) == [1.4, 1.5]


def test_a_rising_edge_fires_once_and_not_when_true_from_the_first_step() -> None:
    assert _run(_time_condition("rising", 0.0, 1.0), 2.0) == [1.1]
    assert _run(_time_condition("rising", 0.5, 1.0), 2.0) == [1.6]
    assert _run(_time_condition("rising", 0.0, -1.0), 2.0) == []  # never false before


def test_shapes_go_from_zero_to_one_with_their_peak_slopes() -> None:
    for shape in ("linear", "cubic", "sinusoidal"):
        assert (shape_fraction(shape, 0.0), shape_fraction(shape, 1.0)) == (0.0, 1.0)
        assert shape_fraction(shape, 0.5) == pytest.approx(0.5)
    h = 1e-6  # the peak slopes the rate dimension divides by (motions.PEAK_SLOPE)
    assert (shape_fraction("sinusoidal", 0.5 + h) - shape_fraction("sinusoidal", 0.5)) / h == (
        pytest.approx(math.pi / 2, rel=1e-4)
    )
    assert (shape_fraction("cubic", 0.5 + h) - shape_fraction("cubic", 0.5)) / h == pytest.approx(
        1.5, rel=1e-4
    )
    assert shape_fraction("step", 0.0) == 1.0


def test_gaps_between_entities_reference_point_and_freespace() -> None:
    car = Body("c", 4.0, 1.8, 1.5, "car")  # front 3.5 m, rear 0.5 m behind the reference point
    me = Actor("me", car, "0", -1, 100.0, 0.0, 10.0)
    ahead = Actor("ahead", car, "0", -2, 130.0, 0.0, 5.0)
    assert longitudinal_gap_m(me, ahead, False) == 30.0
    assert longitudinal_gap_m(me, ahead, True) == pytest.approx(30.0 - 3.5 - 0.5)
    assert longitudinal_gap_m(ahead, me, True) == pytest.approx(-26.0)
    against = Actor("a", car, "0", 1, 100.0, 0.0, 10.0)  # a positive lane runs against s
    assert against.front_s_m() == 96.5


def test_lane_ids_skip_zero() -> None:
    assert (lane_plus(-1, 1), lane_plus(1, -1), lane_plus(-4, 1), lane_plus(-4, -1)) == (
        1,
        -1,
        -3,
        -5,
    )


class _Lanes:
    """Two straight lanes 3.5 m apart (lane -1 left of lane -2), any friction 1."""

    def shift_m(self, road: str, lane_from: int, lane_to: int, s_m: float) -> float:
        return 3.5 * (lane_to - lane_from)

    def has(self, road: str, lane: int) -> bool:
        return lane in (-1, -2)


def _xml(text: str) -> Node:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "a.xml"
        path.write_text(text, encoding="utf-8")
        return parse(path)


def _step_through(motion, actor: Actor, world, until_s: float) -> list[tuple[float, float]]:
    motion.start(world, actor)
    out, done = [], False
    while not done and world.time_s < until_s:
        done = motion.step(world, actor, 0.01)
        actor.advance(actor.speed_mps, 0.01)
        world.time_s = round(world.time_s + 0.01, 10)
        out.append((world.time_s, actor.offset_m))
    return out


def test_a_sinusoidal_lane_change_by_rate_peaks_at_that_lateral_speed() -> None:
    """OpenSCENARIO rate = the peak lateral speed: 3.5 m at 2 m/s peak takes pi 3.5 / 4 s."""
    node = _xml(
        '<LaneChangeAction><LaneChangeActionDynamics dynamicsShape="sinusoidal" value="2" '
        'dynamicsDimension="rate"/><LaneChangeTarget><AbsoluteTargetLane value="-1"/>'
        "</LaneChangeTarget></LaneChangeAction>"
    )
    actor = Actor("c", Body("c", 4.0, 1.8, 1.5, "car"), "0", -2, 0.0, 0.0, 10.0)
    world = SimpleNamespace(time_s=0.0, lanes=_Lanes(), actors={})
    path = _step_through(LateralMotion(node), actor, world, 10.0)
    assert path[-1][0] == pytest.approx(math.pi * 3.5 / 4, abs=0.011)
    assert (actor.lane, actor.offset_m) == (-1, 0.0)
    speeds = [(b[1] - a[1]) / 0.01 for a, b in itertools.pairwise(path[:-1])]  # then lane -1
    assert max(speeds) == pytest.approx(2.0, abs=0.01)


def test_a_lane_offset_respects_its_lateral_acceleration() -> None:
    """A cubic offset of 1 m at most 0.5 m/s^2: T = sqrt(6 x 1 / 0.5) = 3.46 s."""
    node = _xml(
        '<LaneOffsetAction continuous="false"><LaneOffsetActionDynamics maxLateralAcc="0.5" '
        'dynamicsShape="cubic"/><LaneOffsetTarget><AbsoluteTargetLaneOffset value="-1"/>'
        "</LaneOffsetTarget></LaneOffsetAction>"
    )
    actor = Actor("c", Body("c", 4.0, 1.8, 1.5, "car"), "0", -2, 0.0, 0.0, 10.0)
    world = SimpleNamespace(time_s=0.0, lanes=_Lanes(), actors={})
    path = _step_through(LateralMotion(node), actor, world, 10.0)
    assert path[-1][0] == pytest.approx(math.sqrt(12.0), abs=0.011)
    assert actor.offset_m == pytest.approx(-1.0) and actor.lane == -2
    ys = [y for _, y in path]
    acc = [(ys[k + 1] - 2 * ys[k] + ys[k - 1]) / 1e-4 for k in range(1, len(ys) - 1)]
    assert max(abs(a) for a in acc) <= 0.5 * 1.01
