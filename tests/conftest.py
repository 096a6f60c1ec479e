"""Shared fixtures: small configs and an isolated working directory."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import settings
from threadpoolctl import threadpool_limits
from typer.testing import CliRunner, Result

from cartpole_q.cli import app

REPO = Path(__file__).resolve().parents[1]
CONFIGS = REPO / "configs"

# No test may depend on machine speed or a warm numba cache: the first call of a compiled
# function loads (or compiles) it, which can take longer than Hypothesis' 200 ms deadline.
settings.register_profile("cartpole-q", deadline=None)
settings.load_profile("cartpole-q")

# LAPACK on one thread in the test process, as the package runs every solve
# (cartpole_q.rl.solvers.one_thread): the plain re-derivations solve the same systems with
# numpy.linalg and must get the same bits.
_ONE_THREAD = threadpool_limits(limits=1, user_api="blas")

# Rendering in tests never opens a window.
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")


DEFAULT_HANDLERS = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: signal.SIG_DFL}
"""Python's own SIGINT and SIGTERM handlers, as a process started from a terminal has them"""


@pytest.fixture(autouse=True)
def default_signal_handlers() -> Iterator[None]:
    """Every test starts, and leaves, with Python's default SIGINT and SIGTERM handlers.

    The suite may itself run with SIGINT ignored (started as a background job by a script:
    ``cmd &`` in a non-interactive shell ignores SIGINT for it), and a command run in-process that
    ends interrupted leaves both ignored on purpose (its process is on its way out). An
    ignored signal stays ignored across exec, so a command a test starts would never see
    the test's Ctrl-C: the signal tests hung so when the suite ran as such a job.
    """
    for signum, handler in DEFAULT_HANDLERS.items():
        signal.signal(signum, handler)
    yield
    for signum, handler in DEFAULT_HANDLERS.items():
        signal.signal(signum, handler)


def write_yaml(path: Path, data: object) -> Path:
    """Write ``data`` as YAML and return the path."""
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Run the test inside an empty temporary directory (so runs/ lands there)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def small_config_file(tmp_path: Path) -> Path:
    """A quick config: 30 episodes, periodic evaluation and checkpoints on."""
    return write_yaml(
        tmp_path / "small.yaml",
        {
            "name": "small",
            "train": {"episodes": 30, "eval_every": 10, "eval_episodes": 2, "checkpoint_every": 10},
            "eval": {"episodes": 3},
        },
    )


def invoke(*args: object) -> Result:
    """Run the command line in-process (unexpected exceptions propagate to the test)."""
    return CliRunner().invoke(app, [str(a) for a in args], catch_exceptions=False)


def then_sigint(function: Callable[..., Any]) -> Callable[..., Any]:
    """``function``, after which this process gets a real SIGINT (a signal at that moment)."""

    def wrapped(*args: Any, **kwargs: Any) -> Any:
        result = function(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)
        return result

    return wrapped
