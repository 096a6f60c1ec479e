"""MkDocs hook: the CLI reference page, generated from the Typer app at build time.

A page holding the marker ``<!-- cli-reference -->`` gets it replaced by Typer's own
Markdown for every command (what ``typer cartpole_q.cli.app utils docs`` prints), so the
reference cannot drift from the options the command line accepts. Typer's generator is
called in-process rather than through the ``typer`` executable: a missing executable or a
failing import then fails the build instead of leaving the page silently empty.
"""

from __future__ import annotations

from typing import Any

MARKER = "<!-- cli-reference -->"
"""where the generated reference goes in a page"""


def cli_reference() -> str:
    """Typer's Markdown for ``cartpole-q`` and each of its commands, headings from ``##``.

    Returns:
        The reference, one ``##`` section for the app and a ``###`` one per command.
    """
    import typer
    import typer.main
    from typer.cli import get_docs_for_click

    from cartpole_q.cli.app import app

    command = typer.main.get_command(app)
    # The page's own title is the only "#" heading: start the app's section one level down.
    with typer.Context(command, info_name="cartpole-q") as context:
        text = get_docs_for_click(obj=command, ctx=context, name="cartpole-q", indent=1)
    # A literal bracket in a help text is written `\[` for rich (`cartpole-q\[video]`);
    # Typer's Markdown keeps the backslash, which a code span would show.
    return text.replace("\\[", "[").strip() + "\n"


def on_page_markdown(markdown: str, page: Any, **kwargs: Any) -> str:
    """Replace the marker with the generated reference (other pages pass unchanged)."""
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, cli_reference())
