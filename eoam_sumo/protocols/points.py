"""The test points of each protocol: grids, target motion, lateral position and gap. Pure.

Grids and set-up from Vector's OpenSCENARIO encodings of the Euro NCAP protocols,
github.com/vectorgrp/OSC-NCAP-scenarios (MPL-2.0), commit ee7aa11 (``VECTOR``):

- 2023 (AEB C2C test protocol 4.3.1): ``AEB_C2C_2023/Variations/NCAP_AEB_C2C_*_Variation_2023``:
  CCRs 10-50 km/h in 5 km/h steps (AEB) and 55-80 km/h (``CCRs_FCW``); CCRm 30-80 km/h in
  5 km/h steps behind a target at 20 km/h; overlaps -75, -50, 50, 75, 100 %; CCRb both at
  50 km/h, 12 or 40 m apart, the target braking at 2 or 6 m/s^2 after 3 s
  (``GVT_braking_delay``), 100 % overlap. The target offset for an overlap
  (``NCAP_AEB_C2C_CCR_2023.xosc`` ``_GVT_offset``): sign(o) min(1, 100 - o)
  (w_gvt / 2 - w_vut (|o| - 50) / 100).
- 2026 (Crash Avoidance - Frontal Collisions): ``CA-FC_2026/Variations/{Standard,Extended}Range``:
  impact locations 0-100 % (standard) and -25, 125 % (extended); CCRs 10-80 km/h in 10 km/h
  steps (60-80 from ``CCRs_FCW``); CCRm 30-80 km/h behind 20 km/h and 90/30 to 130/70;
  CCRb 30-130 km/h, both cars at one speed, 1 s headway, 4 m/s^2 after 3 s
  (``Target_braking_delay``), 90-130 km/h extended; CCFhos 30-100 km/h. Target offset
  (``CCRs.xosc`` ``_Target_offset``): IL / 100 w_vut - w_vut / 2. Ranges as RATING_2026
  ``EXTENDED_RANGE_CELLS``: first and last column, CCRb rows from 90 km/h, CCFhos and CCFhol
  100 % and rows from 90 km/h.
- 2026 CCFhol: RATING_2026 ``data_model.py`` gives its matrix CCFhos's shape (``MATRIX_INDICES``
  8 rows x 4 impact locations, the same ``EXTENDED_RANGE_CELLS``, weights and robustness
  rows); the row speeds sit in the template workbook, not held, and Vector's 2026 set has no
  CCFhol: we take CCFhos's rows (ours). The set-up is Vector's 2023 CCFhol
  (``AEB_C2C_2023/NCAP_AEB_C2C_CCFhol_2023.xosc``): the target oncoming ``GVT_latDist``
  O = 3.5 m to the left of its end position, changing lanes along the catalogue path
  (``lane_change.py``) into the VUT's lane to end at the impact location's offset at a TTC of
  ``GVT_laneChangeTTC`` 1.5 s, ``startupTime`` 8 s of closing before the lane change begins;
  an obstruction vehicle (``NCAP_ObstructionVehicle_Large``, 4.418 m x 1.82 m) drives ahead of
  it in its lane at its speed, ``GVT_followingDistance`` F bumper to bumper (13.9 m at 50,
  19.4 m at 70 km/h: 1 s of the target's speed, which we keep at 90 and 100 km/h).
- The initial gap of a CCR test: ``Ego_initTimeHeadway`` 5 s times the VUT speed (VECTOR
  ``CCRs.xosc``); a head-on test: ``startupTime`` 8 s times the closing speed (VECTOR
  ``CA-FC_2026/CCFhos.xosc`` ``_Target_initDist``).
- UN R152 rows: the relative speeds of the M1 table of para. 5.2.1.4 (10-60 km/h, ``R152``
  in rules.py) against a stationary target, and those a target at 20 km/h allows within the
  subject speed range of para. 5.2.1.3 (10-40 km/h, subject 30-60 km/h); target centred.

The target is the Global Vehicle Target, 4.023 m x 1.712 m (VECTOR
``Catalogs/Vehicles/Vehicles.xosc`` ``NCAP_GlobalVehicleTarget``).
"""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.protocols import lane_change
from eoam_sumo.protocols.rules import R152_LIMITS_KMH, R152_MOVING_TARGET_KMH

VECTOR = "vectorgrp/OSC-NCAP-scenarios@ee7aa11"
GVT_LENGTH_M = 4.023
GVT_WIDTH_M = 1.712
INIT_HEADWAY_S = 5.0
#: CCFhos: the target starts this long of closing apart (VECTOR ``startupTime``) [s]
HEAD_ON_STARTUP_S = 8.0
BRAKING_DELAY_S = 3.0
#: CCFhol (VECTOR 2023): the lateral distance O [m], the TTC at the lane change's end [s], the
#: obstruction vehicle's headway behind which the target pulls out [s] and its size [m]
HOL_SHIFT_M = 3.5
HOL_END_TTC_S = 1.5
HOL_SOV_HEADWAY_S = 1.0
SOV_LENGTH_M = 4.418
SOV_WIDTH_M = 1.82
#: hold time of a target that keeps its speed to the end of the run [s]
FOREVER_S = 1.0e6

PROTOCOLS = ("euroncap-aeb-c2c-2023", "euroncap-aeb-c2c-2026", "unr152")


@dataclass(frozen=True)
class TestPoint:
    """One test point: the protocol's parameters and the target's scripted motion."""

    protocol: str
    test: str  # CCRs, CCRm, CCRb, CCFhos, CCFhol, R152-stationary, R152-moving
    ego_speed_kmh: float
    target_speed_kmh: float
    overlap: float  # % (2023: overlap; 2026: impact location; R152: 100)
    gap_m: float  # front bumper to the target's rear (head-on: front) bumper
    target_decel_mps2: float  # 0: no braking
    hold_s: float  # the target keeps its speed this long before braking
    offset_m: float  # target centre left (+) of the ego lane centre
    extended: bool = False
    head_on: bool = False
    lane_change: bool = False  # CCFhol: the target changes lanes into the VUT's (lane_change.py)

    @property
    def point_id(self) -> str:
        parts = [
            self.test,
            f"v{self.ego_speed_kmh:g}",
            f"t{self.target_speed_kmh:g}",
            f"o{self.overlap:g}",
            f"g{self.gap_m:.1f}",
        ]
        if self.target_decel_mps2:
            parts.append(f"d{self.target_decel_mps2:g}")
        return "_".join(parts).replace("-", "m").replace(".", "p")


def offset_2023_m(overlap: float, vut_width_m: float) -> float:
    """Target offset of a 2023 overlap (VECTOR ``_GVT_offset``)."""
    sign = 1.0 if overlap > 0 else -1.0
    return (
        sign
        * min(1.0, 100.0 - overlap)
        * (GVT_WIDTH_M / 2 - vut_width_m * (abs(overlap) - 50) / 100)
    )


def offset_2026_m(impact_location: float, vut_width_m: float) -> float:
    """Target offset of a 2026 impact location (VECTOR ``_Target_offset``)."""
    return impact_location / 100.0 * vut_width_m - vut_width_m / 2.0


def _ccr(
    protocol: str, test: str, ego: float, target: float, overlap: float, width: float, **kw
) -> TestPoint:
    """A car-to-car rear point; the gap is 5 s at the VUT speed unless given."""
    new = protocol.endswith("2026")
    offset = offset_2026_m(overlap, width) if new else offset_2023_m(overlap, width)
    gap = kw.pop("gap_m", INIT_HEADWAY_S * ego / 3.6)
    return TestPoint(
        protocol,
        test,
        float(ego),
        float(target),
        float(overlap),
        round(gap, 3),
        kw.pop("decel", 0.0),
        kw.pop("hold_s", FOREVER_S),
        round(offset, 4),
        **kw,
    )


def points_2023(width: float) -> list[TestPoint]:
    """AEB C2C 2023 (protocol 4.3.1): CCRs, CCRm, CCRb, CCFhos and CCFhol as VECTOR encodes
    them."""
    p, overlaps = PROTOCOLS[0], (-75, -50, 50, 75, 100)
    out = [_ccr(p, "CCRs", v, 0, o, width) for v in range(10, 85, 5) for o in overlaps]
    out += [_ccr(p, "CCRm", v, 20, o, width) for v in range(30, 85, 5) for o in overlaps]
    out += [
        _ccr(p, "CCRb", 50, 50, 100, width, gap_m=g, decel=d, hold_s=BRAKING_DELAY_S)
        for g in (12.0, 40.0)
        for d in (2.0, 6.0)
    ]
    return out + head_on_2023()


IL_2026 = (-25, 0, 25, 50, 75, 100, 125)
CCRM_2026: tuple[tuple[int, int], ...] = (
    *((v, 20) for v in range(30, 90, 10)),
    *((90, 30), (100, 40), (110, 50), (120, 60), (130, 70)),
)
CCFHOS_2026 = ((30, 50), (40, 50), (50, 50), (60, 70), (70, 70), (80, 70), (90, 90), (100, 100))


def points_2026(width: float) -> list[TestPoint]:
    """Crash Avoidance FC 2026: CCRs, CCRm, CCRb, CCFhos and CCFhol, standard and extended
    grids."""
    p = PROTOCOLS[1]

    def edge(il: float) -> bool:
        return il in (-25, 125)

    out = [
        _ccr(p, "CCRs", v, 0, il, width, extended=edge(il))
        for v in range(10, 90, 10)
        for il in IL_2026
    ]
    out += [
        _ccr(p, "CCRm", v, t, il, width, extended=edge(il)) for v, t in CCRM_2026 for il in IL_2026
    ]
    out += [
        _ccr(
            p,
            "CCRb",
            v,
            v,
            il,
            width,
            gap_m=1.0 * v / 3.6,
            decel=4.0,
            hold_s=BRAKING_DELAY_S,
            extended=edge(il) or v >= 90,
        )
        for v in range(30, 140, 10)
        for il in IL_2026
    ]
    return out + head_on_2026(width) + head_on_lane_change_2026(width)


def _head_on(protocol: str, test: str, v: float, t: float, il: float, offset_m: float) -> TestPoint:
    """A head-on point: CCFhos 8 s of closing apart, CCFhol ``lane_change_gap_m``; 2026:
    extended at 100 % and from 90 km/h."""
    hol = test == "CCFhol"
    gap = lane_change_gap_m(v, t) if hol else HEAD_ON_STARTUP_S * (v + t) / 3.6
    return TestPoint(
        protocol,
        test,
        float(v),
        float(t),
        float(il),
        round(gap, 3),
        0.0,
        FOREVER_S,
        round(offset_m, 4),
        extended=protocol == PROTOCOLS[1] and (il == 100 or v >= 90),
        head_on=True,
        lane_change=hol,
    )


def head_on_2026(width: float) -> list[TestPoint]:
    """CCFhos: the target drives towards the VUT in its lane (impact locations 25-100 %)."""
    return [
        _head_on(PROTOCOLS[1], "CCFhos", v, t, il, offset_2026_m(il, width))
        for v, t in CCFHOS_2026
        for il in (100, 75, 50, 25)
    ]


def lane_change_gap_m(ego_kmh: float, target_kmh: float) -> float:
    """CCFhol's initial front-to-front distance: 8 s of closing, the lane change (the VUT
    covers its duration, the target its extent) and the 1.5 s TTC left at its end (VECTOR
    ``_GVT_initS``, measured front to front; Vector's own sync points differ by the VUT's
    front overhang)."""
    ve, vt = ego_kmh / 3.6, target_kmh / 3.6
    duration = lane_change.path_length_m(target_kmh) / vt
    return (
        (HEAD_ON_STARTUP_S + HOL_END_TTC_S) * (ve + vt)
        + ve * duration
        + lane_change.path_extent_m(target_kmh)
    )


def head_on_lane_change_2026(width: float) -> list[TestPoint]:
    """CCFhol: the oncoming target pulls out from behind an obstruction vehicle into the VUT's
    lane, ending at the impact location's offset (CCFhos's grid: module docstring)."""
    return [
        _head_on(PROTOCOLS[1], "CCFhol", v, t, il, offset_2026_m(il, width))
        for v, t in CCFHOS_2026
        for il in (100, 75, 50, 25)
    ]


def head_on_2023() -> list[TestPoint]:
    """2023 CCFhos and CCFhol (VECTOR ``NCAP_AEB_C2C_CCFho{s,l}_Variation_2023``): both cars
    at 50 or 70 km/h, the target centred (``dt`` 0; the lane change ends on the VUT's lane
    centre), overlap 100 %."""
    return [
        _head_on(PROTOCOLS[0], test, v, v, 100, 0.0)
        for test in ("CCFhos", "CCFhol")
        for v in (50, 70)
    ]


def points_r152() -> list[TestPoint]:
    """UN R152 M1 rows: every relative speed of the table (``rules.R152_LIMITS_KMH``), the
    target stationary or at ``R152_MOVING_TARGET_KMH``."""
    out = []
    for target, rel in R152_LIMITS_KMH:
        tgt = 0.0 if target == "stationary" else R152_MOVING_TARGET_KMH
        out.append(_ccr(PROTOCOLS[2], f"R152-{target}", rel + tgt, tgt, 100, 0.0))
    return out


def protocol_points(name: str, vut_width_m: float) -> list[TestPoint]:
    """Every test point of a protocol, in grid order; ValueError for an unknown name."""
    if name == PROTOCOLS[0]:
        return points_2023(vut_width_m)
    if name == PROTOCOLS[1]:
        return points_2026(vut_width_m)
    if name == PROTOCOLS[2]:
        return points_r152()
    raise ValueError(f"unknown protocol {name!r}; one of {', '.join(PROTOCOLS)}")
