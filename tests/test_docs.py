"""The README is a front door and the MkDocs site is the manual: both checked here.

The README stays short, keeps the two set-up commands CI runs, and its relative links
resolve; the docs document every subcommand and every option of every subcommand's parser
(walked from ``pendverify.cli.build_parser()``, so an option added without documentation
fails here); neither speaks of how the project was made.  ``mkdocs build --strict`` checks
the site's links and API references as well.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from pendverify.cli import build_parser
from tests.cli_parsers import subcommands

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
COMMAND_PAGES = DOCS / "commands"

SETUP_COMMANDS = (
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e . && pendverify check",
    # -m "": every test (a plain run is the fast one for development, pyproject.toml's addopts)
    "python3 -m venv .venv-test && . .venv-test/bin/activate && pip install -e '.[test]' "
    '&& python -m pytest -m ""',
)
# user-facing text names the built-in systems "the two reference systems", never their origin
FORBIDDEN = ("seed 000", "seed 001", "seed-000", "seed-001", "../shared", "source document", "issue-15")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def doc_pages() -> list[Path]:
    return sorted(DOCS.rglob("*.md"))


def prose(text: str) -> str:
    """The text outside fenced code blocks (code may hold brackets that look like links)."""
    return FENCE.sub("", text)


def relative_links(path: Path) -> list[str]:
    targets = (m.group(1) for m in LINK.finditer(prose(path.read_text(encoding="utf-8"))))
    return [t for t in targets if not re.match(r"^(https?:|mailto:|#)", t)]


def option_strings(parser: argparse.ArgumentParser) -> list[str]:
    return [
        option
        for action in parser._actions
        if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
        for option in action.option_strings
    ]


def mentions(text: str, option: str) -> bool:
    return re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text) is not None


def command_page(name: str) -> Path:
    """The page under docs/commands whose title names the top-level command ``name``."""
    for page in sorted(COMMAND_PAGES.glob("*.md")):
        title = next(
            (line for line in page.read_text(encoding="utf-8").splitlines() if line.startswith("# ")), ""
        )
        if re.search(rf"(?<![\w-]){re.escape(name)}(?![\w-])", title):
            return page
    pytest.fail(f"no page in docs/commands has a title naming the command {name!r}")


def test_readme_is_a_front_door_of_at_most_200_lines():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; the manual belongs in docs/"


def test_readme_keeps_the_two_setup_commands_verbatim():
    text = README.read_text(encoding="utf-8")
    for command in SETUP_COMMANDS:
        assert f"```sh\n{command}\n```" in text, command


def test_ci_runs_the_readme_s_test_command():
    """CI's last command is the pytest of the README's test command: every test, not the fast default."""
    readme_pytest = SETUP_COMMANDS[1].rsplit(" && ", 1)[1]
    last = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    assert last.split("  #")[0] == readme_pytest, last


@pytest.mark.parametrize("path", [README, *doc_pages()], ids=lambda p: str(p.relative_to(ROOT)))
def test_no_text_says_how_the_project_was_made(path):
    text = path.read_text(encoding="utf-8").lower()
    found = [word for word in FORBIDDEN if word in text]
    assert not found, f"{path.relative_to(ROOT)} says {found}: say 'the two reference systems' instead"


@pytest.mark.parametrize("path", [README, *doc_pages()], ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(path):
    missing = [
        target
        for target in relative_links(path)
        if not (path.parent / target.split("#", 1)[0]).resolve().exists()
    ]
    assert not missing, f"{path.relative_to(ROOT)} links to files that do not exist: {missing}"


def test_every_subcommand_has_its_page():
    for command, _ in subcommands(build_parser()):
        command_page(command[0])  # fails naming the command


def test_every_option_of_every_subcommand_is_documented_on_its_page():
    """Each option on its command's page; the global ones (``--debug``, ...) may be on the global page."""
    top = build_parser()
    global_options = set(option_strings(top))
    missing = []
    for command, parser in subcommands(top):
        page = command_page(command[0])
        text = page.read_text(encoding="utf-8")
        if len(command) > 1 and " ".join(command) not in text:
            missing.append(f"{' '.join(command)} (on {page.name})")
        missing += [
            f"{' '.join(command)} {option} (on {page.name})"
            for option in option_strings(parser)
            if option not in global_options and not mentions(text, option)
        ]
    assert not missing, "options not documented: " + ", ".join(missing)


def test_global_options_are_documented():
    text = (COMMAND_PAGES / "global-options.md").read_text(encoding="utf-8")
    missing = [option for option in option_strings(build_parser()) if not mentions(text, option)]
    assert not missing, f"global options not in docs/commands/global-options.md: {missing}"


def test_the_site_lists_every_page_it_has():
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    listed = set(re.findall(r":\s*([\w./-]+\.md)\s*$", nav, re.M))
    pages = {str(p.relative_to(DOCS)) for p in doc_pages()}
    assert listed == pages, (
        f"in docs/ but not in the nav: {pages - listed}; in the nav only: {listed - pages}"
    )
