"""Tiny hand-made .xosc cases for the review's tests: one straight road, an ego and a target,
one story whose target brakes at 2 s; each test replaces pieces of it."""

from __future__ import annotations

from pathlib import Path

VEHICLE = (
    '<Vehicle name="car" vehicleCategory="car"><BoundingBox><Center x="1.4" y="0" z="0.75"/>'
    '<Dimensions width="1.9" length="4.8" height="1.5"/></BoundingBox>'
    '<Performance maxSpeed="70" maxAcceleration="5" maxDeceleration="10"/><Axles>'
    '<FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.8" '
    'positionZ="0.3"/><RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6" '
    'positionX="0" positionZ="0.3"/></Axles><Properties/></Vehicle>'
)
STEP = '<SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>'
BRAKE = (
    "<PrivateAction><LongitudinalAction><SpeedAction><SpeedActionDynamics "
    'dynamicsShape="linear" dynamicsDimension="rate" value="5"/><SpeedActionTarget>'
    '<AbsoluteTargetSpeed value="0"/></SpeedActionTarget></SpeedAction></LongitudinalAction>'
    "</PrivateAction>"
)
AT_2S = (
    '<Condition name="C1" delay="0" conditionEdge="none"><ByValueCondition>'
    '<SimulationTimeCondition value="2" rule="greaterThan"/></ByValueCondition></Condition>'
)
TARGET_INIT_SPEED = (
    f"<PrivateAction><LongitudinalAction><SpeedAction>{STEP}<SpeedActionTarget>"
    '<AbsoluteTargetSpeed value="$TargetSpeed"/></SpeedActionTarget></SpeedAction>'
    "</LongitudinalAction></PrivateAction>"
)
GROUP = (
    '<ManeuverGroup maximumExecutionCount="1" name="MG"><Actors selectTriggeringEntities='
    '"false"><EntityRef entityRef="Target"/></Actors><Maneuver name="M"><Event name="E" '
    f'priority="override"><Action name="Act1">{BRAKE}</Action><StartTrigger><ConditionGroup>'
    f"{AT_2S}</ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>"
)
EGO_PLACE = (
    '<PrivateAction><TeleportAction><Position><LanePosition roadId="1" laneId="-1" offset="0" '
    's="50"/></Position></TeleportAction></PrivateAction>'
)
TARGET_PLACE = EGO_PLACE.replace('s="50"', 's="$TargetS"')
EGO_SPEED = (
    f"<PrivateAction><LongitudinalAction><SpeedAction>{STEP}<SpeedActionTarget>"
    '<AbsoluteTargetSpeed value="$EgoSpeed"/></SpeedActionTarget></SpeedAction>'
    "</LongitudinalAction></PrivateAction>"
)


def _time_trigger(tag: str, name: str, value: str, rule: str) -> str:
    return (
        f'<{tag}><ConditionGroup><Condition name="{name}" delay="0" conditionEdge="none">'
        f'<ByValueCondition><SimulationTimeCondition value="{value}" rule="{rule}"/>'
        f"</ByValueCondition></Condition></ConditionGroup></{tag}>"
    )


ACT_START = _time_trigger("StartTrigger", "C0", "0", "greaterOrEqual")
STOP = _time_trigger("StopTrigger", "Stop", "12", "greaterThan")
BASE = f"""<?xml version="1.0" encoding="UTF-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2024-01-01T00:00:00" description="t" author="t"/>
  <ParameterDeclarations>
    <ParameterDeclaration name="EgoSpeed" parameterType="double" value="20"/>
    <ParameterDeclaration name="TargetS" parameterType="double" value="150"/>
    <ParameterDeclaration name="TargetSpeed" parameterType="double" value="10"/>
  </ParameterDeclarations>
  <CatalogLocations/>
  <RoadNetwork><LogicFile filepath="road.xodr"/></RoadNetwork>
  <Entities>
    <ScenarioObject name="Ego">{VEHICLE}</ScenarioObject>
    <ScenarioObject name="Target">{VEHICLE}</ScenarioObject>
  </Entities>
  <Storyboard>
    <Init><Actions>
      <Private entityRef="Ego">
        {EGO_PLACE}
        {EGO_SPEED}
      </Private>
      <Private entityRef="Target">
        {TARGET_PLACE}
        {TARGET_INIT_SPEED}
      </Private>
    </Actions></Init>
    <Story name="S">
      <Act name="A">
        {GROUP}
        {ACT_START}
      </Act>
    </Story>
    {STOP}
  </Storyboard>
</OpenSCENARIO>
"""


def lane(lane_id: int, width_m: float = 3.5, kind: str = "driving") -> str:
    return (
        f'<lane id="{lane_id}" type="{kind}" level="false"><link/>'
        f'<width sOffset="0" a="{width_m}" b="0" c="0" d="0"/></lane>'
    )


def road(left: str = "", right: str = "", rule: str = "", length_m: float = 500.0) -> str:
    """A straight OpenDRIVE road ``1`` (default: one 3.5 m lane each way)."""
    left = left or lane(1)
    right = right or lane(-1)
    attr = f' rule="{rule}"' if rule else ""
    return f"""<?xml version="1.0" standalone="yes"?>
<OpenDRIVE><header revMajor="1" revMinor="4" name="t"/>
<road name="" length="{length_m}" id="1" junction="-1"{attr}><link/>
<planView><geometry s="0" x="0" y="0" hdg="0" length="{length_m}"><line/></geometry></planView>
<lanes><laneSection s="0"><left>{left}</left>
<center><lane id="0" type="none" level="false"><link/></lane></center>
<right>{right}</right></laneSection></lanes></road></OpenDRIVE>
"""


def write_case(folder: Path, *edits: tuple[str, str], xodr: str | None = None) -> Path:
    """``BASE`` with each (old, new) replaced (each old must occur), beside its road."""
    text = BASE
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new)
    (folder / "road.xodr").write_text(xodr or road(), encoding="utf-8")
    path = folder / "case.xosc"
    path.write_text(text, encoding="utf-8")
    return path
