"""V2X: equipped road users broadcast their state; the ego receives what reaches it in time.

Modelled on the ETSI Cooperative Awareness Message (ETSI EN 302 637-2: position, speed,
heading and vehicle length and width; 1-10 Hz, here the 10 Hz upper rate). Every equipped
road user within ``range_m`` of the ego sends one message per ``period_s`` (each with its own
phase); a message is lost with probability ``loss`` and otherwise received ``latency_s`` after
it was sent. The receiver keeps the newest message per sender and predicts it to the present
at its speed and heading (dead reckoning), dropping senders silent for ``timeout_s``.

``penetration`` is the share of road users equipped; which ones is drawn per road user from
``seed`` (a penetration of 1 equips all). Losses and phases are drawn per message from the
seed too: the same seed gives the same run. Persons and bicycles broadcast as vehicles do
(ETSI's VRU awareness message carries the same fields).

Absence of messages proves a lane free only when every road user is equipped
(``covers_all``); there is no roadside unit reporting unequipped ones.
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

from mypy_extensions import mypyc_attr

#: Consecutive losses the "no message means no road user" reasoning allows for: the chance of
#: a longer run of losses is below 1e-6.
LOSS_RUN_PROBABILITY = 1e-6


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class V2XSettings:
    """V2X link and fleet: range 0 turns V2X off."""

    range_m: float = 0.0  # reception range [m]; 0 = no V2X
    latency_s: float = 0.1  # end-to-end latency [s] (ETSI TR 102 638: <= 100 ms for warnings)
    loss: float = 0.0  # packet-loss probability per message [-]
    penetration: float = 1.0  # share of road users equipped [-]
    period_s: float = 0.1  # broadcast period [s] (10 Hz, EN 302 637-2 upper rate)
    timeout_s: float = 1.0  # a sender silent this long is dropped [s]
    seed: int = 0  # draws of equipment, phases and losses

    def __post_init__(self) -> None:
        for key in ("range_m", "latency_s", "loss", "penetration", "period_s", "timeout_s"):
            v = getattr(self, key)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ValueError(f"V2X setting {key}={v!r} must be a finite number >= 0")
        if self.loss >= 1.0:
            raise ValueError(f"V2X loss={self.loss} must be < 1")
        if self.penetration > 1.0:
            raise ValueError(f"V2X penetration={self.penetration} must be <= 1")
        if self.period_s <= 0.0 or self.timeout_s <= 0.0:
            raise ValueError("V2X period_s and timeout_s must be > 0")

    @property
    def enabled(self) -> bool:
        return self.range_m > 0.0

    @property
    def covers_all(self) -> bool:
        """Every road user is equipped: no message within range means no road user there."""
        return self.enabled and self.penetration >= 1.0

    def blind_time_s(self) -> float:
        """Longest time a road user inside the range may go unheard (its first message's
        latency after up to the allowed run of losses): the range counts as free only this
        long times the fastest road user's speed inside its edge."""
        losses = 0
        if self.loss > 0.0:
            losses = math.ceil(math.log(LOSS_RUN_PROBABILITY) / math.log(self.loss))
        return self.latency_s + self.period_s * (1 + losses)


class V2XObject(NamedTuple):
    """A road user as its newest received message tells, predicted to the present."""

    sender: str
    x_m: float  # centre
    y_m: float
    yaw_rad: float
    speed_mps: float
    length_m: float
    width_m: float
    age_s: float  # since the message was sent


class _Message(NamedTuple):
    sent_s: float
    sender: str
    x_m: float
    y_m: float
    yaw_rad: float
    speed_mps: float
    length_m: float
    width_m: float


def _draw(seed: int, *key) -> float:
    """A uniform number in [0, 1) fixed by the seed and the key (string seeding is stable
    across processes, unlike ``hash``)."""
    return random.Random("/".join(str(k) for k in (seed, *key))).random()


class V2XReceiver:
    """The ego's V2X receiver: call :meth:`update` every step with the road users around."""

    def __init__(self, settings: V2XSettings):
        self.settings = settings
        self._equipped: dict[str, bool] = {}
        self._phase: dict[str, float] = {}
        self._next_send: dict[str, int] = {}  # sender -> index of its next message
        self._in_flight: deque[_Message] = deque()
        self._newest: dict[str, _Message] = {}

    def equipped(self, sender: str) -> bool:
        st = self.settings
        known = self._equipped.get(sender)
        if known is None:
            known = self._equipped[sender] = (
                st.penetration >= 1.0 or _draw(st.seed, "equipped", sender) < st.penetration
            )
            self._phase[sender] = st.period_s * _draw(st.seed, "phase", sender)
        return known

    def update(self, time_s: float, ego_xy: tuple[float, float], bodies: Iterable) -> None:
        """Send the messages due by ``time_s`` from the equipped ``bodies`` (objects with
        ``vid, x_m, y_m, yaw_rad, speed_mps, length_m, width_m``) within range, and receive
        those whose latency has passed."""
        st = self.settings
        if not st.enabled:
            return
        ex, ey = ego_xy
        reach2 = st.range_m * st.range_m
        for b in bodies:
            if not self.equipped(b.vid):
                continue
            if (b.x_m - ex) ** 2 + (b.y_m - ey) ** 2 > reach2:
                self._next_send.pop(b.vid, None)
                continue
            k = math.floor((time_s - self._phase[b.vid]) / st.period_s + 1e-9)
            first = self._next_send.get(b.vid)
            if first is not None and k < first:
                continue  # not due yet
            self._next_send[b.vid] = k + 1
            if st.loss > 0.0 and _draw(st.seed, "loss", b.vid, k) < st.loss:
                continue
            self._in_flight.append(
                _Message(time_s, b.vid, b.x_m, b.y_m, b.yaw_rad, b.speed_mps, b.length_m, b.width_m)
            )
        flight = self._in_flight
        while flight and flight[0].sent_s + st.latency_s <= time_s + 1e-9:
            msg = flight.popleft()
            self._newest[msg.sender] = msg

    def objects(self, time_s: float) -> list[V2XObject]:
        """The senders heard within ``timeout_s``, each predicted to ``time_s``."""
        out, stale = [], []
        for sender, m in self._newest.items():
            age = time_s - m.sent_s
            if age > self.settings.timeout_s:
                stale.append(sender)
                continue
            step = m.speed_mps * age
            out.append(
                V2XObject(
                    sender,
                    m.x_m + step * math.cos(m.yaw_rad),
                    m.y_m + step * math.sin(m.yaw_rad),
                    m.yaw_rad,
                    m.speed_mps,
                    m.length_m,
                    m.width_m,
                    age,
                )
            )
        for sender in stale:
            del self._newest[sender]
        out.sort()
        return out
