"""Experiment matrices: a TOML sweep of one SUMO scenario over oncoming traffic x speed x friction.

The format is documented in ``scenarios/table2.toml`` (the paper's Table 2, 4 x 4 x 4 = 64 runs).
Cases come in the paper's Table 2 order: traffic outermost (no oncoming car first, then the
oncoming start distances in file order), then ego speed, then friction, then the optional ARO
stop parameters, each in file order. A ``[sample]`` table (:mod:`eoam_sumo.sampling`) turns
each combination into a group of draws, in turn.

Two levels of checks, both raising ``InputError`` naming the matrix file and the key:
:func:`load_matrix` checks the TOML on its own (keys, types, ranges, files exist);
:func:`check_matrix` then checks it against what a run will use (the scenario's files parse
and hold the ego; every speed and friction is covered by the lookup tables, without ``mu``
the network's own frictions where the ego departs), so a batch refuses bad input before any
case runs. Without ``mu`` every case runs on each lane's own friction, as ``run`` without
``--mu`` does.
"""

from __future__ import annotations

import csv
import difflib
import itertools
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

from eoam_sumo.colours import OUTCOMES
from eoam_sumo.drivers import DRIVERS
from eoam_sumo.errors import InputError
from eoam_sumo.params import MU_MAX, VehicleParams, ego_e_class_sedan
from eoam_sumo.sampling import Sample, parse_sample
from eoam_sumo.seeds import check_seed
from eoam_sumo.sensing.automotive import parse_radar_model
from eoam_sumo.sensing.friction import parse_mu_belief
from eoam_sumo.sim.scenario import ScenarioFiles, ScenarioOverrides, check_scenario, scripted_stops
from eoam_sumo.sim.scenario.routes import check_oncoming_road, ego_route_edges
from eoam_sumo.sim.settings import DEFAULT_MAX_TIME_S, MAX_TIME_LIMIT_S, check_sumo_step_s
from eoam_sumo.sim.vehicle import vehicle_name, vehicle_tables, vehicle_tables_dir
from eoam_sumo.textfiles import not_utf8
from eoam_sumo.traffic_levels.hcm import LEVELS
from eoam_sumo.traffic_levels.spec import (
    MIN_CURVE_RADIUS_M,
    MIN_SPEED_LIMIT_KMH,
    ROADS,
    TrafficSpec,
    max_speed_limit_kmh,
)
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE, load_vehicle

NO_ONCOMING = "none"
#: The keys of a generated scenario (``eoam_sumo.traffic_levels``), in [scenario] one value
#: each, in [sweep] lists; a case folder's ``GENERATED`` is its scenario then.
TRAFFIC_KEYS = ("road", "los", "lanes", "speed_limit_kmh", "curve_radius_m")
STRAIGHT = "none"  # curve_radius_m: a straight road
GENERATED = Path("scenario") / "scenario.sumocfg"
SCHEMA = {
    "scenario": (
        "sumocfg",
        "max_time_s",
        "radar_range_m",
        "policy",
        "driver",
        "v2x_range_m",
        "v2x_latency_s",
        "v2x_loss",
        "v2x_penetration",
        "mu_belief",
        "radar_model",
        "seed",
        "after_stop_s",
        "sumo_step_s",
        "vehicle",
        "abs",
        "esc",
        "abs_esc",
        *TRAFFIC_KEYS,
    ),
    "sweep": (
        "ego_speed_kmh",
        "mu",
        "oncoming_start_m",
        "aro_hold_s",
        "aro_decel_mps2",
        "vehicle",
        "abs",
        "esc",
        "abs_esc",
        "policy",
        "driver",
        *TRAFFIC_KEYS,
    ),
    "paper": ("table",),
    "sample": (),  # draws, seed and the sampled keys: checked by sampling.parse_sample
}
#: ``mu`` may be left out: every case then runs on each lane's own friction (the network's)
REQUIRED = {"scenario": (), "sweep": ("ego_speed_kmh",)}  # unless sampled
PAPER_COLUMNS = ("oncoming_start_m", "ego_speed_kmh", "mu", "outcome")
POLICIES = ("paper", "safe")
#: The equipment keys: ``abs`` and ``esc`` switch one system, ``abs_esc`` both together;
#: "on" or "off" ([scenario] one value, [sweep] a list; never sampled).
EQUIPMENT_KEYS = ("abs", "esc", "abs_esc")
SWITCH = {"on": True, "off": False}
#: [scenario] V2X keys: (default, lowest, highest or None, highest included)
V2X_KEYS = {
    "v2x_range_m": (0.0, 0.0, None, True),
    "v2x_latency_s": (0.1, 0.0, None, True),
    "v2x_loss": (0.0, 0.0, 1.0, False),
    "v2x_penetration": (1.0, 0.0, 1.0, True),
}


def _id_number(value: float) -> str:
    """Filesystem-safe, unique, short text of a number: 165, 92.5, 1e20 (a whole number of
    20 digits or more in exponent form: 1e308 as 309 digits made a name too long to write)."""
    whole = value.is_integer() and abs(value) < 1e20
    return (str(int(value)) if whole else repr(value)).replace("+", "")


def _mu_text(value: float) -> str:
    return repr(float(value)).replace("+", "")


@dataclass(frozen=True)
class Case:
    """One co-simulation of a matrix; None for an ARO parameter keeps the route file's value."""

    case_id: str
    sumocfg: Path
    ego_speed_kmh: float
    mu: float | None  # None: each lane's own friction, as the network sets it
    oncoming_start_m: float | None
    aro_hold_s: float | None
    aro_decel_mps2: float | None
    max_time_s: float
    radar_range_m: float | None = None  # None: the radar's default range
    policy: str = "paper"
    driver: str = "eoam"  # the ego's controller: the EOAM or a reference driver (``DRIVERS``)
    v2x_range_m: float = 0.0  # 0: no V2X
    v2x_latency_s: float = 0.1
    v2x_loss: float = 0.0
    v2x_penetration: float = 1.0
    mu_belief: str | float = "known"
    radar_model: str = "ideal"
    seed: int = 0
    after_stop_s: float | None = None  # None: the run's default (RunSettings.after_stop_s)
    sumo_step_s: float | None = None  # None: the run's default (RunSettings.sumo_step_s)
    # a generated scenario (None: the sumocfg's); its traffic seeded with ``seed``
    road: str | None = None
    los: str | None = None
    lanes: int | None = None
    speed_limit_kmh: float | None = None
    curve_radius_m: float | None = None
    abs_fitted: bool | None = None  # None: the vehicle's own (the sedan's: off)
    esc_fitted: bool | None = None  # None: the vehicle's own (the sedan's: off)
    # the ego's vehicle: a catalogue name or a vehicle file (resolved); None: the paper's
    # sedan (``params.ego_e_class_sedan``, the catalogue's ``sedan``)
    vehicle: str | None = None
    draw: int | None = None  # the draw's number within its group (sampled matrices)
    group_id: str | None = None  # the case id of its group of swept values (sampled)
    # braking only (the EOAM's lane change inhibited, ``EoamSettings.steering_inhibited``):
    # the protocol command's ``--system aeb``
    steering_inhibited: bool = False

    def traffic(self) -> TrafficSpec | None:
        """The generated scenario's spec (None: the case runs its sumocfg)."""
        if self.road is None:
            return None
        return TrafficSpec(
            self.road,
            self.los or "",
            self.lanes,
            self.speed_limit_kmh,
            self.curve_radius_m,
            self.seed,
        )

    def overrides(self) -> ScenarioOverrides:
        return ScenarioOverrides(
            ego_speed_mps=self.ego_speed_kmh / 3.6,
            mu=self.mu,
            oncoming_start_m=self.oncoming_start_m,
            aro_hold_s=self.aro_hold_s,
            aro_decel_mps2=self.aro_decel_mps2,
        )


@dataclass(frozen=True)
class Matrix:
    """A checked experiment matrix (see :func:`load_matrix`)."""

    path: Path
    sumocfg: Path | None  # None: a generated scenario (``traffic_axes``)
    max_time_s: float
    ego_speeds_kmh: tuple[float, ...]
    mus: tuple[float, ...]  # (): each lane's own friction (the network's) in every case
    oncoming_starts_m: tuple[float | None, ...]
    aro_holds_s: tuple[float, ...]
    aro_decels_mps2: tuple[float, ...]
    paper_table: Path | None = None
    radar_range_m: float | None = None
    policy: str = "paper"
    driver: str = "eoam"
    v2x: tuple[float, float, float, float] = (0.0, 0.1, 0.0, 1.0)  # range, latency, loss, share
    mu_belief: str | float = "known"
    radar_model: str = "ideal"
    seed: int = 0
    sample: Sample | None = None
    after_stop_s: float | None = None
    sumo_step_s: float | None = None
    # the generated scenario's keys given, swept or sampled: (key, values), ``TRAFFIC_KEYS``
    # order; a sampled key's values are (None,)
    traffic_axes: tuple[tuple[str, tuple], ...] = ()
    # the vehicles given ([scenario] one, [sweep] a list; sampled: (None,)); (): the sedan
    vehicles: tuple[str | None, ...] = ()
    # [scenario] abs / esc (abs_esc: both); None: the vehicle's own
    abs_fitted: bool | None = None
    esc_fitted: bool | None = None
    # the swept equipment keys as (key, switch values), ``EQUIPMENT_KEYS`` order
    equipment: tuple[tuple[str, tuple[bool, ...]], ...] = ()
    policies: tuple[str, ...] = ()  # [sweep] policy; (): every case runs ``policy``
    drivers: tuple[str, ...] = ()  # [sweep] driver; (): every case runs ``driver``

    def cases(self) -> list[Case]:
        """Every case, in the paper's Table 2 order (traffic, speed, friction, ARO stop),
        after a generated scenario's keys (road, level, lanes, speed limit, curve); with a
        ``[sample]`` table, each combination's draws in turn (``<combination id>_dNNNN``)."""
        sampled = self.sample.keys if self.sample else ()
        axes = (
            *((("vehicle", self.vehicles),) if self.vehicles else ()),
            *self.equipment,
            *((("policy", self.policies),) if self.policies else ()),
            *((("driver", self.drivers),) if self.drivers else ()),
            *self.traffic_axes,
            (
                "oncoming_start_m",
                tuple(sorted(self.oncoming_starts_m, key=lambda d: d is not None)),
            ),
            ("ego_speed_kmh", self.ego_speeds_kmh),
            ("mu", self.mus or (None,)),
            ("aro_hold_s", self.aro_holds_s or (None,)),
            ("aro_decel_mps2", self.aro_decels_mps2 or (None,)),
        )
        settings = {
            "max_time_s": self.max_time_s,
            "radar_range_m": self.radar_range_m,
            "policy": self.policy,
            "driver": self.driver,
            "v2x_range_m": self.v2x[0],
            "v2x_latency_s": self.v2x[1],
            "v2x_loss": self.v2x[2],
            "v2x_penetration": self.v2x[3],
            "mu_belief": self.mu_belief,
            "radar_model": self.radar_model,
            "seed": self.seed,
            "after_stop_s": self.after_stop_s,
            "sumo_step_s": self.sumo_step_s,
            "abs_fitted": self.abs_fitted,
            "esc_fitted": self.esc_fitted,
        }
        cases = []
        for combo in itertools.product(*(values for _, values in axes)):
            values = dict(zip((key for key, _ in axes), combo))
            case_id = _case_id(values, sampled)
            cases.append(
                Case(case_id, self.sumocfg or GENERATED, **{**settings, **_case_fields(values)})
            )
        return cases if self.sample is None else self._draws(cases, self.sample)

    @staticmethod
    def _draws(groups: list[Case], sample: Sample) -> list[Case]:
        """Each group's draws, ``<group>_d<k>``: a draw's id and values do not depend on how
        many draws there are, so a study given more draws resumes (``--resume``) its own."""
        cases = []
        for group in groups:
            for k in range(sample.draws):
                values, seed = sample.values(group.case_id, k)
                cases.append(
                    replace(
                        group,
                        **values,
                        seed=seed,
                        draw=k,
                        group_id=group.case_id,
                        case_id=f"{group.case_id}_d{k}",
                    )
                )
        return cases

    def paper_outcomes(self) -> dict[str, str]:
        """case_id -> the paper's outcome colour for the cases the ``[paper] table`` covers."""
        if self.paper_table is None:
            return {}
        published = load_paper_table(self.paper_table)
        return {
            c.case_id: published[key]
            for c in self.cases()
            if (key := (c.oncoming_start_m, c.ego_speed_kmh, c.mu)) in published
        }


def _case_fields(values: dict) -> dict:
    """A combination's values as ``Case`` fields: the equipment keys' switches as
    ``abs_fitted`` / ``esc_fitted`` (``abs_esc`` sets both)."""
    fields = {k: v for k, v in values.items() if k not in EQUIPMENT_KEYS}
    for key, switched in (("abs", ("abs_fitted",)), ("esc", ("esc_fitted",))):
        if key in values:
            fields.update(dict.fromkeys(switched, values[key]))
    if "abs_esc" in values:
        fields.update(abs_fitted=values["abs_esc"], esc_fitted=values["abs_esc"])
    return fields


def _switch_text(on: bool) -> str:
    return "on" if on else "off"


def _swept_tokens(values: dict) -> list[str]:
    """The case-id tokens of the swept equipment, policy and driver: ``abs-off``, ``esc-on``
    (both for ``abs_esc``), ``paper`` / ``safe``, ``eoam`` / ``r157-cc``."""
    tokens = []
    for key, names in (("abs", ("abs",)), ("esc", ("esc",)), ("abs_esc", ("abs", "esc"))):
        if key in values:
            tokens += [f"{name}-{_switch_text(values[key])}" for name in names]
    tokens += [values[key] for key in ("policy", "driver") if key in values]
    return tokens


def _case_id(values: dict, sampled: tuple[str, ...]) -> str:
    """A case's id from its values: the vehicle's name when the matrix names one, the swept
    equipment and policy (``abs-off_esc-off``, ``safe``), the generated scenario's keys given
    (road, ``losC``, ``l3`` lanes, ``lim100`` speed limit, ``R400`` or ``straight``),
    ``onc-...`` unless sampled, ``v...``, ``mu...``, ``hold...``, ``dec...``; "all" when
    nothing is left."""
    road_parts = {
        "road": lambda v: v,
        "los": lambda v: f"los{v}",
        "lanes": lambda v: f"l{v}",
        "speed_limit_kmh": lambda v: f"lim{_id_number(v)}",
        "curve_radius_m": lambda v: f"R{_id_number(v)}",
    }
    parts = [vehicle_name(values["vehicle"])] if values.get("vehicle") is not None else []
    parts += _swept_tokens(values)
    parts += [
        road_parts[k](values[k])
        if values[k] is not None
        else ("straight" if k == "curve_radius_m" else "")
        for k in TRAFFIC_KEYS
        if k in values and k not in sampled
    ]
    onc = values["oncoming_start_m"]
    speed, mu = values["ego_speed_kmh"], values["mu"]
    hold, decel = values["aro_hold_s"], values["aro_decel_mps2"]
    parts += [
        ""
        if "oncoming_start_m" in sampled
        else f"onc-{NO_ONCOMING if onc is None else _id_number(onc)}",
        "" if speed is None else f"v{_id_number(speed)}",
        "" if mu is None else f"mu{_mu_text(mu)}",
        "" if hold is None else f"hold{_id_number(hold)}",
        "" if decel is None else f"dec{_id_number(decel)}",
    ]
    return "_".join(p for p in parts if p) or "all"


def load_paper_table(path: Path) -> dict[tuple[float | None, float, float], str]:
    """(oncoming_start_m or None, ego_speed_kmh, mu) -> outcome, from a CSV like the paper's."""
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
            header = tuple(rows[0].keys()) if rows else ()
    except OSError as exc:
        raise InputError(f"{path}: cannot read the paper table: {exc}") from exc
    except UnicodeDecodeError as exc:
        raise not_utf8(path, exc, "paper table") from None
    missing = [c for c in PAPER_COLUMNS if c not in header]
    if missing:
        raise InputError(f"{path}: the paper table needs the column '{missing[0]}'")
    table = {}
    for line, row in enumerate(rows, start=2):
        try:
            onc = (
                None
                if row["oncoming_start_m"].strip() in ("", NO_ONCOMING)
                else float(row["oncoming_start_m"])
            )
            key = (onc, float(row["ego_speed_kmh"]), float(row["mu"]))
        except (ValueError, AttributeError) as exc:
            raise InputError(f"{path}, line {line}: not a number: {exc}") from exc
        if row["outcome"] not in OUTCOMES:
            raise InputError(
                f"{path}, line {line}: outcome {row['outcome']!r} is not one of "
                f"{', '.join(OUTCOMES)}"
            )
        table[key] = row["outcome"]
    return table


def _unknown(path: Path, where: str, key: str, valid: tuple[str, ...]) -> InputError:
    close = difflib.get_close_matches(key, valid, n=1)
    hint = f"; did you mean '{close[0]}'?" if close else f" (valid: {', '.join(valid)})"
    return InputError(f"{path}: unknown {where} '{key}'{hint}")


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _number_list(
    path: Path,
    key: str,
    values,
    *,
    minimum: float,
    inclusive: bool,
    maximum: float | None = None,
    allow_none: bool = False,
) -> tuple:
    where = f"[sweep] {key}"
    if not isinstance(values, list):
        raise InputError(f"{path}: {where} must be a list, not {values!r}")
    if not values:
        raise InputError(f"{path}: {where} is an empty list")
    out = []
    for v in values:
        if allow_none and v == NO_ONCOMING:
            item = None
        elif not _is_number(v):
            expected = f'a number or "{NO_ONCOMING}"' if allow_none else "a number"
            raise InputError(f"{path}: {where} value {v!r} is not {expected}")
        elif (v < minimum if inclusive else v <= minimum) or (maximum is not None and v > maximum):
            low = "[" if inclusive else "("
            high = f"{maximum:g}]" if maximum is not None else "inf)"
            raise InputError(f"{path}: {where} value {v!r} is outside {low}{minimum:g}, {high}")
        else:
            item = float(v)
        if item in out:
            raise InputError(f"{path}: {where} lists {v!r} twice")
        out.append(item)
    return tuple(out)


def _checked(
    minimum: float,
    inclusive: bool,
    maximum: float | None = None,
    allow_none: bool = False,
    max_inclusive: bool = True,
):
    """The check of one value of a numeric key (for sampled values)."""

    def check(value):
        if allow_none and value == NO_ONCOMING:
            return None
        if not _is_number(value):
            raise InputError("is not a number" + (f' or "{NO_ONCOMING}"' if allow_none else ""))
        if (value < minimum if inclusive else value <= minimum) or (
            maximum is not None and (value > maximum if max_inclusive else value >= maximum)
        ):
            low = "[" if inclusive else "("
            high = "inf)" if maximum is None else f"{maximum:g}" + ("]" if max_inclusive else ")")
            raise InputError(f"is outside {low}{minimum:g}, {high}")
        return float(value)

    return check


def _one_of(key: str, choices: tuple[str, ...]):
    """The check of one value of the choice ``key`` (policy, driver)."""

    def check(value) -> str:
        if value not in choices:
            raise InputError(f"{key} {value!r} is not one of {', '.join(choices)}")
        return value

    return check


def _road(value) -> str:
    if value not in ROADS:
        raise InputError(f"road {value!r} is not one of {', '.join(ROADS)}")
    return value


def _los(value) -> str:
    if value not in LEVELS:
        raise InputError(f"level of service {value!r} is not one of {', '.join(LEVELS)}")
    return value


def _lanes(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 6:
        raise InputError(f"lanes {value!r} is not a whole number 1-6")
    return value


def _curve_radius(value) -> float | None:
    if value == STRAIGHT:
        return None
    return _checked(MIN_CURVE_RADIUS_M, True)(value)


def _speed_limit(value):
    """A generated road's speed limit: up to the top speed the default tables cover."""
    return _checked(MIN_SPEED_LIMIT_KMH, True, max_speed_limit_kmh())(value)


#: The generated scenario's keys, with the check of one value of each.
TRAFFIC_CHECKS = {
    "road": _road,
    "los": _los,
    "lanes": _lanes,
    "speed_limit_kmh": _speed_limit,
    "curve_radius_m": _curve_radius,
}

#: The keys a [sample] table may draw, with the check of one value of each.
SAMPLED = {
    "ego_speed_kmh": _checked(0.0, False),
    "mu": _checked(0.0, False, MU_MAX),
    "oncoming_start_m": _checked(0.0, True, allow_none=True),
    "aro_hold_s": _checked(0.0, True),
    "aro_decel_mps2": _checked(0.0, False),
    "max_time_s": _checked(0.0, False, MAX_TIME_LIMIT_S),
    "radar_range_m": _checked(0.0, False),
    "mu_belief": parse_mu_belief,
    "radar_model": parse_radar_model,
    "policy": _one_of("policy", POLICIES),
    "driver": _one_of("driver", DRIVERS),
    **{
        key: _checked(low, True, high, max_inclusive=high_in)
        for key, (_, low, high, high_in) in V2X_KEYS.items()
    },
    "after_stop_s": _checked(0.0, True),
    **TRAFFIC_CHECKS,
}


def load_matrix(path: Path) -> Matrix:
    """Read and check an experiment-matrix TOML file; InputError names the file and the key."""
    path = Path(path)
    doc = _read_toml(path)
    _check_tables(path, doc)
    checks = {**SAMPLED, "vehicle": _vehicle_check(path)}
    sample = parse_sample(path, doc["sample"], checks) if "sample" in doc else None
    sampled = sample.keys if sample else ()
    _check_required(path, doc, sampled)
    scenario = doc.get("scenario", {})
    _check_sampled_once(path, doc, sample, sampled)
    traffic_axes = _traffic_axes(path, doc, sample)
    sumocfg = _scenario_file(path, scenario, traffic_axes)
    max_time, radar_range = _run_limits(path, scenario)
    policy = _scenario_choice(path, scenario, "policy", POLICIES)
    policies = _swept_choices(path, doc, "policy", POLICIES)
    v2x = _v2x_link(path, scenario, policy, bool(policies))
    if "v2x_range_m" in sampled and "policy" not in sampled and (policy != "safe" or policies):
        raise InputError(
            f"{path}: [sample] v2x_range_m: V2X informs the safe policy only; set "
            'policy = "safe" in [scenario] (not a [sweep] of policies)'
        )
    paper = _paper_table(path, doc, sampled)
    settings = _sensing_settings(path, scenario)
    seed = check_seed(scenario.get("seed", 0), f"{path}: [scenario] seed")
    return Matrix(
        path=path,
        sumocfg=sumocfg,
        max_time_s=max_time,
        radar_range_m=radar_range,
        **settings,
        seed=seed,
        sample=sample,
        after_stop_s=_after_stop(path, scenario),
        sumo_step_s=_sumo_step(path, scenario),
        traffic_axes=traffic_axes,
        vehicles=_vehicle_axis(path, doc, sampled, checks["vehicle"]),
        **_equipment(path, doc),
        policies=policies,
        driver=_scenario_choice(path, scenario, "driver", DRIVERS),
        drivers=_swept_choices(path, doc, "driver", DRIVERS),
        **_swept_values(path, doc.get("sweep", {}), sampled),
        paper_table=paper,
        policy=policy,
        v2x=v2x,
    )


def _paper_table(path: Path, doc: dict, sampled: tuple[str, ...]) -> Path | None:
    """[paper] table (None: not given); refused without a swept or sampled ``mu``: the
    paper's cells are per friction, and a case on the network's own has none to match."""
    if "table" not in doc.get("paper", {}):
        return None
    if "mu" not in doc.get("sweep", {}) and "mu" not in sampled:
        raise InputError(
            f"{path}: [paper] table needs [sweep] mu: the paper's cells are per friction, "
            "and without mu every case runs on the network's own lane frictions"
        )
    return _existing_file(path, "[paper] table", doc["paper"]["table"])


def _after_stop(path: Path, scenario: dict) -> float | None:
    """[scenario] after_stop_s (None: the run's default), a number >= 0."""
    value = scenario.get("after_stop_s")
    if value is not None and (not _is_number(value) or value < 0):
        raise InputError(f"{path}: [scenario] after_stop_s = {value!r} must be a number >= 0")
    return None if value is None else float(value)


def _sumo_step(path: Path, scenario: dict) -> float | None:
    """[scenario] sumo_step_s (None: the run's default), 0.01 to 0.1 s in whole 10 ms."""
    value = scenario.get("sumo_step_s")
    if value is None:
        return None
    return check_sumo_step_s(value, f"{path}: [scenario] sumo_step_s")


def _vehicle_check(path: Path):
    """The check of one ``vehicle`` value of the matrix ``path``: a catalogue name, or a
    vehicle file (relative to the matrix file), read and checked (``vehicle_files``); the
    value as a case holds it (a file: its absolute path)."""

    def check(value):
        if not isinstance(value, str) or not value.strip():
            raise InputError(f"vehicle {value!r} is not a catalogue name or a .toml file")
        vehicle = value
        if value.endswith(".toml") or len(Path(value).parts) > 1:
            vehicle = str((path.parent / value).resolve())
        load_vehicle(vehicle)
        return vehicle

    return check


def _vehicle_axis(path: Path, doc: dict, sampled: tuple[str, ...], check) -> tuple:
    """The vehicles of the matrix: [scenario] one, [sweep] a list, sampled (None,), none
    given (); each checked, no two with the same name (their case ids and tables folder)."""
    where = [t for t in ("scenario", "sweep") if "vehicle" in doc.get(t, {})]
    if len(where) > 1:
        raise InputError(f"{path}: 'vehicle' is in [scenario] and [sweep]; keep one")
    if "vehicle" in sampled:
        return (None,)
    if not where:
        return ()
    raw = doc[where[0]]["vehicle"]
    listed = raw if where[0] == "sweep" else [raw]
    if not isinstance(listed, list) or not listed:
        raise InputError(f"{path}: [sweep] vehicle must be a non-empty list")
    try:
        values = tuple(check(v) for v in listed)
    except InputError as exc:
        raise InputError(f"{path}: [{where[0]}] vehicle: {exc}") from None
    names = [vehicle_name(v) for v in values]
    twice = next((n for n in names if names.count(n) > 1), None)
    if twice is not None:
        raise InputError(f"{path}: [sweep] vehicle lists two vehicles named {twice!r}")
    return values


def _switches(path: Path, where: str, key: str, raw) -> tuple[bool, ...]:
    """The "on" / "off" values of an equipment key: [scenario] one, [sweep] a non-empty list
    of distinct values."""
    listed = raw if where == "sweep" else [raw]
    if not isinstance(listed, list) or not listed:
        raise InputError(f'{path}: [sweep] {key} must be a non-empty list of "on" / "off"')
    for value in listed:
        if not isinstance(value, str) or value not in SWITCH:
            what = f"{key} = {value!r}" if where == "scenario" else f"{key} value {value!r}"
            raise InputError(f'{path}: [{where}] {what} is not "on" or "off"')
        if listed.count(value) > 1:
            raise InputError(f"{path}: [sweep] {key} lists {value!r} twice")
    return tuple(SWITCH[v] for v in listed)


def _equipment(path: Path, doc: dict) -> dict:
    """The ``Matrix`` fields of the equipment keys (``EQUIPMENT_KEYS``): [scenario] values as
    ``abs_fitted`` / ``esc_fitted``, [sweep] lists as ``equipment`` axes."""
    fields: dict = {"abs_fitted": None, "esc_fitted": None, "equipment": ()}
    given = [k for k in EQUIPMENT_KEYS if any(k in doc.get(t, {}) for t in ("scenario", "sweep"))]
    if "abs_esc" in given and len(given) > 1:
        raise InputError(f"{path}: 'abs_esc' switches both ABS and ESC; drop '{given[0]}'")
    axes = []
    for key in given:
        where = [t for t in ("scenario", "sweep") if key in doc.get(t, {})]
        if len(where) > 1:
            raise InputError(f"{path}: '{key}' is in [scenario] and [sweep]; keep one")
        values = _switches(path, where[0], key, doc[where[0]][key])
        if where[0] == "sweep":
            axes.append((key, values))
            continue
        for name in ("abs", "esc"):
            if key in (name, "abs_esc"):
                fields[f"{name}_fitted"] = values[0]
    fields["equipment"] = tuple(axes)
    return fields


def _swept_choices(path: Path, doc: dict, key: str, choices: tuple[str, ...]) -> tuple[str, ...]:
    """[sweep] ``key`` (policy, driver): a non-empty list of distinct ``choices`` (not also in
    [scenario]); (): not swept."""
    if key not in doc.get("sweep", {}):
        return ()
    if key in doc.get("scenario", {}):
        raise InputError(f"{path}: '{key}' is in [scenario] and [sweep]; keep one")
    listed = doc["sweep"][key]
    if not isinstance(listed, list) or not listed:
        raise InputError(f"{path}: [sweep] {key} must be a non-empty list")
    for value in listed:
        if value not in choices:
            raise InputError(
                f"{path}: [sweep] {key} value {value!r} is not one of "
                f"{', '.join(repr(p) for p in choices)}"
            )
        if listed.count(value) > 1:
            raise InputError(f"{path}: [sweep] {key} lists {value!r} twice")
    return tuple(listed)


def _scenario_file(path: Path, scenario: dict, traffic_axes: tuple) -> Path | None:
    """[scenario] sumocfg, or None for a generated scenario; exactly one of the two."""
    if "sumocfg" in scenario:
        if traffic_axes:
            raise InputError(
                f"{path}: [scenario] sumocfg with the generated scenario's "
                f"'{traffic_axes[0][0]}': keep one"
            )
        return _existing_file(path, "[scenario] sumocfg", scenario["sumocfg"])
    if not traffic_axes:
        raise InputError(f"{path}: [scenario] needs the key 'sumocfg' (or a generated 'road')")
    keys = [key for key, _ in traffic_axes]
    for need in ("road", "los"):
        if need not in keys:
            raise InputError(f"{path}: '{keys[0]}' needs the key '{need}'")
    return None


def _traffic_axes(path: Path, doc: dict, sample: Sample | None) -> tuple:
    """The generated scenario's keys as (key, values): [scenario] one value, [sweep] a list
    of distinct values, sampled (None,); every combination checked as a scenario spec, a
    sampled key with every value its distribution can give at its bounds (each choice)."""
    axes, domains = [], []
    for key in TRAFFIC_KEYS:
        where = [t for t in ("scenario", "sweep") if key in doc.get(t, {})]
        if len(where) > 1:
            raise InputError(f"{path}: '{key}' is in [scenario] and [sweep]; keep one")
        dist = sample.of(key) if sample else None
        if dist is not None:
            axes.append((key, (None,)))
            domains.append((key, tuple(dict.fromkeys(dist.extremes()))))
        elif where:
            raw = doc[where[0]][key]
            listed = raw if where[0] == "sweep" else [raw]
            if not isinstance(listed, list) or not listed:
                raise InputError(f"{path}: [sweep] {key} must be a non-empty list")
            try:
                values = tuple(TRAFFIC_CHECKS[key](v) for v in listed)
            except InputError as exc:
                raise InputError(f"{path}: [{where[0]}] {key}: {exc}") from None
            twice = next((v for v, c in zip(listed, values) if values.count(c) > 1), None)
            if twice is not None:
                raise InputError(f"{path}: [sweep] {key} lists {twice!r} twice")
            axes.append((key, values))
            domains.append((key, values))
    _check_specs(path, domains, sample)
    return tuple(axes)


def _check_specs(path: Path, axes: list, sample: Sample | None = None) -> None:
    """InputError for a combination that is not a scenario (a curved motorway, a rural road
    with three lanes), naming the keys and, for a sampled key, the [sample] table."""
    keys = [key for key, _ in axes]
    for combo in itertools.product(*(values for _, values in axes)):
        values = dict(zip(keys, combo))
        if values.get("road") is None:
            continue
        try:
            TrafficSpec(
                values["road"],
                values.get("los") or "A",
                values.get("lanes"),
                values.get("speed_limit_kmh"),
                values.get("curve_radius_m"),
            ).checked()
        except InputError as exc:
            drawn = [k for k in keys if sample and sample.of(k)]
            note = f" (sampled in [sample]: {', '.join(drawn)})" if drawn else ""
            raise InputError(f"{path}: {', '.join(keys)}{note}: {exc}") from None


def _read_toml(path: Path) -> dict:
    """The matrix file's TOML document; InputError if it is missing, unreadable or malformed."""
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError as exc:
        raise InputError(f"matrix file {path} not found") from exc
    except OSError as exc:
        raise InputError(f"{path}: cannot read the matrix file: {exc}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: malformed TOML: {exc}") from exc
    except UnicodeDecodeError as exc:
        raise not_utf8(path, exc, "matrix file") from None


def _check_tables(path: Path, doc: dict) -> None:
    """InputError for a table or key the schema does not know ([sample] is checked apart)."""
    for table, body in doc.items():
        if table not in SCHEMA:
            raise _unknown(path, "table", table, tuple(SCHEMA))
        if not isinstance(body, dict):
            raise InputError(f"{path}: '{table}' must be a table ([{table}])")
        for key in body:
            if key not in SCHEMA[table] and table != "sample":
                raise _unknown(path, f"key in [{table}]", key, SCHEMA[table])


def _check_required(path: Path, doc: dict, sampled: tuple[str, ...]) -> None:
    """InputError for a missing required table (one whose every required key is sampled may
    be left out), or a required key neither given nor sampled."""
    for table, keys in REQUIRED.items():
        if table not in doc and not set(keys) <= set(sampled):
            raise InputError(f"{path}: missing table [{table}]")
        for key in keys:
            if key not in doc.get(table, {}) and key not in sampled:
                raise InputError(f"{path}: [{table}] needs the key '{key}' (or sample it)")


def _check_sampled_once(
    path: Path, doc: dict, sample: Sample | None, sampled: tuple[str, ...]
) -> None:
    """InputError for a key both given and sampled, or a fixed seed beside a [sample] table."""
    for key in sampled:
        for table in ("scenario", "sweep"):
            if key in doc.get(table, {}):
                raise InputError(
                    f"{path}: '{key}' is both in [{table}] and sampled in [sample]; keep one"
                )
    if sample is not None and "seed" in doc.get("scenario", {}):
        raise InputError(
            f"{path}: [scenario] seed with a [sample] table: the draws' seeds "
            "come from [sample] seed"
        )


def _run_limits(path: Path, scenario: dict) -> tuple[float, float | None]:
    """[scenario] max_time_s (default ``DEFAULT_MAX_TIME_S``) and radar_range_m (None: the
    radar's default), each a number > 0."""
    max_time = scenario.get("max_time_s", DEFAULT_MAX_TIME_S)
    if not _is_number(max_time) or not 0 < max_time <= MAX_TIME_LIMIT_S:
        raise InputError(
            f"{path}: [scenario] max_time_s = {max_time!r} must be a number in "
            f"(0, {MAX_TIME_LIMIT_S:g}]"
        )
    radar_range = scenario.get("radar_range_m")
    if radar_range is not None and (not _is_number(radar_range) or radar_range <= 0):
        raise InputError(f"{path}: [scenario] radar_range_m = {radar_range!r} must be a number > 0")
    return float(max_time), None if radar_range is None else float(radar_range)


def _scenario_choice(path: Path, scenario: dict, key: str, choices: tuple[str, ...]) -> str:
    """[scenario] ``key`` (policy, driver), one of ``choices`` (default: the first, the
    paper's policy and the EOAM)."""
    value = scenario.get(key, choices[0])
    if value not in choices:
        raise InputError(
            f"{path}: [scenario] {key} = {value!r} must be one of "
            f"{', '.join(repr(p) for p in choices)}"
        )
    return value


def _v2x_link(
    path: Path, scenario: dict, policy: str, swept: bool = False
) -> tuple[float, float, float, float]:
    """[scenario] V2X range, latency, loss and penetration, each within its ``V2X_KEYS``
    bounds; a range > 0 needs the safe policy (not a swept one)."""
    v2x = []
    for key, (default, low, high, high_in) in V2X_KEYS.items():
        value = scenario.get(key, default)
        if (
            not _is_number(value)
            or value < low
            or (high is not None and (value > high or (value == high and not high_in)))
        ):
            bound = f">= {low:g}" + (
                "" if high is None else f" and {'<=' if high_in else '<'} {high:g}"
            )
            raise InputError(f"{path}: [scenario] {key} = {value!r} must be a number {bound}")
        v2x.append(float(value))
    if v2x[0] > 0.0 and swept:
        raise InputError(
            f"{path}: [scenario] v2x_range_m = {v2x[0]:g} with a [sweep] policy: V2X informs "
            'the safe policy only; set v2x_range_m = 0 or policy = "safe" in [scenario]'
        )
    if v2x[0] > 0.0 and policy != "safe":
        raise InputError(
            f"{path}: [scenario] v2x_range_m = {v2x[0]:g} needs policy = "
            '"safe" (V2X informs the safe policy only)'
        )
    return (v2x[0], v2x[1], v2x[2], v2x[3])


def _sensing_settings(path: Path, scenario: dict) -> dict:
    """[scenario] mu_belief and radar_model where given, checked as a sampled value is."""
    settings = {}
    for key in ("mu_belief", "radar_model"):
        if key in scenario:
            try:
                settings[key] = SAMPLED[key](scenario[key])
            except InputError as exc:
                raise InputError(f"{path}: [scenario] {exc}") from None
    return settings


def _swept_values(path: Path, sweep: dict, sampled: tuple[str, ...]) -> dict:
    """The [sweep] lists as ``Matrix`` fields; a sampled key has the placeholder ``(None,)``."""
    return {
        "ego_speeds_kmh": (None,)
        if "ego_speed_kmh" in sampled
        else _number_list(
            path, "ego_speed_kmh", sweep["ego_speed_kmh"], minimum=0.0, inclusive=False
        ),
        "mus": (None,)
        if "mu" in sampled
        else _number_list(path, "mu", sweep["mu"], minimum=0.0, inclusive=False, maximum=MU_MAX)
        if "mu" in sweep
        else (),
        "oncoming_starts_m": (None,)
        if "oncoming_start_m" in sampled
        else _number_list(
            path,
            "oncoming_start_m",
            sweep.get("oncoming_start_m", [NO_ONCOMING]),
            minimum=0.0,
            inclusive=True,
            allow_none=True,
        ),
        "aro_holds_s": (
            _number_list(path, "aro_hold_s", sweep["aro_hold_s"], minimum=0.0, inclusive=True)
            if "aro_hold_s" in sweep
            else ()
        ),
        "aro_decels_mps2": (
            _number_list(
                path, "aro_decel_mps2", sweep["aro_decel_mps2"], minimum=0.0, inclusive=False
            )
            if "aro_decel_mps2" in sweep
            else ()
        ),
    }


def check_matrix(matrix: Matrix, tables_dir: Path | None = None, ego_id: str = "ego") -> None:
    """Check the matrix against what its runs will use, before any of them starts.

    The scenario's ``.sumocfg``, network, route and additional files must parse and hold the
    vehicle ``ego_id`` (``sim.scenario.check_scenario``, no SUMO started); every swept
    speed and friction must be one the lookup tables in ``tables_dir`` (default: the folder
    the co-simulation uses, ``$EOAM_TABLES_DIR`` or the repository's ``tables/``) cover, by
    the same ``LookupTables.check_run`` each run applies; without ``mu`` (each lane's own
    friction) the frictions of the lanes the ego may depart on (``start_frictions``), as a
    run checks the one under the ego. InputError names the matrix file, the key and the value.
    """
    if matrix.sumocfg is None:  # generated per case: nothing to read yet
        _check_generated_oncoming(matrix)
        _check_vehicles_tables(matrix, tables_dir)
        return
    try:
        files = check_scenario(matrix.sumocfg, ego_id)
        holds = matrix.aro_holds_s or _extremes(matrix, "aro_hold_s") or (None,)
        decels = matrix.aro_decels_mps2 or _extremes(matrix, "aro_decel_mps2") or (None,)
        for hold in holds:  # the ARO's stop profile fits the scenario
            for decel in decels:
                over = ScenarioOverrides(aro_hold_s=hold, aro_decel_mps2=decel)
                scripted_stops(files, over, ego_id)
    except InputError as exc:
        raise InputError(f"{matrix.path}: [scenario] sumocfg: {exc}") from exc
    _check_oncoming_road(matrix, files, ego_id)
    own = not matrix.mus and not _extremes(matrix, "mu")
    lanes = StartFrictions(files.net_file, start_frictions(files, ego_id)) if own else None
    _check_vehicles_tables(matrix, tables_dir, lanes)


@dataclass(frozen=True)
class StartFrictions:
    """The network's own frictions a matrix without ``mu`` starts its cases on: (lane id,
    friction) of each lane of ``net_file`` the ego may depart on."""

    net_file: Path
    lanes: tuple[tuple[str, float], ...]


def start_frictions(files: ScenarioFiles, ego_id: str = "ego") -> tuple[tuple[str, float], ...]:
    """(lane id, friction) of each lane the ego may depart on, as its network writes them
    (``ScenarioFiles.edge_lanes``): its ``departLane`` on its first route edge (a trip's
    ``from``); every lane of that edge when the lane is no number (``free``, ...); every lane
    of the network when the edge is not known before SUMO routes the ego."""
    spec = files.vehicles[ego_id]
    route = ego_route_edges(files, ego_id)
    edge = route[0] if route else spec.attrs.get("from")
    lane = spec.attrs.get("departLane", "")
    edges = files.edge_lanes.values() if edge is None else [files.edge_lanes.get(edge, [])]
    return tuple(
        (lane_id, mu)
        for lanes in edges
        for lane_id, index, mu in lanes
        if not lane.isdigit() or index == int(lane)
    )


def _check_generated_oncoming(matrix: Matrix) -> None:
    """An oncoming start on a generated motorway (one carriageway each way, apart: no lane
    of the other direction beside the ego's) is refused before any case runs."""
    for case in matrix.cases():
        if case.road == "motorway" and case.oncoming_start_m is not None:
            raise InputError(
                f"{matrix.path}: oncoming_start_m = {case.oncoming_start_m:g} on a generated "
                "motorway: its carriageways are apart, no lane of the other direction lies "
                'beside the ego\'s (oncoming traffic needs road = "rural")'
            )


def _check_oncoming_road(matrix: Matrix, files: ScenarioFiles, ego_id: str) -> None:
    """An oncoming start (swept or sampled) only on a road with a lane of the other
    direction beside the ego's route (``check_oncoming_road``), once per scenario file."""
    starts = (*matrix.oncoming_starts_m, *_extremes(matrix, "oncoming_start_m"))
    asked = [d for d in starts if d is not None]
    if not asked:
        return
    try:
        check_oncoming_road(files, ego_id)
    except InputError as exc:
        raise InputError(f"{matrix.path}: oncoming_start_m = {asked[0]:g}: {exc}") from exc


def _check_vehicles_tables(
    matrix: Matrix, tables_dir: Path | None, lanes: StartFrictions | None = None
) -> None:
    """Every vehicle of the matrix (swept, or any its sample may choose; none named: the
    sedan) has its lookup tables under ``tables_dir`` (``sim.vehicle.vehicle_tables_dir``),
    built for its parameters, covering every speed and friction of the matrix (``lanes``:
    the network's, without ``mu``)."""
    dist = matrix.sample.of("vehicle") if matrix.sample else None
    named = {v for v in (*matrix.vehicles, *(dist.extremes() if dist else ())) if v is not None}
    switches = itertools.product(_switched(matrix, "abs"), _switched(matrix, "esc"))
    for vehicle, (abs_fitted, esc_fitted) in itertools.product(sorted(named) or [None], switches):
        params = vehicle_params(vehicle, abs_fitted, esc_fitted)
        name = vehicle or DEFAULT_VEHICLE
        try:
            tables = vehicle_tables(name, params, tables_dir, cached=False)
        except InputError as exc:
            if vehicle is None and abs_fitted is None:
                raise
            raise InputError(f"{matrix.path}: vehicle {name!r}: {exc}") from None
        check_within_tables(matrix, tables, vehicle_tables_dir(name, tables_dir, params), lanes)


def _switched(matrix: Matrix, system: str) -> tuple[bool | None, ...]:
    """The values ``abs`` or ``esc`` (``system``) takes in the matrix's cases (None: the
    vehicle's own)."""
    for key, values in matrix.equipment:
        if key in (system, "abs_esc"):
            return values
    return (matrix.abs_fitted if system == "abs" else matrix.esc_fitted,)


def vehicle_params(
    vehicle: str | None, abs_fitted: bool | None = None, esc_fitted: bool | None = None
) -> VehicleParams:
    """The ego a case runs: ``vehicle`` (None: the paper's sedan), its ABS and ESC switched
    where given (None: the vehicle's own)."""
    params = ego_e_class_sedan() if vehicle is None else load_vehicle(vehicle)
    if abs_fitted is not None:
        params = replace(params, abs_fitted=abs_fitted)
    if esc_fitted is not None:
        params = replace(params, esc_fitted=esc_fitted)
    return params


def check_within_tables(
    matrix: Matrix, tables, folder: Path | str | None = None, lanes: StartFrictions | None = None
) -> None:
    """InputError for the first swept speed or friction ``tables.check_run`` refuses, then
    for the first of the network's own frictions ``lanes`` (a matrix without ``mu``).

    Speeds are checked at the tables' highest friction and frictions at their lowest speed,
    so the error names the key at fault (``check_run`` refuses speeds above the grid and
    frictions below it).
    """
    beliefs = (matrix.mu_belief, *_extremes(matrix, "mu_belief"))
    for key, values, check in (
        (
            "ego_speed_kmh",
            (*matrix.ego_speeds_kmh, *_extremes(matrix, "ego_speed_kmh")),
            lambda v: tables.check_run(tables.mu_grid[-1], v / 3.6),
        ),
        (
            "mu",
            (*matrix.mus, *_extremes(matrix, "mu")),
            lambda m: tables.check_run(m, tables.speed_grid_mps[0]),
        ),
        (
            "mu_belief",
            tuple(b for b in beliefs if isinstance(b, float)),
            lambda m: tables.check_run(m, tables.speed_grid_mps[0]),
        ),
    ):
        for value in values:
            if value is None:  # the placeholder of a sampled key
                continue
            try:
                check(value)
            except InputError as exc:
                where = "" if folder is None else f" in {folder}"
                table = "[scenario]" if key == "mu_belief" else "[sweep]"
                if matrix.sample and matrix.sample.of(key):
                    table = "[sample]"
                raise InputError(
                    f"{matrix.path}: {table} {key} value {value:g} is outside the lookup "
                    f"tables{where}: {exc}"
                ) from exc
    if lanes is not None:
        _check_start_frictions(matrix, tables, folder, lanes)


def _check_start_frictions(matrix: Matrix, tables, folder, lanes: StartFrictions) -> None:
    """InputError for the first of the network's own frictions where the ego departs that
    ``tables.check_run`` refuses (a matrix without ``mu``)."""
    for lane, mu in lanes.lanes:
        try:
            tables.check_run(mu, tables.speed_grid_mps[0])
        except InputError as exc:
            where = "" if folder is None else f" in {folder}"
            raise InputError(
                f"{matrix.path}: no mu in [sweep], so the cases run on the network's own "
                f"frictions, and lane '{lane}' of {lanes.net_file} (where the ego departs) has "
                f"friction {mu:g}, outside the lookup tables{where}: {exc}"
            ) from exc


def _extremes(matrix: Matrix, key: str) -> tuple:
    """The values at the bounds of a sampled key's distribution (none if not sampled)."""
    dist = matrix.sample.of(key) if matrix.sample else None
    return dist.extremes() if dist else ()


def _existing_file(path: Path, where: str, value) -> Path:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{path}: {where} = {value!r} must be a file name (a string)")
    resolved = (path.parent / value).resolve()
    if resolved.is_dir():
        raise InputError(f"{path}: {where} = {value!r}: {resolved} is a folder, not a file")
    if not resolved.is_file():
        raise InputError(f"{path}: {where} = {value!r}: file {resolved} not found")
    return resolved
