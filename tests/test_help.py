"""Every command's ``--help`` shows its help texts whole: rich markup eats no bracketed word.

Typer renders help with rich markup, where ``[video]`` is a style tag and vanishes: ``pip
install "cartpole-q[video]"`` would print as ``pip install "cartpole-q"``. A bracket meant
literally is written ``\\[`` in the source; this test renders every command's help and looks
for each bracketed text of the source in it.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import pytest
import typer.main

from cartpole_q.cli import app
from tests.conftest import invoke

BRACKETED = re.compile(r"\\?\[[^\[\]\n]*\]")
"""a bracketed text as written in the source: ``[video]``, or escaped, ``\\[video]``"""
FRAME = re.compile(r"[\u2500-\u257f]")
"""the box-drawing characters of rich's panels"""


def _commands() -> Iterator[tuple[tuple[str, ...], Any]]:
    """Every command with the words that call it (the app itself first, as ``()``)."""
    root = typer.main.get_command(app)
    pending: list[tuple[tuple[str, ...], Any]] = [((), root)]
    while pending:
        path, command = pending.pop(0)
        yield path, command
        # Typer's own click (typer._click): a group is what has subcommands.
        for name, sub in sorted(getattr(command, "commands", {}).items()):
            pending.append(((*path, name), sub))


def _help_texts(command: Any) -> list[str]:
    """The texts of the source that ``--help`` shows: the command's and each parameter's."""
    texts = [command.help or "", command.epilog or ""]
    texts.extend(getattr(param, "help", None) or "" for param in command.params)
    return [text for text in texts if text]


def _flat(text: str) -> str:
    """Text without rich's frames, every run of whitespace one space (help wraps lines)."""
    return " ".join(FRAME.sub(" ", text).split())


COMMANDS = list(_commands())


def test_some_help_text_has_a_literal_bracket() -> None:
    """The test below has something to check (the extras' install lines)."""
    found = [
        match
        for _, command in COMMANDS
        for text in _help_texts(command)
        for match in BRACKETED.findall(text)
    ]
    literal = {match.replace("\\[", "[") for match in found}
    assert {"[video]", "[tensorboard]", "[ray]"} <= literal, found


@pytest.mark.parametrize(
    ("words", "command"), COMMANDS, ids=[" ".join(path) or "cartpole-q" for path, _ in COMMANDS]
)
def test_help_shows_every_bracketed_text_of_the_source(
    words: tuple[str, ...], command: Any
) -> None:
    result = invoke(*words, "--help")
    assert result.exit_code == 0, result.output
    # A word wider than its column is cut with an ellipsis: a user could not read it.
    assert "\u2026" not in result.stdout, result.stdout
    shown = _flat(result.stdout)
    for text in _help_texts(command):
        for bracketed in BRACKETED.findall(text):
            literal = _flat(bracketed.replace("\\[", "["))
            assert literal in shown, f"{' '.join(words)} --help lost {literal!r}:\n{result.stdout}"
