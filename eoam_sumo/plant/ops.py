"""The arithmetic the plant model is written against, for plain floats and for CasADi.

The model (``model.py``) never calls ``math`` or ``casadi`` directly: it receives an ``ops``
object with the functions below, so one source text is evaluated both as a CasADi SX/MX
expression (compiled online path, offline optimiser) and with Python floats (reference).
The float versions mirror CasADi's C semantics (``casadi_sign``, ``fmin``, ``fmax`` and
``if_else`` evaluating both branches) so the two agree to rounding.
"""

from __future__ import annotations

import math

import casadi


def _float_sign(x: float) -> float:
    """``casadi_sign``: -1, +1, or ``x`` itself for a zero."""
    return -1.0 if x < 0.0 else (1.0 if x > 0.0 else x)


def _float_fmin(a: float, b: float) -> float:
    return min(b, a)


def _float_fmax(a: float, b: float) -> float:
    return max(b, a)


def _float_if_else(cond, if_true: float, if_false: float) -> float:
    return if_true if cond else if_false


class FloatOps:
    """Plain Python floats (``math``), used by the reference plant."""

    sin = staticmethod(math.sin)
    cos = staticmethod(math.cos)
    atan = staticmethod(math.atan)
    exp = staticmethod(math.exp)
    sqrt = staticmethod(math.sqrt)
    fabs = staticmethod(math.fabs)
    sign = staticmethod(_float_sign)
    fmin = staticmethod(_float_fmin)
    fmax = staticmethod(_float_fmax)
    if_else = staticmethod(_float_if_else)


class CasadiOps:
    """CasADi symbolic arithmetic (works for SX, MX and DM)."""

    sin = staticmethod(casadi.sin)
    cos = staticmethod(casadi.cos)
    atan = staticmethod(casadi.atan)
    exp = staticmethod(casadi.exp)
    sqrt = staticmethod(casadi.sqrt)
    fabs = staticmethod(casadi.fabs)
    sign = staticmethod(casadi.sign)
    fmin = staticmethod(casadi.fmin)
    fmax = staticmethod(casadi.fmax)
    if_else = staticmethod(casadi.if_else)


FLOAT_OPS = FloatOps()
CASADI_OPS = CasadiOps()
