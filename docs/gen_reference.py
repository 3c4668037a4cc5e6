"""Generates the reference pages while MkDocs builds the site (mkdocs-gen-files):

- ``reference/cli.md``: every ``mjswarm`` subcommand's ``--help``, formatted by the
  argparse parsers themselves, so the page cannot drift from the command line;
- ``reference/api/*.md``: one page per package, each module rendered by mkdocstrings
  from its docstrings;
- ``reference/state-machines.md``: the embodied explorer's modes and its navigator's
  states, with every move between them, from :data:`algorithms.exploration.modes.
  TRANSITIONS` and :data:`algorithms.navigation.navigator.NAVIGATOR_TRANSITIONS`;
- ``changelog.md``: the repository's ``CHANGELOG.md``.
"""

from __future__ import annotations

import argparse
import os
import pkgutil
from pathlib import Path

import mkdocs_gen_files

from algorithms.exploration.modes import TRANSITIONS, Mode
from algorithms.navigation.navigator import NAVIGATOR_TRANSITIONS
from mjswarm.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent

#: API pages: page name -> (title, packages whose modules it renders).
API_PAGES = {
    "algorithms": ("algorithms: the robots' minds", ("algorithms",)),
    "core": ("mjswarm.core: the simulation core", ("mjswarm.core",)),
    "arena": ("mjswarm.arena: arena specs and the MJCF builder", ("mjswarm.arena",)),
    "worlds": ("mjswarm.worlds: the worlds and the loop", ("mjswarm.worlds",)),
    "experiments": ("mjswarm.experiments: loop functions", ("mjswarm.experiments",)),
    "outputs": ("mjswarm.outputs: recordings, video, plots", ("mjswarm.outputs",)),
}


def subcommands(parser: argparse.ArgumentParser, prefix: str):
    """Yield ``(command line, parser)`` for ``parser`` and every subparser below it."""
    yield prefix, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from subcommands(sub, f"{prefix} {name}")


def cli_page() -> str:
    os.environ["COLUMNS"] = "88"  # argparse wraps to the terminal; fix it for the page
    lines = ["# Command line", "",
             "Generated from the `mjswarm` argparse parsers when the site is built: each "
             "section is exactly what `--help` prints.", ""]
    for command, parser in subcommands(build_parser(), "mjswarm"):
        lines += [f"## `{command}`", "", "```text", parser.format_help().rstrip(), "```", ""]
    return "\n".join(lines)


def modules(package: str) -> list[str]:
    """``package`` and every module below it, in alphabetical order."""
    path = ROOT.joinpath(*package.split("."))
    found = [package]
    for info in pkgutil.walk_packages([str(path)], prefix=f"{package}."):
        found.append(info.name)
    return sorted(found)


def api_page(title: str, packages: tuple[str, ...]) -> str:
    lines = [f"# {title}", ""]
    for package in packages:
        for module in modules(package):
            lines += [f"::: {module}", "    options:", "      members_order: source", ""]
    return "\n".join(lines)


def moves(table: dict) -> list[str]:
    """A transition table as markdown rows: from, to, when."""
    lines = ["| from | to | when |", "|---|---|---|"]
    for source, targets in table.items():
        lines += [f"| `{source.name}` | `{target.name}` | {why} |"
                  for target, why in targets.items()]
    return lines


def modes_page() -> str:
    """The explorer's modes and the navigator's states, as the code holds them."""
    lines = ["# State machines", "",
             "Generated from `algorithms.exploration.modes` and "
             "`algorithms.navigation.navigator` when the site is built.", "",
             "## The explorer's modes", "",
             "Every mode that is not terminal may also end in `HALTED` (it stops for good) "
             "or `INFEASIBLE` (its tether's stall verdict, rule 5).", "",
             "| mode | what it does |", "|---|---|"]
    lines += [f"| `{m.name}` | {m.value} |" for m in Mode]
    lines += ["", *moves(TRANSITIONS), "", "## The navigator's states", "",
              *moves(NAVIGATOR_TRANSITIONS)]
    return "\n".join(lines) + "\n"


with mkdocs_gen_files.open("reference/state-machines.md", "w") as page:
    page.write(modes_page())
with mkdocs_gen_files.open("reference/cli.md", "w") as page:
    page.write(cli_page())
for name, (title, packages) in API_PAGES.items():
    with mkdocs_gen_files.open(f"reference/api/{name}.md", "w") as page:
        page.write(api_page(title, packages))
with mkdocs_gen_files.open("changelog.md", "w") as page:
    page.write((ROOT / "CHANGELOG.md").read_text())
