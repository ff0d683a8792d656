"""The ego starts in the lane its scenario names, on a road converted from OpenDRIVE where
SUMO maps a hinted lane index onto another lane (lanes 1 and 2 of a three-lane carriageway
running against the road's s swapped by ``moveToXY(..., laneIndex, keepRoute=1)``)."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.cli import main

pytestmark = pytest.mark.sumo

LANES = "".join(
    f'<lane id="{i}" type="driving" level="false"><link/>'
    '<width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>'
    for i in (3, 2, 1, -1, -2, -3)  # in descending order of id (OpenDRIVE 1.6 sec. 9.3)
)
XODR = f"""<?xml version="1.0" standalone="yes"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="4" name="straight3" version="1.0"/>
  <road name="r" length="1000" id="1" junction="-1">
    <link/><type s="0" type="motorway"/>
    <planView><geometry s="0" x="0" y="0" hdg="0" length="1000"><line/></geometry></planView>
    <lanes><laneSection s="0">
      <left>{LANES.split('<lane id="-1"')[0]}</left>
      <center><lane id="0" type="none" level="false"><link/></lane></center>
      <right><lane id="-1"{LANES.split('<lane id="-1"')[1]}</right>
    </laneSection></lanes>
  </road>
</OpenDRIVE>
"""
VEHICLE = (
    '<Vehicle name="car" vehicleCategory="car"><BoundingBox><Center x="1.5" y="0" z="0.75"/>'
    '<Dimensions width="1.8" length="4.5" height="1.5"/></BoundingBox>'
    '<Performance maxSpeed="70" maxAcceleration="10" maxDeceleration="10"/><Axles>'
    '<FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.8" positionX="3.1" '
    'positionZ="0.3"/><RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.8" '
    'positionX="0" positionZ="0.3"/></Axles><Properties/></Vehicle>'
)


def _xosc(lane: int) -> str:
    speed = (
        '<SpeedActionDynamics dynamicsShape="step" value="0" dynamicsDimension="time"/>'
        '<SpeedActionTarget><AbsoluteTargetSpeed value="20"/></SpeedActionTarget>'
    )
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="1" date="2026-01-01T00:00:00" description="t" author="t"/>
  <ParameterDeclarations/><CatalogLocations/>
  <RoadNetwork><LogicFile filepath="straight3.xodr"/></RoadNetwork>
  <Entities><ScenarioObject name="Ego">{VEHICLE}</ScenarioObject></Entities>
  <Storyboard>
    <Init><Actions><Private entityRef="Ego">
      <PrivateAction><TeleportAction><Position>
        <LanePosition roadId="1" laneId="{lane}" s="500" offset="0"/>
      </Position></TeleportAction></PrivateAction>
      <PrivateAction><LongitudinalAction><SpeedAction>{speed}</SpeedAction>
      </LongitudinalAction></PrivateAction>
    </Private></Actions></Init>
    <StopTrigger><ConditionGroup><Condition name="st" delay="0" conditionEdge="rising">
      <ByValueCondition><SimulationTimeCondition value="1" rule="greaterThan"/>
      </ByValueCondition></Condition></ConditionGroup></StopTrigger>
  </Storyboard>
</OpenSCENARIO>
"""


@pytest.mark.parametrize("lane", [1, 2, 3, -1, -2])
def test_the_ego_starts_on_its_lane_centre(tmp_path, lane):
    """The plant's first pose lies on the centre of the lane the scenario names: OpenDRIVE
    lane k's centre is 3.5 (|k| - 1/2) m left (k > 0) or right of the road's reference line
    (SUMO's frame shifts y by the net's offset; the lateral offset from the lane is 0)."""
    (tmp_path / "straight3.xodr").write_text(XODR)
    (tmp_path / "s.xosc").write_text(_xosc(lane))
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "s.xosc"), "--out", str(out), "--max-time-s", "1"]) == 0
    first = pd.read_csv(out / "timeseries.csv").iloc[0]
    assert first["lateral_offset_m"] == pytest.approx(0.0, abs=1e-6)
    assert first["y_m"] == pytest.approx(pd.read_csv(out / "road.csv")["y_m"].iloc[0], abs=1e-6)


@pytest.mark.parametrize("step_s", ["0.07", "0.08"])
def test_a_sumo_step_that_does_not_divide_the_departure_is_refused(tmp_path, capsys, step_s):
    """SUMO inserts a vehicle one of its steps after the step its departure falls in: at
    0.07 s from a departure at 1 s the run's clock started before the ego's departure and the
    obstacle ran 1.5 m behind the 10 ms reference. Such a step is refused in one line naming
    the vehicle; one that divides the departure runs."""
    from tests.builders import BASELINE

    argv = ["run", str(BASELINE), "--max-time-s", "1", "--sumo-step-s", step_s]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "vehicle 'ego' departs at 1 s" in err
    assert not (tmp_path / "a").exists()
    assert main([*argv[:-1], "0.05", "--out", str(tmp_path / "b")]) == 0
