"""Training into a run directory: checks first, then checkpoints, signals and results.

Order of events for a new run: the config is checked against its environment and the
output path is checked, so bad input leaves nothing behind; only then is the directory
created and ``config.yaml`` written. Training writes ``checkpoint.npz`` every
``train.checkpoint_every`` episodes. SIGINT or SIGTERM stops at the end of the current
episode and the run directory is completed as ``interrupted``; a second signal stops at
once. ``--resume`` continues from the checkpoint and gives byte-identical results.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

from cartpole_q import rundir
from cartpole_q.config import Config, load_config
from cartpole_q.environment import EnvInfo, inspect_env
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.rundir import RunError
from cartpole_q.training import TrainResult, train


@dataclass(frozen=True)
class Prepared:
    """A checked config with its environment and engine, ready to train."""

    config: Config
    env_info: EnvInfo
    engine: str
    source: str


@dataclass(frozen=True)
class Outcome:
    """A finished (or interrupted) single run."""

    path: Path
    result: TrainResult
    summary: dict[str, Any]


class StopRequest:
    """Turns SIGINT and SIGTERM into a polite request to stop at the next episode boundary.

    Use as a context manager in the main thread; the previous handlers come back on exit.
    A second signal raises ``KeyboardInterrupt`` for an immediate stop.
    """

    def __init__(self, announce: Callable[[str], None] | None = None) -> None:
        self._event = threading.Event()
        self._announce = announce
        self._previous: dict[int, Any] = {}

    def is_set(self) -> bool:
        """Whether a stop was requested."""
        return self._event.is_set()

    def set(self) -> None:
        """Request a stop."""
        self._event.set()

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self._event.is_set():
            raise KeyboardInterrupt
        self._event.set()
        if self._announce is not None:
            self._announce(
                f"{signal.Signals(signum).name}: stopping after the current episode "
                "(send it again to stop at once)"
            )

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc_info: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous.clear()


def prepare(config: Config, source: str) -> Prepared:
    """Check a config against its environment and pick its engine (no files touched).

    Raises:
        ConfigError: the config does not fit its environment or engine.
    """
    from cartpole_q.engines import resolve_engine

    env_info = inspect_env(config, source)
    return Prepared(config, env_info, resolve_engine(config, env_info, source), source)


def start_run(prepared: Prepared, out: Path | None) -> Path:
    """Create the run directory and write its ``config.yaml``.

    Raises:
        RunError: ``out`` is a file or a non-empty directory.
    """
    run_dir = rundir.create_run_dir(prepared.config.name, out)
    rundir.write_config(run_dir, prepared.config)
    return run_dir


def execute_run(
    run_dir: Path,
    prepared: Prepared,
    *,
    resume: bool = False,
    should_stop: Callable[[], bool] | None = None,
    reporter: Reporter | None = None,
    key: Any = None,
    label: str | None = None,
) -> Outcome:
    """Train ``prepared.config`` into ``run_dir`` (which holds its ``config.yaml``).

    Args:
        run_dir: the run directory.
        prepared: the checked config.
        resume: continue from ``run_dir``'s checkpoint (from episode 0 when the run was
            stopped before its first checkpoint) instead of a new run.
        should_stop: polled between chunks of episodes.
        reporter: receives progress under ``key``.
        key: the reporter's key for this run.
        label: the reporter's label (default: the directory name).

    Raises:
        RunError: ``resume`` and the checkpoint is missing or damaged.
    """
    reporter = reporter or NullReporter()
    checkpoint = None
    if resume:
        rundir.remove_stale_temporaries(run_dir)
        # Killed before its first checkpoint: nothing was lost but time; start over.
        if (run_dir / rundir.CHECKPOINT_FILE).is_file():
            checkpoint = rundir.load_checkpoint(run_dir)
        # The run is unfinished again until the new summary is written.
        (run_dir / rundir.SUMMARY_FILE).unlink(missing_ok=True)
    config = prepared.config
    reporter.start(key, label or run_dir.name, config.train.episodes)
    result = train(
        config,
        env_info=prepared.env_info,
        resume=checkpoint,
        should_stop=should_stop,
        on_progress=lambda progress: reporter.update(key, progress),
        on_checkpoint=lambda snapshot: rundir.write_checkpoint(run_dir, snapshot),
    )
    summary = rundir.write_run(run_dir, result)
    reporter.finish(key, outcome_line(label or run_dir.name, summary))
    return Outcome(run_dir, result, summary)


def prepare_resume(run_dir: Path) -> Prepared:
    """Load an unfinished run's config for ``--resume``.

    Raises:
        RunError: ``run_dir`` is not a run directory, or its run already finished.
        ConfigError: its ``config.yaml`` no longer fits its environment.
    """
    if not (run_dir / rundir.CONFIG_FILE).is_file():
        raise RunError(f"{run_dir}: is not a run directory (it has no {rundir.CONFIG_FILE}).")
    source = str(run_dir / rundir.CONFIG_FILE)
    config = load_config(run_dir / rundir.CONFIG_FILE)
    summary_path = run_dir / rundir.SUMMARY_FILE
    if summary_path.is_file():
        import json

        try:
            interrupted = json.loads(summary_path.read_text(encoding="utf-8")).get("interrupted")
        except (OSError, ValueError, AttributeError):
            interrupted = True
        if not interrupted:
            raise RunError(f"{run_dir}: this run already finished; there is nothing to resume.")
    return prepare(config, source)


def outcome_line(label: str, summary: dict[str, Any]) -> str:
    """One line saying how a run ended.

    >>> outcome_line("seed 3", {"solved_episode": 180, "eval": {"mean": 500.0},
    ...     "episodes": 180, "interrupted": False})
    'seed 3: solved at episode 180, greedy eval mean 500.0'
    """
    evaluation = summary.get("eval") or {}
    mean = evaluation.get("mean")
    tail = f", greedy eval mean {mean:.1f}" if mean is not None else ""
    if summary.get("interrupted"):
        return f"{label}: interrupted after episode {summary['episodes']}{tail}"
    if summary.get("solved_episode") is not None:
        return f"{label}: solved at episode {summary['solved_episode']}{tail}"
    return f"{label}: not solved in {summary['episodes']} episodes{tail}"
