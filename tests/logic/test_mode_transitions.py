"""Mode machine 0-5 (paper sec. 3.2, 8.1) driven by synthetic perception and ego measurements.

The controller runs with the real lookup tables; the sensor sequences are constructed by hand
(the commands are not applied to any vehicle), so every transition is provoked on purpose.
"""

import math

import pytest

from eoam_sumo.control import SteeringController, equivalent_mass_kg
from eoam_sumo.decision import Mode
from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, ObjectState, Perception
from eoam_sumo.eoam.shifts import lane_change_height_m
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import AIR_DENSITY_KGPM3, ego_e_class_sedan

P = ego_e_class_sedan()
DT = 0.01
LANE = 3.5
#: mode 2's travel in a 3.0 m lane without an obstacle track (the ego's lane taken as full):
#: its centre, or the clearing offset where that is farther (the yawed body's reach at mu 1)
HEIGHT_3M = lane_change_height_m(
    P, EoamSettings(), None, EgoMeasurement(0.0, 30.0, 0, 0, 0, 0, 0, 0, 0, 0, 1.0, 3.0)
)


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


class Drive:
    """Synthetic ego: straight road, kinematic progress at the given speed and lateral offset."""

    def __init__(self, tables, speed_mps, mu=1.0, lane_m=LANE, settings=None):
        self.ctrl = EoamController(P, tables, settings or EoamSettings())
        self.ctrl.reset(speed_mps)
        self.t, self.s, self.v, self.d, self.mu, self.lane = 0.0, 0.0, speed_mps, 0.0, mu, lane_m
        self.cmd = None

    def step(self, range_m=None, rate_mps=None, oncoming=False, d_m=None, e_yaw=0.0, n=1, obj=None):
        if d_m is not None:
            self.d = d_m
        for _ in range(n):
            meas = EgoMeasurement(
                self.t, self.v, 0.0, 0.0, 0.0, 0.0, self.s, self.d, e_yaw, 0.0, self.mu, self.lane
            )
            rate = -self.v if (range_m is not None and rate_mps is None) else rate_mps
            self.cmd = self.ctrl.step(meas, Perception(range_m, rate, oncoming, obj), DT)
            self.t += DT
            self.s += self.v * DT
        return self.cmd

    @property
    def mode(self):
        return self.ctrl.mode


def bounds(tables, mu, v):
    b = tables.boundaries.at(mu, v)
    return b.clear_opt_m, b.clear_buffered_m, b.stop_m, b.stop_buffered_m, b.ttc_s


def sector_spans(tables, mu, v) -> dict:
    """Sector -> (lowest, highest) distance of it at closing speed v (paper Figure 14)."""
    s, sb, b0, bb, ttc = bounds(tables, mu, v)
    return {
        "A": (0.0, min(s, b0)),
        "C": (b0, s),
        "F": (s, min(sb, bb)),
        "B": (max(s, bb), sb),
        "D": (sb, bb),
        "E": (max(sb, bb), ttc * v),
    }


def range_in(tables, mu, v, sector):
    """A distance in the given sector at closing speed v (asserts the sector is not empty)."""
    lo, hi = sector_spans(tables, mu, v)[sector]
    assert hi - lo > 0.2, f"sector {sector} empty at mu={mu}, v={v}: {lo}..{hi}"
    return 0.5 * (lo + hi)


def speed_with(tables, mu, *sectors, speeds=(45.0, 40.0, 33.3, 25.0, 20.0, 15.0, 10.0, 7.0)):
    """A closing speed at which all the given sectors are wide enough to aim at."""
    for v in speeds:
        widths = sector_spans(tables, mu, v)
        if all(widths[k][1] - widths[k][0] > 1.0 for k in sectors):
            return v
    pytest.fail(f"no speed with usable sectors {sectors} at mu={mu}")


def test_absent_or_parked_obstacle_never_triggers(tables):
    drive = Drive(tables, 33.3)
    drive.step(n=300)  # nothing in the path (parked cars are not in the path)
    drive.step(oncoming=True, n=300)  # oncoming traffic with nothing in the path
    assert drive.mode is Mode.NORMAL and drive.ctrl.modes_visited == [0]
    assert not drive.ctrl.fcw_raised and drive.cmd.sector == ""


def test_not_closing_or_far_obstacle_is_g_and_no_transition(tables):
    drive = Drive(tables, 33.3)
    cmd = drive.step(range_m=30.0, rate_mps=0.0, n=50)  # keeps its distance
    assert cmd.sector == "G" and drive.mode is Mode.NORMAL
    cmd = drive.step(range_m=30.0, rate_mps=+2.0, n=50)  # pulls away
    assert cmd.sector == "G" and drive.mode is Mode.NORMAL
    _s, sb, _b0, bb, ttc = bounds(tables, 1.0, 5.0)
    cmd = drive.step(range_m=ttc * 5.0 + max(sb, bb) + 1.0, rate_mps=-5.0, n=50)
    assert cmd.sector == "G" and drive.mode is Mode.NORMAL and not drive.ctrl.fcw_raised


def test_fcw_only_in_e(tables):
    v = speed_with(tables, 1.0, "E")
    drive = Drive(tables, v)
    cmd = drive.step(range_m=range_in(tables, 1.0, v, "E"), n=20)
    assert cmd.sector == "E" and cmd.fcw and drive.mode is Mode.NORMAL
    assert drive.ctrl.fcw_raised


@pytest.mark.parametrize("sector", ["D", "C", "A"])
def test_0_to_1_on_braking_sectors(tables, sector):
    v = speed_with(tables, 1.0, sector)
    drive = Drive(tables, v)
    cmd = drive.step(range_m=range_in(tables, 1.0, v, sector))
    assert cmd.sector == sector and drive.mode is Mode.UPDATE_BRAKE and cmd.fcw
    # pure braking at the no-lock limit, no drive
    assert cmd.drive_force_cmd_n == 0.0
    # the tables' limit braking (B0's deceleration) on the car and its spinning wheels, less
    # at most the drag and rolling resistance where the wheel-lock cap takes them off
    limit = equivalent_mass_kg(P) * tables.limit_brake_decel_mps2(1.0)
    assert limit == pytest.approx(0.95 * equivalent_mass_kg(P) * tables.max_decel_mps2(1.0))
    rolling = P.rolling_resistance_coeff * P.mass_kg * 9.81
    resistance = rolling + 0.5 * AIR_DENSITY_KGPM3 * P.drag_area_m2 * v * v
    assert limit - resistance <= cmd.brake_force_cmd_n <= limit + 1e-6


@pytest.mark.parametrize("sector", ["F", "B"])
def test_0_to_2_via_each_steer_sector(tables, sector):
    v = speed_with(tables, 1.0, sector)
    drive = Drive(tables, v)
    cmd = drive.step(range_m=range_in(tables, 1.0, v, sector))
    assert cmd.sector == sector and drive.mode is Mode.UPDATE_STEER_BRAKE
    assert drive.ctrl.modes_visited == [0, 2]
    # the manoeuvre references one lane to the left, from where the ego is
    drive.step(n=200)
    assert 0.0 < drive.cmd.y_target_m <= LANE + 1e-9 and drive.cmd.dx_m > 0.0


def test_0_to_3_steer_asked_with_oncoming(tables):
    v = speed_with(tables, 1.0, "F")
    drive = Drive(tables, v)
    drive.step(range_m=range_in(tables, 1.0, v, "F"), oncoming=True)
    assert drive.mode is Mode.ONCOMING_BRAKE and drive.ctrl.modes_visited == [0, 3]


def test_1_to_2_then_timer_expiry_2_to_5(tables):
    v = speed_with(tables, 1.0, "D", "F")
    drive = Drive(tables, v, settings=EoamSettings(return_when_stable=False))
    drive.step(range_m=range_in(tables, 1.0, v, "D"), n=5)
    assert drive.mode is Mode.UPDATE_BRAKE
    drive.step(range_m=range_in(tables, 1.0, v, "F"))
    assert drive.mode is Mode.UPDATE_STEER_BRAKE
    t_trigger = drive.t - DT
    timer = EoamSettings().manoeuvre_time_s
    while drive.t < t_trigger + timer - 2 * DT:
        drive.step(d_m=LANE)  # obstacle passed, in the next lane, no oncoming traffic
        assert drive.mode is Mode.UPDATE_STEER_BRAKE
    drive.step(n=3)
    assert drive.mode is Mode.RETURN
    assert drive.ctrl.modes_visited == [0, 1, 2, 5]


def test_2_to_5_early_once_stable_in_the_next_lane_and_past_the_obstacle(tables):
    v = speed_with(tables, 1.0, "F")
    drive = Drive(tables, v)
    rng = range_in(tables, 1.0, v, "F")
    obj = ObjectState(drive.s + P.cg_to_front_bumper_m + rng + 2.5, 0.0, 0.0, 5.0, 1.9)
    drive.step(range_m=rng, obj=obj)
    assert drive.mode is Mode.UPDATE_STEER_BRAKE
    length = drive.ctrl.state.path.length_m
    # in the next lane and straight, but the obstacle (front at obj.s + 2.5) not yet passed
    front = obj.s_m + 2.5
    while drive.s - P.cg_to_rear_bumper_m < front + 0.9:
        drive.step(d_m=LANE)
        assert drive.mode is Mode.UPDATE_STEER_BRAKE or drive.cmd.dx_m < length
    drive.step(d_m=LANE, n=max(1, math.ceil((length - drive.cmd.dx_m) / (v * DT))) + 15)
    assert drive.mode is Mode.RETURN and drive.t < 8.0  # well before the timer
    assert drive.ctrl.modes_visited == [0, 2, 5]
    # not stable: heading still turning or off the lane centre keeps the lane change going
    for kwargs in ({"d_m": LANE, "e_yaw": 0.05}, {"d_m": LANE - 0.5}):
        other = Drive(tables, v)
        other.step(range_m=rng, obj=obj)
        other.step(n=int(4.0 / DT), **kwargs)
        assert other.mode is Mode.UPDATE_STEER_BRAKE


def test_1_to_3_on_oncoming(tables):
    v = speed_with(tables, 1.0, "D", "F")
    drive = Drive(tables, v)
    drive.step(range_m=range_in(tables, 1.0, v, "D"), n=3)
    drive.step(range_m=range_in(tables, 1.0, v, "D"), oncoming=True)
    assert drive.mode is Mode.ONCOMING_BRAKE
    # terminal: neither a steer sector nor the oncoming vehicle leaving change it
    drive.step(range_m=range_in(tables, 1.0, v, "F"), n=50)
    drive.step(n=50)
    assert drive.mode is Mode.ONCOMING_BRAKE and drive.ctrl.modes_visited == [0, 1, 3]
    assert drive.cmd.brake_force_cmd_n > 0.0 and drive.cmd.drive_force_cmd_n == 0.0


def test_1_to_0_when_the_obstacle_leaves_the_path(tables):
    v = speed_with(tables, 1.0, "D", "E")
    drive = Drive(tables, v)
    drive.step(range_m=range_in(tables, 1.0, v, "D"), n=3)
    drive.step(range_m=range_in(tables, 1.0, v, "E"), n=10)  # still closing: keep braking
    assert drive.mode is Mode.UPDATE_BRAKE
    drive.step()  # nothing in the path any more
    assert drive.mode is Mode.NORMAL


def start_steer(tables, lane_m=LANE, settings=None):
    v = speed_with(tables, 1.0, "F")
    drive = Drive(tables, v, lane_m=lane_m, settings=settings)
    drive.step(range_m=range_in(tables, 1.0, v, "F"))
    assert drive.mode is Mode.UPDATE_STEER_BRAKE
    return drive


@pytest.mark.parametrize(
    ("lane_m", "travel_m", "expected"),
    [
        (3.5, 0.30, Mode.ONCOMING_BRAKE),
        (3.5, 1.04, Mode.ONCOMING_BRAKE),
        (3.5, 1.06, Mode.ONCOMING_STEER_BRAKE),
        (3.5, 2.50, Mode.ONCOMING_STEER_BRAKE),
        (3.0, 0.3 * HEIGHT_3M - 0.01, Mode.ONCOMING_BRAKE),  # point of no return 0.3 x travel
        (3.0, 0.3 * HEIGHT_3M + 0.01, Mode.ONCOMING_STEER_BRAKE),
    ],
)
def test_2_to_3_or_4_around_the_point_of_no_return(tables, lane_m, travel_m, expected):
    drive = start_steer(tables, lane_m)
    drive.step(d_m=travel_m, n=5)
    assert drive.mode is Mode.UPDATE_STEER_BRAKE
    drive.step(oncoming=True)
    assert drive.mode is expected


@pytest.mark.parametrize(
    ("width_m", "target_m"),
    [
        (1.9, 0.95 + 0.5 * P.width_m + 0.5),
        (2.6, 1.3 + 0.5 * P.width_m + 0.5),
        (4.4, LANE),
    ],
)
def test_4_aims_just_past_the_obstacle_side_then_5_once_past_it(tables, width_m, target_m):
    v = speed_with(tables, 1.0, "F")
    drive = Drive(tables, v)
    rng = range_in(tables, 1.0, v, "F")
    length, speed = 25.0, 5.0  # a slow long truck ahead: the shift ends before it is passed
    centre = drive.s + P.cg_to_front_bumper_m + rng + 0.5 * length
    drive.step(range_m=rng, obj=ObjectState(centre, 0.0, speed, length, width_m))
    drive.step(d_m=1.5, oncoming=True)
    assert drive.mode is Mode.ONCOMING_STEER_BRAKE
    # the target of mode 4: the obstacle's side plus half the ego and the side clearance
    margin = EoamSettings().pass_margin_m
    for _ in range(2000):
        ahead = drive.s - P.cg_to_rear_bumper_m - (centre + 0.5 * length + speed * drive.t)
        peak = drive.d
        drive.step(d_m=drive.cmd.y_target_m, oncoming=True)
        if drive.mode is not Mode.ONCOMING_STEER_BRAKE:
            break
        assert ahead < margin
    assert drive.mode is Mode.RETURN and drive.ctrl.modes_visited == [0, 2, 4, 5]
    assert ahead >= margin
    assert peak == pytest.approx(target_m, abs=0.02)
    # the return starts where the ego is and ends on the original lane centre
    assert drive.cmd.y_target_m == pytest.approx(peak, abs=0.05)
    follow_return_to_its_end(drive)


@pytest.mark.parametrize("min_time", [True, False])
def test_return_turns_urgent_when_oncoming_traffic_appears(tables, min_time):
    """An oncoming vehicle seen during a comfortable return re-plans it at the evasive
    lateral acceleration: it reaches the lane centre sooner. Time-optimal (jerk-limited
    bang-bang, ramp r): r + sqrt(r^2 + 4 D / A) for the lane width D; as a quintic, quicker
    by sqrt(a_comfortable / a_evasive)."""
    st = EoamSettings(min_time_escapes=min_time)
    ends = {}
    for seen in (False, True):
        drive = start_steer(tables, settings=st)
        while drive.mode is not Mode.RETURN:
            drive.step(d_m=LANE)
        t0 = drive.t
        for _ in range(5000):
            cmd = drive.step(d_m=drive.cmd.y_target_m, oncoming=seen)
            if cmd.dx_m > 0.0 and abs(cmd.y_target_m) < 1e-9:
                break
        ends[seen] = drive.t - t0
    if min_time:
        accel, ramp = st.evasive_lateral_g * 9.81, st.escape_ramp_s
        expected = ramp + math.sqrt(ramp * ramp + 4.0 * LANE / accel)
        assert ends[True] == pytest.approx(DT + expected, abs=2.5 * DT)
        assert ends[True] < ends[False]
    else:
        ratio = math.sqrt(st.return_lateral_g / st.evasive_lateral_g)  # quintic ~ 1/sqrt(a)
        assert ends[True] == pytest.approx(ends[False] * ratio, rel=0.06)


def follow_return_to_its_end(drive):
    """Move the synthetic ego exactly along the RETURN reference until it reaches d = 0."""
    for _ in range(5000):
        cmd = drive.step(d_m=drive.cmd.y_target_m)
        if cmd.dx_m > 0.0 and abs(cmd.y_target_m) < 1e-9:
            return
    pytest.fail("the return reference never reached the lane centre")


def test_5_to_0_return_completion_and_hand_back(tables):
    drive = start_steer(tables)
    drive.step(d_m=LANE, n=int(EoamSettings().manoeuvre_time_s / DT) + 2)
    assert drive.mode is Mode.RETURN
    follow_return_to_its_end(drive)
    assert drive.mode is Mode.RETURN
    dwell = EoamSettings().settle_dwell_s
    drive.step(d_m=0.05, n=int(dwell / DT) - 5)
    assert drive.mode is Mode.RETURN  # not settled long enough
    drive.step(d_m=0.05, n=10)
    assert drive.mode is Mode.NORMAL
    assert drive.ctrl.modes_visited == [0, 2, 5]  # first visits only
    # handed back: the speed PID holds the initial speed again
    assert drive.cmd.speed_target_mps == pytest.approx(drive.v)


def test_return_does_not_hand_back_while_off_centre(tables):
    drive = start_steer(tables)
    drive.step(d_m=LANE, n=int(EoamSettings().manoeuvre_time_s / DT) + 2)
    follow_return_to_its_end(drive)
    drive.step(d_m=0.5, n=200)  # 0.5 m off the centre
    assert drive.mode is Mode.RETURN
    drive.step(d_m=0.0, e_yaw=0.1, n=200)  # on the centre but not aligned with the road
    assert drive.mode is Mode.RETURN


def test_modes_with_low_friction_and_lane_keeping_in_normal(tables):
    drive = Drive(tables, 25.0, mu=0.3)
    cmd = drive.step(d_m=0.4, n=5)
    assert cmd.mode == 0 and cmd.y_target_m == 0.0
    assert cmd.lateral_error_m == pytest.approx(0.4) and cmd.steer_cmd_rad < 0.0
    assert all(
        math.isfinite(x) for x in (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n)
    )


def test_step_needs_reset_and_finite_measurements(tables):
    ctrl = EoamController(P, tables)
    meas = EgoMeasurement(0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, LANE)
    with pytest.raises(ValueError, match="reset"):
        ctrl.step(meas, Perception(), DT)
    ctrl.reset(30.0)
    bad = EgoMeasurement(0.0, math.nan, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, LANE)
    with pytest.raises(ValueError, match="vx_mps"):
        ctrl.step(bad, Perception(), DT)


@pytest.mark.parametrize(
    "beyond_m,mode", [(20.0, Mode.ONCOMING_BRAKE), (80.0, Mode.UPDATE_STEER_BRAKE)]
)
def test_a_standing_car_in_the_next_lane_blocks_the_steer_like_oncoming_traffic(
    tables, beyond_m, mode
):
    """A standing object in the next lane within the in-path obstacle's range plus
    ``next_lane_clear_m`` (50 m) turns the steer into limit braking in lane (mode 3); one
    further on leaves room to pass and return."""
    v = speed_with(tables, 1.0, "F")
    rng = range_in(tables, 1.0, v, "F")
    drive = Drive(tables, v)
    drive.ctrl.step(
        EgoMeasurement(0.0, v, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, LANE),
        Perception(rng, -v, False, None, rng + beyond_m),
        DT,
    )
    assert drive.mode is mode


@pytest.mark.parametrize(("v_lat_mps", "arrests"), [(2.0, True), (0.6, True), (0.3, False)])
def test_an_abort_moving_out_fast_is_arrested_at_the_envelope_edge(tables, v_lat_mps, arrests):
    """Mode 3 entered moving away from the lane centre at a lane change's lateral speed steers
    at the front slip envelope's edge against the motion (no feedback) until the motion stops;
    a slower drift gets the time-optimal shift back at once."""
    drive = start_steer(tables, settings=EoamSettings(ponr_at_lateral_stop=False))
    e_yaw = math.asin(v_lat_mps / drive.v)  # vy = 0: the lateral speed is vx sin(e_yaw)
    drive.step(d_m=0.5, e_yaw=e_yaw, n=3)
    cmd = drive.step(oncoming=True, e_yaw=e_yaw)
    assert drive.mode is Mode.ONCOMING_BRAKE
    edge = SteeringController(P).envelope_edge(drive.v, 0.0, 0.0, 1.0, -1.0)
    if arrests:
        assert cmd.steer_cmd_rad == pytest.approx(edge, rel=1e-12)
        assert cmd.steer_fb_rad == 0.0 and cmd.lateral_error_m == 0.0
        cmd = drive.step(oncoming=True, e_yaw=-0.01)  # moving right: arrested, shift back
    assert cmd.steer_cmd_rad > edge + 0.05  # a shift's command, well inside the envelope
