"""``cartpole-q updates``: ``study`` for chapter 8's planning studies (an alias for one release)."""

from __future__ import annotations

from cartpole_q.cli.base import Command, app
from cartpole_q.cli.studies import study_command

app.command(
    "updates",
    cls=Command,
    help="`study` for planning-update studies (chapter 8: figure kinds expected_vs_sample, trajectory_sampling, until_optimal); the last line is its directory.",
)(study_command)
