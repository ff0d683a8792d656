"""Checking numbers given by the user: one InputError naming the value."""

from __future__ import annotations

import math

from eoam_sumo.errors import InputError


def number(
    name: str, value, *, minimum: float, inclusive: bool = True, maximum: float | None = None
) -> float:
    """``value`` as a float; InputError naming ``name`` unless it is a finite number in range."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (value >= minimum if inclusive else value > minimum)
    ok = ok and (maximum is None or value <= maximum)
    if not ok:
        bound = f"{'>=' if inclusive else '>'} {minimum:g}"
        if maximum is not None:
            bound += f" and <= {maximum:g}"
        raise InputError(f"{name}={value!r} must be a finite number {bound}")
    return float(value)
