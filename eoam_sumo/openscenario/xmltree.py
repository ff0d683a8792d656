"""A small XML tree that keeps each element's file and line (for one-line refusals).

The standard library's ElementTree drops line numbers; expat reports them, so the tree is
built from expat's events.
"""

from __future__ import annotations

import contextlib
import math
import xml.parsers.expat
from dataclasses import dataclass, field
from pathlib import Path

from eoam_sumo.errors import InputError


@dataclass
class Node:
    """One element: tag, attributes, children, and where it was read."""

    tag: str
    attrib: dict[str, str]
    file: Path
    line: int
    children: list[Node] = field(default_factory=list)
    via: str = ""  # the catalog reference this node was expanded from, if any
    scope: dict[str, str] | None = None  # a ParameterCondition's parameters in scope

    def parameters(self, top: dict[str, str]) -> dict[str, str]:
        """The parameters in scope at this node (``top``: the scenario's, when not kept)."""
        return top if self.scope is None else self.scope

    def where(self) -> str:
        """``<Tag> at FILE:LINE`` for messages (and the reference that brought it in)."""
        return f"<{self.tag}> at {self.file}:{self.line}{self.via}"

    def find(self, tag: str) -> Node | None:
        """The first child with ``tag``."""
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list[Node]:
        """Every child with ``tag``."""
        return [c for c in self.children if c.tag == tag]

    def iter(self):
        """This node and every descendant, in document order."""
        yield self
        for child in self.children:
            yield from child.iter()

    def get(self, key: str, default: str | None = None) -> str | None:
        """An attribute's value."""
        return self.attrib.get(key, default)

    def num(self, key: str, default: float | None = None) -> float:
        """A numeric attribute (``default`` when absent, required without one); InputError
        naming the element when it is not a number."""
        if key not in self.attrib and default is not None:
            return default
        return _number(self, key, self.need(key))

    def need(self, key: str) -> str:
        """A required attribute, InputError naming the element when missing."""
        if key not in self.attrib:
            raise InputError(f"{self.where()}: attribute {key!r} is missing")
        return self.attrib[key]


def _number(node: Node, key: str, text: str) -> float:
    """A finite number (Python's float() also reads "nan" and "inf": refused here)."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{node.where()}: {key}={text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{node.where()}: {key}={text!r} is not a finite number")
    return value


def parse(path: Path) -> Node:
    """The file's root node; InputError naming the file and line on malformed XML."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from exc
    parser = xml.parsers.expat.ParserCreate()
    stack: list[Node] = []
    roots: list[Node] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        node = Node(tag, dict(attrib), Path(path), parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(node)
        stack.append(node)

    def end(tag: str) -> None:
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as exc:
        raise InputError(f"{path}:{exc.lineno}: not well-formed XML: {exc}") from exc
    return roots[0]


def root_tag(path: Path, limit: int = 65536) -> str | None:
    """The tag of the file's root element (read from its first ``limit`` bytes), None when
    the file cannot be read or does not start as XML (a TOML matrix, a binary file)."""
    try:
        with Path(path).open("rb") as fh:
            data = fh.read(limit)
    except OSError:
        return None
    found: list[str] = []
    parser = xml.parsers.expat.ParserCreate()

    def start(tag: str, attrib: dict[str, str]) -> None:
        found.append(tag)
        raise StopIteration  # the root is all that is wanted

    parser.StartElementHandler = start
    with contextlib.suppress(StopIteration, xml.parsers.expat.ExpatError):
        parser.Parse(data, False)
    return found[0] if found else None
