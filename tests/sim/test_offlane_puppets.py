"""A road user an OpenSCENARIO storyboard places off every lane (beyond the road's edge) stays
in the run: SUMO's context of the ego holds only the vehicles on its lanes, so the tracking
reads the storyboard's road users by id."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.cli import main
from tests.sim.test_insertion_lane import VEHICLE, XODR

pytestmark = pytest.mark.sumo

SPEED = (
    '<SpeedActionDynamics dynamicsShape="step" value="0" dynamicsDimension="time"/>'
    '<SpeedActionTarget><AbsoluteTargetSpeed value="{v}"/></SpeedActionTarget>'
)


def _private(name: str, lane: int, s_m: float, offset_m: float, speed_mps: float) -> str:
    return (
        f'<Private entityRef="{name}"><PrivateAction><TeleportAction><Position>'
        f'<LanePosition roadId="1" laneId="{lane}" s="{s_m}" offset="{offset_m}"/>'
        "</Position></TeleportAction></PrivateAction><PrivateAction><LongitudinalAction>"
        f"<SpeedAction>{SPEED.format(v=speed_mps)}</SpeedAction></LongitudinalAction>"
        "</PrivateAction></Private>"
    )


XOSC = f"""<?xml version="1.0" encoding="UTF-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="1" date="2026-01-01T00:00:00" description="t" author="t"/>
  <ParameterDeclarations/><CatalogLocations/>
  <RoadNetwork><LogicFile filepath="straight3.xodr"/></RoadNetwork>
  <Entities>
    <ScenarioObject name="Ego">{VEHICLE}</ScenarioObject>
    <ScenarioObject name="Off">{VEHICLE}</ScenarioObject>
  </Entities>
  <Storyboard>
    <Init><Actions>
      {_private("Ego", -2, 100.0, 0.0, 20.0)}
      {_private("Off", -3, 140.0, -5.0, 20.0)}
    </Actions></Init>
    <StopTrigger><ConditionGroup><Condition name="st" delay="0" conditionEdge="rising">
      <ByValueCondition><SimulationTimeCondition value="3" rule="greaterThan"/>
      </ByValueCondition></Condition></ConditionGroup></StopTrigger>
  </Storyboard>
</OpenSCENARIO>
"""


def test_a_road_user_placed_beyond_the_road_edge_is_logged_every_step(tmp_path):
    """'Off' drives 5 m right of the outer lane's centre (3.25 m beyond the road's edge), 40 m
    ahead of the ego at its speed: it is in traffic.csv at every step of the ego's, at its
    place (it was there in one row only: in SUMO's context of the ego are only the vehicles on
    its lanes)."""
    (tmp_path / "straight3.xodr").write_text(XODR)
    (tmp_path / "s.xosc").write_text(XOSC)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "s.xosc"), "--out", str(out)]) == 0
    traffic = pd.read_csv(out / "traffic.csv")
    ego = traffic[traffic["id"] == "ego"].set_index("time_s")
    off = traffic[traffic["id"] == "Off"].set_index("time_s")
    assert set(ego.index) <= set(off.index)
    # it departs on its lane's centre, and is at its place from the first step on
    lateral = (off["y_m"] - ego["y_m"]).dropna().iloc[1:]
    assert lateral.to_numpy() == pytest.approx(-(3.5 + 5.0), abs=0.05)
