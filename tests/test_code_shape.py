"""The code reads like its design: no function of the package longer than 60 lines, the
docstring aside (the project's rule; ruff format, checked by make lint, lays the lines out)."""

from __future__ import annotations

import ast
from pathlib import Path

import eoam_sumo

PACKAGE = Path(eoam_sumo.__file__).resolve().parent
MAX_LINES = 60


def _docstring_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    first = node.body[0]
    is_docstring = (
        isinstance(first, ast.Expr)
        and isinstance(first.value, ast.Constant)
        and isinstance(first.value.value, str)
    )
    if is_docstring and first.end_lineno is not None:
        return first.end_lineno - first.lineno + 1
    return 0


def function_lengths(source: str) -> list[tuple[str, int, int]]:
    """``(name, first line, lines without the docstring)`` of every function in ``source``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.end_lineno:
            length = node.end_lineno - node.lineno + 1 - _docstring_lines(node)
            found.append((node.name, node.lineno, length))
    return found


def test_no_function_is_longer_than_60_lines():
    long = [
        f"{path.relative_to(PACKAGE.parent)}:{line} {name} ({length} lines)"
        for path in sorted(PACKAGE.rglob("*.py"))
        for name, line, length in function_lengths(path.read_text(encoding="utf-8"))
        if length > MAX_LINES
    ]
    assert long == []


def test_the_length_counts_the_body_without_the_docstring():
    source = 'def f():\n    """Doc.\n\n    More.\n    """\n    a = 1\n    return a\n'
    assert function_lengths(source) == [("f", 1, 3)]
    nested = "def g():\n    def h():\n        return 1\n    return h\n"
    assert sorted(function_lengths(nested)) == [("g", 1, 4), ("h", 2, 2)]
