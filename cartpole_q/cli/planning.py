"""``cartpole-q dp``: ``study`` for dynamic-programming studies (an alias for one release)."""

from __future__ import annotations

from cartpole_q.cli.base import Command, app
from cartpole_q.cli.studies import study_command

app.command(
    "dp",
    cls=Command,
    help="`study` for dynamic-programming studies (chapters 3-4); the last line is its directory.",
)(study_command)
