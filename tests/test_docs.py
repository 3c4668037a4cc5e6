"""The front page and the manual: README's controller runs and prints what README says,
README stays a front page, and nothing a user reads speaks of how mjswarm was developed."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Words of a development log: numbered issues, sessions and stages, commit references,
#: "(was: ...)" asides.
HISTORY = re.compile(r"\b(issues? #?\d+|sessions? \d+|stage \d+|commit [0-9a-f]{7,})\b"
                     r"|(?<!\w)\(was[:,]|\bwas: |\bseed 00\d\b", re.IGNORECASE)

#: What users read: the front page, the manual, the code's docstrings and help texts.
READ_BY_USERS = ("README.md", "CHANGELOG.md", "docs", "algorithms", "mjswarm", "examples",
                 "models")


def user_files():
    for name in READ_BY_USERS:
        path = ROOT / name
        if path.is_file():
            yield path
            continue
        for file in sorted(path.rglob("*")):
            if file.suffix in {".md", ".py", ".xml", ".json", ".toml"} and file.is_file():
                yield file


def test_nothing_users_read_speaks_of_the_development_history():
    hits = []
    for file in user_files():
        for number, line in enumerate(file.read_text(errors="replace").splitlines(), 1):
            if HISTORY.search(line):
                hits.append(f"{file.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not hits, "\n".join(hits[:40])


def test_the_history_pattern_finds_what_it_is_for():
    for text in ("as issue 13 found", "(was: 12 s)", "in session 9", "see seed 003",
                 "commit 497d05b"):
        assert HISTORY.search(text), text
    for text in ("the paper's 13-vertex arena", "it was measured", "Algorithm 3"):
        assert not HISTORY.search(text), text


def test_readme_is_a_front_page():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 250


def readme_block(language: str, after: str) -> str:
    """The first ``language`` code block of README after the line containing ``after``."""
    text = (ROOT / "README.md").read_text()
    start = text.index(after)
    match = re.compile(rf"```{language}\n(.*?)```", re.DOTALL).search(text, start)
    assert match, f"no {language} block after {after!r}"
    return match.group(1)


def test_readmes_controller_prints_what_readme_says(tmp_path):
    code = readme_block("python", "## Write a controller")
    expected = readme_block("text", "It prints")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout == expected


@pytest.mark.parametrize("page", ["index", "getting-started", "concepts", "robot", "arenas",
                                  "navigation", "exploration", "collision", "connectivity",
                                  "faults", "recordings", "sweeps", "performance", "papers"])
def test_every_page_of_the_site_exists_and_says_something(page):
    text = (ROOT / "docs" / f"{page}.md").read_text()
    assert text.startswith("# ") and len(text.split()) > 150


def test_every_measured_table_names_its_command():
    tables = sorted((ROOT / "docs" / "tables").glob("*.md"))
    assert tables
    for table in tables:
        assert "*Measured by `python benchmarks/" in table.read_text(), table.name


def test_the_version_follows_the_changelog():
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    from mjswarm import __version__

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    released = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", (ROOT / "CHANGELOG.md").read_text(),
                          re.MULTILINE)
    assert project == __version__ == released[0]
