"""The documentation stands alone: a short README that links every page of docs/, and no
text in the repository that points at files outside it."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
OUTSIDE = re.compile(r"design\.md|\.\./shared|/work/|\bissue \d+|\bissues? #\d+", re.IGNORECASE)


def _tracked_text_files() -> list[Path]:
    try:
        listed = subprocess.run(
            ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    suffixes = {".py", ".md", ".toml", ".xml", ".cfg", ".sumocfg", ".txt", ""}
    return [
        ROOT / name for name in listed if Path(name).suffix in suffixes and (ROOT / name).is_file()
    ]


def test_readme_is_short():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 200


def test_readme_links_every_docs_page_and_every_link_resolves():
    text = README.read_text(encoding="utf-8")
    links = set(re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text))
    local = {link for link in links if not re.match(r"[a-z]+://", link)}
    for link in local:
        assert (ROOT / link).exists(), f"README links {link}, which does not exist"
    pages = {f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")}
    assert pages - local == set(), "README does not link these docs pages"
    assert "CHANGELOG.md" in local


def test_no_reference_to_files_outside_the_repository():
    found = []
    for path in _tracked_text_files():
        if path.name == "test_docs.py":
            continue
        for n, line in enumerate(
            path.read_text(encoding="utf-8", errors="replace").splitlines(), 1
        ):
            if OUTSIDE.search(line):
                found.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert found == []
