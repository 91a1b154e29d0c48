"""The docs point at things that exist: links, anchors, commands and their options, modules.

Every relative link in ``README.md`` and ``docs/**/*.md`` names an existing file (and, with a
``#fragment``, a heading of that file); every ``radartune COMMAND --option`` a page shows is a
subcommand and option of the command line; every ``python -m MODULE`` names an importable module
and every ``python PATH.py`` an existing script.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import re
from pathlib import Path

import pytest

from core.cli import COMMANDS

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted([ROOT / "README.md", *(ROOT / "docs").rglob("*.md")])

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)
CODE_BLOCK = re.compile(r"^```.*?^```", re.MULTILINE | re.DOTALL)
COMMAND = re.compile(r"(?:\bradartune|-m core\.cli)\s+([a-z_][a-z_-]*)([^`\n]*)")
OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")
MODULE = re.compile(r"\bpython3?\s+-m\s+([A-Za-z_][\w.]*)")
SCRIPT = re.compile(r"\bpython3?\s+([\w/.-]+\.py)\b")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`|\*\*|\*", "", heading).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = CODE_BLOCK.sub("", page.read_text(encoding="utf-8"))
    found: set[str] = set()
    for heading in HEADING.findall(text):
        base, n = slug(heading), 0
        name = base
        while name in found:
            n += 1
            name = f"{base}-{n}"
        found.add(name)
    return found


def links(page: Path) -> list[str]:
    text = CODE_BLOCK.sub("", page.read_text(encoding="utf-8"))
    text = re.sub(r"`[^`\n]*`", "", text)
    return [a or b for a, b in LINK.findall(text)]


def subcommands() -> dict[str, set[str]]:
    """Every subcommand of ``radartune`` with the options its help lists."""
    sub = argparse.ArgumentParser(prog="radartune").add_subparsers()
    for module_name in COMMANDS.values():
        importlib.import_module(module_name).add_parser(sub)
    found = {name: set(OPTION.findall(p.format_help())) for name, p in sub.choices.items()}
    # `radartune gui` passes its arguments through to the app, which owns them (app/main.py
    # imports no Qt at load)
    from app.main import build_parser

    found["gui"] = set(OPTION.findall(build_parser().format_help()))
    return found


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_links_resolve(page: Path) -> None:
    broken = []
    for target in links(page):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
            continue
        path, _, fragment = target.partition("#")
        resolved = (page.parent / path).resolve() if path else page
        if not resolved.exists():
            broken.append(f"{target}: no such file")
        elif fragment and resolved.suffix == ".md" and fragment not in anchors(resolved):
            broken.append(f"{target}: no heading #{fragment}")
    assert not broken, f"{page.relative_to(ROOT)}: " + "; ".join(broken)


def test_commands_and_options_exist() -> None:
    commands = subcommands()
    unknown = []
    for page in PAGES:
        for name, rest in COMMAND.findall(page.read_text(encoding="utf-8")):
            where = f"{page.relative_to(ROOT)}: radartune {name}"
            if name not in commands:
                unknown.append(f"{where}: no such command")
                continue
            for option in OPTION.findall(rest):
                if option not in commands[name]:
                    unknown.append(f"{where}: no option {option}")
    assert not unknown, "\n".join(unknown)


def test_modules_and_scripts_exist() -> None:
    missing = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for module in MODULE.findall(text):
            if importlib.util.find_spec(module) is None:
                missing.append(f"{page.relative_to(ROOT)}: python -m {module}")
        for script in SCRIPT.findall(text):
            if not (ROOT / script).exists():
                missing.append(f"{page.relative_to(ROOT)}: python {script}")
    assert not missing, "\n".join(missing)
