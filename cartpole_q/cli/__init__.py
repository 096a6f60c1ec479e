"""The ``cartpole-q`` command line (:mod:`cartpole_q.cli.app`) and what it prints."""

from cartpole_q.cli.app import app, main

__all__ = ["app", "main"]
