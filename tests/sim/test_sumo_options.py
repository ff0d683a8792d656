"""SUMO's options under the co-simulation: what it sets over the sumocfg (named in
``sumo_overrides``), what it leaves to the user, the collision output it writes from its own
contacts, and how SUMO's output times line up with the session's."""

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.collisions import CollisionRecord, write_collision_output
from eoam_sumo.sim.session.launch import (
    ENFORCED_OPTIONS,
    ERROR_LOG_STDERR,
    start_error,
    sumo_command,
)
from eoam_sumo.world.bodies import Body
from tests.builders import on_highway

ROUTES = """<routes><route id="east" edges="E0"/>
  <vehicle id="ego" type="ego" route="east" depart="0" departPos="100" departSpeed="20"/>
  <vehicle id="halted" type="aro" route="east" depart="0" departPos="160" departSpeed="0">
    <stop lane="E0_0" endPos="160" duration="1000"/></vehicle>
</routes>"""


def _command(cfg_options: dict, extra=(), gui=False, keep=False):
    return sumo_command(
        "sumo",
        Path("s.sumocfg"),
        cfg_options,
        0.01,
        Path("err.log"),
        tuple(extra),
        gui,
        keep_gui_open=keep,
    )


def _with_options(cfg: Path, xml: str) -> Path:
    """The sumocfg with these option sections added."""
    cfg.write_text(cfg.read_text().replace("</configuration>", xml + "</configuration>"))
    return cfg


# --------------------------------------------------------------------------- SUMO's errors
WARNING = (
    "Warning: State was written at a different time=120.00 than the begin time 0 (set "
    "option load-state.offset to force a different begin)!"
)
TOO_HIGH = (
    "Departure speed for vehicle 'lead' is too high for the departure edge 'E0', time=120.00."
)


def _refusal(tmp_path: Path, error_log: str, stderr_log: str, exc_text: str) -> str:
    log = tmp_path / "sumo-errors.log"
    log.write_text(error_log)
    (tmp_path / ERROR_LOG_STDERR).write_text(stderr_log)
    return start_error(Path("s.sumocfg"), log, RuntimeError(exc_text))


def test_a_refusal_quotes_sumos_error_and_never_a_warning(tmp_path):
    prefix = "s.sumocfg: SUMO could not load the scenario: "
    # only a warning logged (the handover's): the error is the exception's
    assert _refusal(tmp_path, WARNING + "\n", WARNING + "\n", TOO_HIGH) == prefix + TOO_HIGH
    # the error logged after the warning (TraCI: the exception says only that SUMO quit)
    logged = f"{WARNING}\nError: {TOO_HIGH}\nQuitting (on error).\n"
    assert _refusal(tmp_path, logged, "", "connection closed by SUMO") == prefix + TOO_HIGH
    # a message over two lines stays whole, once though both logs hold it
    two_lines = "Error: No connection between edge 'a'\n and edge 'c' found.\n"
    assert (
        _refusal(tmp_path, two_lines, two_lines, "x")
        == prefix + "No connection between edge 'a' and edge 'c' found."
    )
    assert _refusal(tmp_path, "", "", "") == prefix + "RuntimeError"


# --------------------------------------------------------------------------- the command line
def test_options_the_sumocfg_sets_otherwise_are_named_as_overrides():
    cmd, over = _command(
        {
            "collision.action": "warn",
            "step-length": "0.1",
            "time-to-teleport": "-1",
            "no-step-log": "1",
        }
    )
    assert over == {
        "step-length": "0.010",
        "step-method.ballistic": "true",
        "collision.action": "none",
        "no-warnings": "true",
        "route-steps": "0",
    }
    # same meaning, other spelling: not an override (numbers by value, SUMO's booleans)
    assert cmd[cmd.index("--time-to-teleport") + 1] == "-1"
    _, over = _command(
        {
            "step-length": "0.010",
            "step-method.ballistic": "x",
            "collision.action": "none",
            "time-to-teleport": "-1.0",
            "no-warnings": "yes",
            "no-step-log": "on",
            "route-steps": "0",
        }
    )
    assert over == {}


def test_a_sumocfg_without_the_options_gets_every_one_named():
    cmd, over = _command({})
    assert over == {"step-length": "0.010", **dict(ENFORCED_OPTIONS)}
    for option, value in over.items():
        assert cmd[cmd.index(f"--{option}") + 1] == value


def test_warnings_the_sumocfg_turns_on_stay_on():
    cmd, over = _command({"no-warnings": "false"})
    assert "--no-warnings" not in cmd and "no-warnings" not in over


def test_extra_arguments_win_and_are_not_overrides():
    cmd, over = _command({}, extra=["--collision.action", "warn"])
    assert cmd.count("--collision.action") == 1 and cmd[-2:] == ["--collision.action", "warn"]
    assert "collision.action" not in over


def test_gui_starts_at_once_and_quits_only_when_not_kept_open():
    cmd, over = _command({}, gui=True, keep=True)
    assert over["start"] == "true" and "--quit-on-end" not in cmd
    assert over["window-size"] == "1280,800"
    cmd, over = _command({"window-size": "800,600"}, gui=True)
    assert over["quit-on-end"] == "true" and "--window-size" not in cmd


def test_the_users_error_log_is_kept():
    cmd, _ = _command({"error-log": "mine.log"})
    assert "--error-log" not in cmd


# --------------------------------------------------------------------------- real SUMO runs
@pytest.mark.sumo
def test_sumo_runs_with_the_overrides_the_session_names(tmp_path):
    import libsumo

    cfg = _with_options(
        on_highway(tmp_path, ROUTES),
        '<processing><collision.action value="warn"/></processing>'
        '<report><no-warnings value="false"/></report>',
    )
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        assert s.sumo_overrides["collision.action"] == "none"
        assert "no-warnings" not in s.sumo_overrides
        for option, value in s.sumo_overrides.items():  # what SUMO itself reports
            got = libsumo.simulation.getOption(option)
            assert got == value or float(got) == float(value)
        assert libsumo.simulation.getOption("no-warnings") == "false"


@pytest.mark.sumo
def test_fcd_output_is_labelled_one_step_before_the_session_time(tmp_path):
    """SUMO labels a step's outputs with its start: the ego the session has at t is in
    fcd-output at t - 0.01 s."""
    cfg = _with_options(
        on_highway(tmp_path, ROUTES), '<output><fcd-output value="fcd.xml"/></output>'
    )
    seen = {}
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        for k in range(5):
            x = 100.0 + 0.3 * (k + 1)
            s.move_ego(x, -1.75, 90.0, 30.0)
            s.step()
            seen[round(s.time_s, 2)] = x
    fcd = {
        round(float(step.get("time")), 2): float(v.get("x"))
        for step in ET.parse(tmp_path / "fcd.xml").getroot().iter("timestep")
        for v in step.iter("vehicle")
        if v.get("id") == "ego"
    }
    for t, x in seen.items():
        assert fcd[round(t - 0.01, 2)] == pytest.approx(x, abs=0.006)  # fcd: 2 decimals


@pytest.mark.sumo
def test_recorded_contacts_go_to_the_sumocfg_collision_output(tmp_path):
    cfg = _with_options(
        on_highway(tmp_path, ROUTES), '<output><collision-output value="out/coll.xml"/></output>'
    )
    (tmp_path / "out").mkdir()
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        assert s.collision_output == tmp_path / "out" / "coll.xml"
        s.step()
        ego, halted = s.ego_body(), s.body("halted")
        s.record_collision(s.time_s, ego, halted)
        t = s.time_s
    root = ET.parse(tmp_path / "out" / "coll.xml").getroot()
    assert root.tag == "collisions"
    (rec,) = root.findall("collision")
    assert rec.get("collider") == "ego" and rec.get("victim") == "halted"
    assert rec.get("colliderType") == "ego" and rec.get("victimType") == "aro"
    assert float(rec.get("time")) == pytest.approx(t - 0.01)
    assert rec.get("lane") == "E0_0" and float(rec.get("colliderSpeed")) == pytest.approx(
        ego.speed_mps, abs=0.005
    )
    back = [float(v) for v in rec.get("victimBack").split(",")]
    assert back == pytest.approx([halted.x_m - 0.5 * halted.length_m, halted.y_m], abs=0.006)


@pytest.mark.sumo
def test_no_collision_output_asked_for_none_written(tmp_path):
    cfg = on_highway(tmp_path, ROUTES)
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        assert s.collision_output is None
        s.record_collision(s.time_s, s.ego_body(), s.body("halted"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.rou.xml", "v.sumocfg"]


def test_sumos_own_records_are_kept_in_time_order(tmp_path):
    path = tmp_path / "c.xml"
    path.write_text(
        '<?xml version="1.0"?><!-- by SUMO --><collisions>'
        '<collision time="3.00" type="collision" lane="a_0" collider="x" '
        'victim="y" colliderType="t" victimType="t" colliderSpeed="1" '
        'victimSpeed="0"/></collisions>'
    )
    a = Body("ego", "passenger", 10.0, 0.0, 0.0, 20.0, 4.0, 2.0)
    b = Body("p", "pedestrian", 12.0, 0.5, 1.0, 1.0, 0.3, 0.5)
    write_collision_output(path, [CollisionRecord(2.5, "E0_0", 12.0, a, b, "ego", "walker")])
    recs = ET.parse(path).getroot().findall("collision")
    assert [r.get("time") for r in recs] == ["2.50", "3.00"]
    assert (
        recs[0].get("colliderFront") == "12.00,0.00" and recs[0].get("colliderBack") == "8.00,0.00"
    )
    write_collision_output(tmp_path / "new.xml", [])  # missing file: written anew, empty
    assert ET.parse(tmp_path / "new.xml").getroot().tag == "collisions"


@pytest.mark.parametrize(
    "args,message",
    [
        (["--gui-screenshot", "5"], "need --gui"),
        (["--gui-delay-ms", "20"], "need --gui"),
        (["--gui", "--gui-screenshot", "5,x"], "not a list of seconds"),
        (["--gui", "--gui-screenshot", "-1"], "must be numbers >= 0"),
    ],
)
def test_gui_options_are_checked_before_sumo_starts(tmp_path, capsys, args, message):
    from eoam_sumo.cli import EXIT_BAD_INPUT, main

    cfg = on_highway(tmp_path, ROUTES)
    assert main(["run", str(cfg), "--out", str(tmp_path / "o"), *args]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
