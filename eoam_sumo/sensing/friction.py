"""What the EOAM believes the road's friction to be (the plant always uses the true one).

The DMM boundaries, the lookup-table trajectory and the brake limit of the EOAM all depend on
the friction (paper sec. 7, eq. 33 and Figure 15); the paper assumes it is known. Three
beliefs:

* ``known``: the true friction of the lane under the ego (the paper's assumption).
* a number: a fixed assumption, e.g. ``1.0`` for a system without an estimator that plans
  for a dry road.
* ``estimate``: a model of a tyre-based friction estimator's output. Such estimators identify
  the friction from the tyres' departure from their linear region: the slip-slope method of
  Gustafsson (1997, "Slip-based tire-road friction estimation", Automatica 33(6)) needs
  traction or braking force, and the steering-torque method of Hsu, Laws and Gerdes (2010,
  "Estimation of tire slip angle and friction limits using steering torque", IEEE Trans.
  Control Systems Technology 18(4)) needs lateral force; both are uninformative in steady
  cruising. The model: the estimate starts at ``prior_mu`` (a dry road); while the tyres are
  excited (friction utilisation sqrt(ax^2 + ay^2) / (mu g) at least
  ``excitation_utilisation``) it moves towards the true friction of ``delay_s`` ago, observed
  with Gaussian noise ``noise_sd``, with time constant ``time_constant_s``; without excitation
  it holds. The output is the estimate plus ``bias``, published every ``update_period_s`` and
  held between updates, clipped to [``mu_min``, 1.2]. The model is of the estimator's output,
  not of its internals (the plant has no wheel-speed states to estimate slip from).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from mypy_extensions import mypyc_attr

from eoam_sumo.errors import InputError
from eoam_sumo.params import G_MPS2, MU_MAX

KINDS = ("known", "estimate")
STREAM = 1  # random stream of the run seed (the radar draws from stream 2)


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class EstimatorSettings:
    """The friction estimator model (``estimate`` belief); reasons in the module docstring."""

    prior_mu: float = 1.0  # before any excitation: a dry road assumed [-] (assumed)
    bias: float = 0.0  # added to the estimate [-] (0: an unbiased estimator; sample it)
    noise_sd: float = 0.05  # observation noise, 1 sigma [-] (assumed, a tenth of 0.5)
    delay_s: float = 0.3  # the observation is of the friction this long ago [s] (assumed)
    update_period_s: float = 0.1  # output rate 10 Hz [s] (assumed)
    excitation_utilisation: float = 0.3  # utilisation above which it learns [-] (assumed)
    time_constant_s: float = 0.5  # convergence while excited [s] (assumed)

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not math.isfinite(value) or (name != "bias" and value < 0.0):
                raise InputError(
                    f"friction estimator {name} = {value!r} must be finite"
                    + ("" if name == "bias" else " and >= 0")
                )
        if self.update_period_s <= 0.0 or self.time_constant_s <= 0.0:
            raise InputError("friction estimator update_period_s and time_constant_s must be > 0")


def parse_mu_belief(value) -> str | float:
    """``known``, ``estimate`` or a friction in (0, 1.2]; InputError naming the value."""
    if isinstance(value, str):
        text = value.strip().lower()
        if text in KINDS:
            return text
        try:
            value = float(text)
        except ValueError:
            raise InputError(
                f"mu_belief {value!r} is not 'known', 'estimate' or a number in (0, {MU_MAX:g}]"
            ) from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"mu_belief {value!r} is not 'known', 'estimate' or a number")
    if not (math.isfinite(value) and 0.0 < value <= MU_MAX):
        raise InputError(f"mu_belief {value!r} is outside (0, {MU_MAX:g}]")
    return float(value)


class FrictionBelief:
    """The friction the EOAM decides with; :meth:`mu` is called once per step (sense phase).

    ``belief``: as :func:`parse_mu_belief` returns; ``seed`` seeds the estimator's noise;
    ``mu_min`` is the lowest friction the lookup tables cover (estimates are clipped to it).
    ``trace`` keeps (time_s, mu) at each change of the output."""

    def __init__(
        self,
        belief: str | float = "known",
        *,
        seed: int = 0,
        settings: EstimatorSettings = EstimatorSettings(),
        mu_min: float = 0.1,
    ):
        self.belief = parse_mu_belief(belief)
        self.settings = settings
        self.mu_min = mu_min
        self._rng = np.random.default_rng([seed, STREAM])
        self._estimate = settings.prior_mu
        self._history: deque[tuple[float, float]] = deque()  # (t, true mu) within the delay
        self._next_update_s: float | None = None
        self._last_update_s: float | None = None
        self._output = self._clip(settings.prior_mu + settings.bias)
        self.trace: list[tuple[float, float]] = []

    @property
    def label(self) -> str | float:
        """What summary.json records as ``mu_belief``."""
        return self.belief

    def _clip(self, mu: float) -> float:
        return min(max(mu, self.mu_min), MU_MAX)

    def mu(self, true_mu: float, t_s: float, ax_mps2: float, ay_mps2: float) -> float:
        """The believed friction at time ``t_s``, given the road's ``true_mu`` under the ego
        and the ego's measured accelerations (the estimator's excitation)."""
        belief = self.belief
        if belief == "known":
            out = true_mu
        elif isinstance(belief, float):
            out = belief
        else:
            out = self._estimated(true_mu, t_s, ax_mps2, ay_mps2)
        if not self.trace or self.trace[-1][1] != out:
            self.trace.append((t_s, out))
        return out

    def _estimated(self, true_mu: float, t_s: float, ax: float, ay: float) -> float:
        st = self.settings
        history = self._history
        history.append((t_s, true_mu))
        while len(history) > 1 and history[1][0] <= t_s - st.delay_s + 1e-9:
            history.popleft()
        if self._next_update_s is None:
            self._next_update_s = t_s
        if t_s + 1e-9 < self._next_update_s:
            return self._output
        dt = st.update_period_s if self._last_update_s is None else t_s - self._last_update_s
        self._last_update_s = t_s
        self._next_update_s += st.update_period_s
        utilisation = math.hypot(ax, ay) / (max(true_mu, 1e-6) * G_MPS2)
        noise = self._rng.standard_normal()  # drawn at every update: the stream stays aligned
        if utilisation >= st.excitation_utilisation:
            observed = history[0][1] + st.noise_sd * noise
            self._estimate += (1.0 - math.exp(-dt / st.time_constant_s)) * (
                observed - self._estimate
            )
        self._output = self._clip(self._estimate + st.bias)
        return self._output

    def at(self, t_s: float) -> float | None:
        """The believed friction at time ``t_s`` (from the trace), None before the first call."""
        value = None
        for t, mu in self.trace:
            if t > t_s + 1e-9:
                break
            value = mu
        return value
