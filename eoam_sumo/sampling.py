"""Monte Carlo sampling of experiment matrices: the ``[sample]`` table and outcome probabilities.

A matrix with a ``[sample]`` table runs ``draws`` cases for each combination of the swept
values (a *group*); in each, the sampled keys take values drawn from their distributions:

    [sample]
    draws = 200
    seed = 1
    oncoming_start_m = { uniform = [250, 550] }
    mu_belief = { normal = [0.7, 0.1], clip = [0.3, 1.0] }
    radar_model = { choice = ["ideal", "automotive"] }

Distributions: ``{ uniform = [low, high] }``, ``{ normal = [mean, sd] }`` with an optional
``clip = [low, high]`` (required where the key's values are bounded, i.e. for every numeric
key: the clip must lie within the key's valid range), ``{ choice = [v1, v2, ...] }``.

Draws are reproducible and independent of the order cases run in: draw ``k`` of the group
with id ``g`` uses numpy's PCG64 seeded with (seed, crc32(g), k); keys are drawn in name
order, then the draw's run seed (``seed`` column: the friction estimator's and radar's
noise), so re-running one draw with ``eoam-sumo run --seed`` reproduces it.

Outcome probabilities per group: p = count / n with the Wilson score interval (Wilson 1927,
"Probable inference, the law of succession, and statistical inference", JASA 22(158)):

    centre = (p + z^2 / (2n)) / (1 + z^2 / n)
    half   = z / (1 + z^2 / n) * sqrt(p (1 - p) / n + z^2 / (4 n^2)),   z = 1.959964 (95 %)

which, unlike the normal approximation, stays inside [0, 1] and is not empty at p = 0 or 1.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.seeds import check_seed

KINDS = ("uniform", "normal", "choice")
Z_95 = 1.959963984540054  # standard normal quantile of 0.975
MAX_DRAWS = 1_000_000
#: A key's own check: the value as a case holds it, or InputError.
Check = Callable[[object], object]


@dataclass(frozen=True)
class Distribution:
    """A checked distribution of one matrix key."""

    key: str
    kind: str
    params: tuple
    clip: tuple[float, float] | None = None

    def draw(self, rng: np.random.Generator):
        if self.kind == "choice":
            return self.params[int(rng.integers(len(self.params)))]
        if self.kind == "uniform":
            return float(rng.uniform(*self.params))
        value = self.params[0] + self.params[1] * float(rng.standard_normal())
        if self.clip is not None:
            value = min(max(value, self.clip[0]), self.clip[1])
        return value

    def extremes(self) -> tuple:
        """Every value the distribution can give at its bounds (choices: all of them)."""
        if self.kind in ("choice", "uniform"):
            return self.params
        return self.clip if self.clip is not None else ()


@dataclass(frozen=True)
class Sample:
    """The ``[sample]`` table: draws per group, the seed, the distributions by key."""

    draws: int
    seed: int
    distributions: tuple[Distribution, ...]

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(d.key for d in self.distributions)

    def of(self, key: str) -> Distribution | None:
        return next((d for d in self.distributions if d.key == key), None)

    def values(self, group_id: str, draw: int) -> tuple[dict, int]:
        """(key -> drawn value, run seed) of draw ``draw`` of the group ``group_id``."""
        rng = np.random.default_rng([self.seed, zlib.crc32(group_id.encode()), draw])
        values = {d.key: d.draw(rng) for d in self.distributions}
        return values, int(rng.integers(0, 2**31 - 1))


def _pair(where: str, value) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2 or not all(_is_number(v) for v in value):
        raise InputError(f"{where} = {value!r} must be a list of two numbers")
    return float(value[0]), float(value[1])


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def parse_distribution(path, key: str, spec, check: Check) -> Distribution:
    """A checked distribution of ``key`` from its TOML inline table; ``check(value)``
    returns the value as a case holds it or raises InputError (the key's own check)."""
    where = f"{path}: [sample] {key}"
    if not isinstance(spec, dict):
        raise InputError(
            f"{where} = {spec!r} must be a distribution: {{ uniform = [low, high] "
            "}, { normal = [mean, sd] } or { choice = [...] }"
        )
    kinds = [k for k in spec if k in KINDS]
    extra = [k for k in spec if k not in (*KINDS, "clip")]
    if len(kinds) != 1 or extra:
        raise InputError(
            f"{where} = {spec!r} must name one of {', '.join(KINDS)} (and clip, for normal)"
        )
    kind = kinds[0]
    if "clip" in spec and kind != "normal":
        raise InputError(f"{where}: clip applies to a normal distribution only, not {kind}")

    def checked(value, what: str):
        try:
            return check(value)
        except InputError as exc:
            raise InputError(f"{where}: {what} {value!r}: {exc}") from None

    if kind == "choice":
        values = spec["choice"]
        if not isinstance(values, list) or not values:
            raise InputError(f"{where}: choice = {values!r} must be a non-empty list")
        return Distribution(key, kind, tuple(checked(v, "choice") for v in values))
    low, high = _pair(f"{where}: {kind}", spec[kind])
    if kind == "uniform":
        if not low < high:
            raise InputError(f"{where}: uniform = [{low:g}, {high:g}] needs low < high")
        return Distribution(key, kind, (checked(low, "low"), checked(high, "high")))
    if not high > 0.0:
        raise InputError(f"{where}: normal = [{low:g}, {high:g}] needs sd > 0")
    if "clip" not in spec:
        raise InputError(
            f"{where}: normal = [{low:g}, {high:g}] needs clip = [low, high] "
            "within the key's valid values"
        )
    clip = _pair(f"{where}: clip", spec["clip"])
    if not clip[0] <= clip[1]:
        raise InputError(f"{where}: clip = [{clip[0]:g}, {clip[1]:g}] needs low <= high")
    return Distribution(
        key, kind, (low, high), (checked(clip[0], "clip low"), checked(clip[1], "clip high"))
    )


def parse_sample(path, table: dict, checks: dict[str, Check]) -> Sample:
    """The ``[sample]`` table; ``checks`` maps each key that may be sampled to its check."""
    where = f"{path}: [sample]"
    if "draws" not in table:
        raise InputError(f"{where} needs the key 'draws'")
    draws, seed = table["draws"], table.get("seed", 0)
    if isinstance(draws, bool) or not isinstance(draws, int) or not 1 <= draws <= MAX_DRAWS:
        raise InputError(f"{where} draws = {draws!r} must be an integer in [1, {MAX_DRAWS}]")
    check_seed(seed, f"{where} seed")
    distributions = []
    for key in sorted(k for k in table if k not in ("draws", "seed")):
        if key not in checks:
            raise InputError(
                f"{where}: '{key}' cannot be sampled (keys that can: {', '.join(sorted(checks))})"
            )
        distributions.append(parse_distribution(path, key, table[key], checks[key]))
    return Sample(draws, seed, tuple(distributions))


def wilson_interval(count: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion count/n (formula: module docstring)."""
    if n <= 0 or not 0 <= count <= n:
        raise ValueError(f"need 0 <= count <= n and n > 0, got count={count}, n={n}")
    p = count / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z / denom * math.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n))
    # p lies inside the interval (exactly at its end for count 0 or n): clamp the rounding
    return max(0.0, min(centre - half, p)), min(1.0, max(centre + half, p))
