"""V2X messages: range, latency, packet loss and penetration, all seeded."""

import math
from collections import namedtuple

import pytest

from eoam_sumo.sensing.v2x import V2XReceiver, V2XSettings

B = namedtuple("B", "vid x_m y_m yaw_rad speed_mps length_m width_m")


def _run(settings, bodies_at, t_end_s, dt=0.01):
    rx = V2XReceiver(settings)
    seen = []
    for k in range(round(t_end_s / dt) + 1):
        t = k * dt
        rx.update(t, (0.0, 0.0), bodies_at(t))
        seen.append((t, rx.objects(t)))
    return rx, seen


def test_a_message_arrives_after_the_latency_and_is_dead_reckoned_to_now():
    def car(t):
        return [B("c", 300.0 - 20.0 * t, 1.75, math.pi, 20.0, 4.7, 1.8)]

    _, seen = _run(V2XSettings(range_m=500.0, latency_s=0.1), car, 1.0)
    first = next(t for t, objs in seen if objs)
    assert first == pytest.approx(0.1, abs=1e-9)
    t, objs = seen[-1]
    assert objs[0].x_m == pytest.approx(300.0 - 20.0 * t, abs=1e-6)  # predicted to the present
    assert 0.1 <= objs[0].age_s <= 0.2 + 1e-9


def test_nothing_is_heard_beyond_the_range_or_with_v2x_off():
    def far(t):
        return [B("c", 600.0, 1.75, math.pi, 0.0, 4.7, 1.8)]

    assert not _run(V2XSettings(range_m=500.0), far, 0.5)[1][-1][1]
    assert not _run(V2XSettings(range_m=0.0), far, 0.5)[1][-1][1]


def test_packet_loss_drops_about_its_share_and_is_the_same_for_the_same_seed():
    def car(t):
        return [B("c", 100.0, 1.75, 0.0, 0.0, 4.7, 1.8)]

    counts = []
    for seed in (1, 1, 2):
        rx = V2XReceiver(V2XSettings(range_m=500.0, loss=0.3, seed=seed))
        got = 0
        for k in range(20001):
            t = k * 0.01
            before = rx._newest.get("c")
            rx.update(t, (0.0, 0.0), car(t))
            got += rx._newest.get("c") is not before
        counts.append(got)
    assert counts[0] == counts[1] != counts[2]
    assert counts[0] / 2000 == pytest.approx(0.7, abs=0.04)  # 2000 messages in 200 s


def test_penetration_equips_a_seeded_share_of_road_users():
    bodies = [B(f"v{i}", 50.0 + i, 0.0, 0.0, 0.0, 4.7, 1.8) for i in range(400)]
    rx = V2XReceiver(V2XSettings(range_m=1000.0, penetration=0.25, seed=7))
    share = sum(rx.equipped(b.vid) for b in bodies) / len(bodies)
    assert share == pytest.approx(0.25, abs=0.06)
    again = V2XReceiver(V2XSettings(range_m=1000.0, penetration=0.25, seed=7))
    assert [again.equipped(b.vid) for b in bodies] == [rx.equipped(b.vid) for b in bodies]
    assert V2XSettings(range_m=1.0, penetration=1.0).covers_all
    assert not V2XSettings(range_m=1.0, penetration=0.99).covers_all


def test_blind_time_allows_for_a_run_of_losses():
    assert V2XSettings(latency_s=0.1).blind_time_s() == pytest.approx(0.2)
    lossy = V2XSettings(latency_s=0.1, loss=0.1)  # 0.1 ** 6 = 1e-6
    assert lossy.blind_time_s() == pytest.approx(0.1 + 0.1 * 7)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"loss": 1.0},
        {"penetration": 1.5},
        {"range_m": -1.0},
        {"period_s": 0.0},
        {"latency_s": math.nan},
    ],
)
def test_bad_v2x_settings_are_refused(kwargs):
    with pytest.raises(ValueError):
        V2XSettings(**kwargs)
