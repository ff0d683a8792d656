"""OpenSCENARIO 1.2 parameter references ``$name`` and expressions ``${...}`` (sec. 8.4).

Expressions are evaluated by walking Python's syntax tree over a fixed set of node types
(numbers, names, + - * / % **, unary minus, not/and/or, and the 1.2 functions round floor
ceil sqrt pow sin cos tan asin acos atan abs sign min max), never by
``eval``: anything else is refused with the expression in the message.
"""

from __future__ import annotations

import ast
import math
import operator
import re
from collections.abc import Callable

NAME_RE = re.compile(r"\$([A-Za-z_][A-Za-z0-9_]*)")
_BINARY = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Mod: math.fmod,
    ast.Pow: operator.pow,
}
_FUNCTIONS: dict[str, Callable[..., float]] = {
    "round": lambda x: float(math.floor(x + 0.5)),
    "floor": lambda x: float(math.floor(x)),
    "ceil": lambda x: float(math.ceil(x)),
    "sqrt": math.sqrt,
    "pow": math.pow,
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "asin": math.asin,
    "acos": math.acos,
    "atan": math.atan,
    "abs": abs,
    "sign": lambda x: float((x > 0) - (x < 0)),
    "min": min,
    "max": max,
}


class ExpressionError(ValueError):
    """An expression that is not OpenSCENARIO's, or names an undeclared parameter."""


def number(text: str) -> float | bool:
    """A parameter's value as an expression operand: true/false or a number."""
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        value = float(text)
    except ValueError as exc:
        raise ExpressionError(f"{text!r} is not a number") from exc
    if not math.isfinite(value):
        raise ExpressionError(f"{text!r} is not a finite number")
    return value


def evaluate(expr: str, values: dict[str, str]) -> float | bool:
    """The value of ``expr`` (the text inside ``${}``), ``$name`` read from ``values``."""
    for name in NAME_RE.findall(expr):
        if name not in values:
            raise ExpressionError(f"${name} is not declared")
    text = NAME_RE.sub(r"\1", expr).replace("&&", " and ").replace("||", " or ")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"${{{expr}}} is not an expression") from exc
    value = _walk(tree.body, values, expr)
    if not math.isfinite(value):
        raise ExpressionError(f"${{{expr}}} is {value}, not a finite number")
    return value


def _walk(node: ast.AST, values: dict[str, str], expr: str) -> float | bool:
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
        return float(node.value)
    if isinstance(node, ast.Name):
        if node.id in values:
            return number(values[node.id])
        if node.id in ("true", "false"):
            return node.id == "true"
        if node.id == "pi":  # esmini's constant, used in Vector's environment catalog
            return math.pi
        raise ExpressionError(f"${{{expr}}}: {node.id!r} is not declared")
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        left, right = _walk(node.left, values, expr), _walk(node.right, values, expr)
        try:
            return float(_BINARY[type(node.op)](left, right))
        except OverflowError:
            raise ExpressionError(f"${{{expr}}}: the result is too large") from None
        except (ZeroDivisionError, ValueError) as exc:
            raise ExpressionError(f"${{{expr}}}: {exc}") from exc
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return -_walk(node.operand, values, expr)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        return not _walk(node.operand, values, expr)
    if isinstance(node, ast.BoolOp):
        parts = [bool(_walk(v, values, expr)) for v in node.values]
        return all(parts) if isinstance(node.op, ast.And) else any(parts)
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in _FUNCTIONS
        and not node.keywords
    ):
        args = [float(_walk(a, values, expr)) for a in node.args]
        try:
            return float(_FUNCTIONS[node.func.id](*args))
        except OverflowError:
            raise ExpressionError(f"${{{expr}}}: the result is too large") from None
        except (TypeError, ValueError) as exc:
            raise ExpressionError(f"${{{expr}}}: {exc}") from exc
    raise ExpressionError(f"${{{expr}}}: {ast.unparse(node)!r} is not allowed in an expression")


def format_value(value: float | bool) -> str:
    """An evaluated value written back as an attribute's text."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(float(value))


def substitute(text: str, values: dict[str, str]) -> str:
    """An attribute's text with ``$name`` or ``${expr}`` resolved (other text unchanged)."""
    stripped = text.strip()
    if stripped.startswith("${") and stripped.endswith("}"):
        return format_value(evaluate(stripped[2:-1], values))
    if stripped.startswith("$"):
        name = stripped[1:]
        if name not in values:
            raise ExpressionError(f"${name} is not declared")
        return values[name]
    return text
