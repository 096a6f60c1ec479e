"""Training into a run directory: checks first, then checkpoints, signals and results.

Order of events for a new run: the config is checked against its environment and the
output path is checked, so bad input leaves nothing behind; only then is the directory
created and locked, found empty under its lock, and ``config.yaml`` written. Training writes ``checkpoint.npz`` every
``train.checkpoint_every`` episodes. SIGINT or SIGTERM stops at the end of the current
episode and the run directory is completed as ``interrupted``; a second signal stops at
once. ``--resume`` continues from the checkpoint and gives byte-identical results.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
from collections.abc import Callable, Hashable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

from cartpole_q.config import (
    COMMAND_LINE,
    Config,
    ConfigError,
    Provenance,
    config_differences,
    load_config,
    shown_value,
)
from cartpole_q.engines.plan import Plan, plan_run
from cartpole_q.errors import RunError
from cartpole_q.progress import NullReporter, Reporter
from cartpole_q.results import RunSummary, SeedResult
from cartpole_q.store import rundir
from cartpole_q.store.atomic import make_directory, remove_stale_temporaries
from cartpole_q.store.checkpoint import (
    CHECKPOINT_FILE,
    load_checkpoint,
    read_checkpoint_meta,
    write_checkpoint,
)
from cartpole_q.training import Checkpoint, TrainResult, train


@dataclass(frozen=True)
class Outcome:
    """A finished (or interrupted) single run."""

    path: Path
    result: TrainResult
    summary: RunSummary


@dataclass(frozen=True)
class Reporting:
    """Where a run's progress goes: a reporter, and the key and label it shows the run under."""

    reporter: Reporter
    key: Hashable = None
    """the reporter's key for this run"""
    label: str | None = None
    """the reporter's label (default: the run directory's name)"""


class StopRequest:
    """Turns SIGINT and SIGTERM into a polite request to stop at the next episode boundary.

    Use as a context manager in the main thread; the previous handlers come back on exit.
    A second signal raises ``KeyboardInterrupt`` for an immediate stop.
    """

    def __init__(
        self,
        announce: Callable[[str], None] | None = None,
        stop_point: str = "the current episode",
    ) -> None:
        self._event = threading.Event()
        self._announce = announce
        self._stop_point = stop_point
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
                f"{signal.Signals(signum).name}: stopping after {self._stop_point} "
                "(send it again to stop at once)"
            )

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc_info: object) -> None:
        for signum, handler in self._previous.items():
            # Once stopping, the command is on its way out: a further signal must not
            # turn its clean exit (files complete, exit code 130) into a crash.
            signal.signal(signum, signal.SIG_IGN if self._event.is_set() else handler)
        self._previous.clear()


def prepare(config: Config, source: str | Provenance) -> Plan:
    """Plan a run: check a config against its environment, pick its engine and twin.

    No files are touched (see :func:`~cartpole_q.engines.plan.plan_run`).

    Raises:
        ConfigError: the config does not fit its environment or engine.
    """
    return plan_run(config, source)


def prepare_new(
    config_file: Path | None,
    assignments: list[str],
    *,
    seed: int | None = None,
    seeds: str | None = None,
    episodes: int | None = None,
    engine: str | None = None,
) -> Plan:
    """Load a new run's config from a file (or the default) and the command line's values.

    Args:
        config_file: a config file or a shipped config's name (``None``: the default).
        assignments: ``--set KEY=VALUE`` texts, applied in order.
        seed: the run's seed (one run: clears ``train.seeds``).
        seeds: ``train.seeds`` (several runs).
        episodes: ``train.episodes``.
        engine: ``engine``.

    Raises:
        ConfigError: naming the file or option and the key.
    """
    from cartpole_q.config import parse_assignment, resolve_config_path

    overrides: dict[str, Any] = dict(map(parse_assignment, assignments))
    if seed is not None:
        overrides.update({"seed": seed, "train.seeds": None})
    if seeds is not None:
        overrides["train.seeds"] = seeds
    if episodes is not None:
        overrides["train.episodes"] = episodes
    if engine is not None:
        overrides["engine"] = engine
    loaded = load_config(config_file, overrides, override_source=COMMAND_LINE)
    file = str(resolve_config_path(config_file)) if config_file else "default config"
    return prepare(loaded, Provenance(file, tuple(overrides), COMMAND_LINE))


@contextlib.contextmanager
def new_run(prepared: Plan, out: Path | None) -> Iterator[Path]:
    """Create the run directory and write its ``config.yaml``, holding its lock inside.

    A failure before ``config.yaml`` is written (a full disk) removes the directory this
    created; after it, the directory stays for ``train --resume``.

    Raises:
        RunError: ``out`` is a file or a non-empty directory, or another command is
            writing it.
        WriteError: ``config.yaml`` (or the lock file) cannot be written.
    """
    with rundir.new_directory(prepared.config.name, out) as claim:
        rundir.write_config(claim.path, prepared.config)
        claim.keep()
        yield claim.path


def start_run(prepared: Plan, out: Path | None) -> Path:
    """Create the run directory and write its ``config.yaml`` (its lock released on return).

    Raises:
        RunError: ``out`` is a file or a non-empty directory.
    """
    with new_run(prepared, out) as run_dir:
        return run_dir


def execute_run(
    run_dir: Path,
    prepared: Plan,
    *,
    resume: bool = False,
    should_stop: Callable[[], bool] | None = None,
    reporting: Reporting | None = None,
    watch_every: int = 0,
    video_every: int = 0,
    plot: bool = True,
) -> Outcome:
    """Train ``prepared.config`` into ``run_dir`` (which holds its ``config.yaml``).

    Args:
        run_dir: the run directory.
        prepared: the checked config.
        resume: continue from ``run_dir``'s checkpoint (from episode 0 when the run was
            stopped before its first checkpoint) instead of a new run.
        should_stop: polled between chunks of episodes.
        reporting: where progress goes (default: nowhere).
        watch_every: every this many episodes, play one greedy episode in Gymnasium's
            window (``train --watch``; 0: never).
        video_every: every this many episodes, record one greedy episode as
            ``videos/episode-NNNNNN.gif`` in the run directory (``train --video-every``).
        plot: draw ``reward_curve.png`` (a multi-seed run draws one for all its seeds
            instead, unless ``train --seed-plots``).

    Raises:
        RunError: ``resume`` and the checkpoint is missing or damaged.
    """
    reporting = reporting or Reporting(NullReporter())
    reporter, key, label = reporting.reporter, reporting.key, reporting.label
    config = prepared.config
    checkpoint = None
    if resume:
        remove_stale_temporaries(run_dir)
        # Killed before its first checkpoint: nothing was lost but time; start over.
        if (run_dir / CHECKPOINT_FILE).is_file():
            checkpoint = load_checkpoint(run_dir)
            check_resumable(run_dir, checkpoint, config)
        # config.yaml says what the run now is (train.episodes may have grown).
        rundir.write_config(run_dir, config)
        # The run is unfinished again until the new summary is written.
        (run_dir / rundir.SUMMARY_FILE).unlink(missing_ok=True)
    reporter.start(key, label or run_dir.name, config.train.episodes)
    result = train(
        prepared,
        resume=checkpoint,
        should_stop=should_stop,
        on_progress=lambda progress: reporter.update(key, progress),
        on_checkpoint=lambda snapshot: write_checkpoint(run_dir, snapshot),
        snapshot_every=math.gcd(watch_every, video_every),
        on_snapshot=_greedy_viewer(run_dir, config, watch_every, video_every),
    )
    summary = rundir.write_run(run_dir, result, overwrite=True, plot=plot)
    reporter.finish(key, outcome_line(label or run_dir.name, summary.result()))
    return Outcome(run_dir, result, summary)


VIDEOS_DIR = "videos"
"""where ``train --video-every`` puts its recordings, inside the run directory"""


def _greedy_viewer(
    run_dir: Path, config: Config, watch_every: int, video_every: int
) -> Callable[[int, Any], None] | None:
    """Show or record the current greedy policy at snapshots, as the options ask."""
    if not (watch_every or video_every):
        return None
    from cartpole_q.evaluation import evaluate

    def view(episode: int, q_table: np.ndarray) -> None:
        if watch_every and episode % watch_every == 0:
            evaluate(q_table, config, episodes=1, render_mode="human")
        if video_every and episode % video_every == 0:
            from cartpole_q.store.video import VideoRecorder, offscreen_rendering

            videos = run_dir / VIDEOS_DIR
            make_directory(videos)
            path = videos / f"episode-{episode:06d}.gif"
            with VideoRecorder(path, episodes=1, force=True) as recorder:
                with offscreen_rendering():
                    evaluate(q_table, config, episodes=1, render_mode="rgb_array",
                             on_frame=recorder.on_frame)  # fmt: skip
                recorder.save()

    return view


def prepare_resume(run_dir: Path, episodes: int | None = None) -> Plan:
    """Load a run's config for ``--resume``: an unfinished run, or one to extend.

    Args:
        run_dir: the run directory (or the parent of a multi-seed run).
        episodes: extend the run to this many episodes in all (``--episodes``); without
            it, ``train.episodes`` of its ``config.yaml`` (which the user may have raised).

    Raises:
        RunError: ``run_dir`` is not a run directory; its run already finished and there
            is nothing to extend; or a multi-seed run's seeds were trained with another
            config than its ``config.yaml`` now says.
        ConfigError: its ``config.yaml`` is invalid or no longer fits its environment.
    """
    config_path = run_dir / rundir.CONFIG_FILE
    if not config_path.is_file():
        raise RunError(f"{run_dir}: is not a run directory (it has no {rundir.CONFIG_FILE}).")
    overrides = None if episodes is None else {"train.episodes": episodes}
    config = load_config(config_path, overrides, override_source=COMMAND_LINE)
    multi_seed = config.train.seeds is not None
    if multi_seed and episodes is not None:
        raise RunError(
            f"{run_dir}: is a multi-seed run; --episodes extends one run: extend its seeds "
            f"one by one with `cartpole-q train --resume {run_dir}/seed-NNN --episodes N`."
        )
    if multi_seed:
        aggregate = rundir.read_multi_seed_summary(run_dir)
        if aggregate is not None and not aggregate.interrupted:
            raise RunError(f"{run_dir}: this run already finished; there is nothing to resume.")
        _check_seed_configs(run_dir, config)
    else:
        summary = rundir.read_summary(run_dir)
        if summary is not None and not summary.interrupted:
            _check_extendable(run_dir, config, summary, episodes is not None)
    return prepare(config, str(config_path))


def _check_extendable(
    run_dir: Path, config: Config, summary: RunSummary, from_option: bool
) -> None:
    """Refuse to resume a finished run unless it ended at ``train.episodes`` and more are asked."""
    done = summary.episodes
    budget = config.train.max_env_steps
    if budget is not None and summary.env_steps >= budget:
        raise RunError(
            f"{run_dir}: this run already finished; there is nothing to resume: it stopped at "
            f"train.max_env_steps ({budget:,} env steps), cutting its last episode there, so "
            "it cannot go on as one run; train it again with a larger train.max_env_steps."
        )
    meta = read_checkpoint_meta(run_dir)
    if meta is None:
        solved = summary.solved_episode
        if solved is not None and solved == done:
            reason = (
                f"it stopped at episode {solved}, where it solved (train.stop_when_solved), so "
                "a longer run from the start would have stopped there too; only a run that "
                "ended by reaching train.episodes can be extended"
            )
        else:
            reason = f"it kept no {CHECKPOINT_FILE} to continue from"
        raise RunError(
            f"{run_dir}: this run already finished; there is nothing to resume: {reason}."
        )
    trained = int(meta.get("episode", done))
    if config.train.episodes <= trained:
        asked = (
            f"--episodes {config.train.episodes}"
            if from_option
            else f"train.episodes in its {rundir.CONFIG_FILE} ({config.train.episodes})"
        )
        raise RunError(
            f"{run_dir}: this run already finished all {trained} episodes and {asked} "
            f"asks for no more; there is nothing to resume. To train it longer, give "
            f"`cartpole-q train --resume {run_dir} --episodes N` with N above {trained}."
        )


def check_resumable(run_dir: Path, checkpoint: Checkpoint, config: Config) -> None:
    """Refuse to continue a checkpoint under another config than it was trained with.

    Only ``train.episodes`` may differ, and only grow: the continued run is then
    byte-identical to a run trained that long from the start.

    Raises:
        RunError: naming the first key that differs, with both values.
    """
    where = run_dir / rundir.CONFIG_FILE
    trained: Config | None = checkpoint.config
    if trained is None and config.discretization is not None:
        # a checkpoint from before configs were recorded in it (CartPole grids only)
        states = math.prod(config.discretization.bins)
        if checkpoint.tables.q.shape[0] != states:
            raise RunError(
                f"{where}: discretization.bins: {list(config.discretization.bins)} gives "
                f"{states} states, but the checkpoint's Q-table has {checkpoint.tables.q.shape[0]}; "
                "--resume continues a run exactly as it was trained."
            )
        return
    if trained is None:
        return
    for key, old, new in config_differences(trained, config):
        if key == "train.episodes":
            if new >= old:
                continue
            raise RunError(
                f"{where}: train.episodes: the run was trained for {old} episodes and cannot "
                f"be shortened to {new}; --resume only continues or extends a run."
            )
        raise RunError(
            f"{where}: {key}: the run was trained with {shown_value(old)}, {rundir.CONFIG_FILE} "
            f"now says {shown_value(new)}. --resume continues a run exactly as it was trained, so "
            "only train.episodes may change (and only grow); put the value back, or train a "
            f"new run with `cartpole-q train --config {where}`."
        )


def _check_seed_configs(parent: Path, config: Config) -> None:
    """Refuse a multi-seed resume whose seeds were started with another config."""
    from cartpole_q.store.runsets import seed_dir

    seeds = config.train.seeds
    assert seeds is not None
    for seed in seeds:
        child = seed_dir(parent, seed, seeds)
        if not (child / rundir.CONFIG_FILE).is_file():
            continue
        try:
            started = load_config(child / rundir.CONFIG_FILE)
        except ConfigError as error:
            raise RunError(
                f"{child}: its {rundir.CONFIG_FILE} is not a valid config. {error}"
            ) from None
        differences = config_differences(started, config.for_seed(seed))
        if differences:
            key, old, new = differences[0]
            raise RunError(
                f"{parent / rundir.CONFIG_FILE}: {key}: {child.name} was trained with "
                f"{shown_value(old)}, {rundir.CONFIG_FILE} now says {shown_value(new)}. A multi-seed "
                "run resumes exactly as it was configured; put the value back (to train one "
                f"seed longer: `cartpole-q train --resume {child} --episodes N`)."
            )


def outcome_line(label: str, result: SeedResult) -> str:
    """One line saying how a run ended.

    >>> outcome_line("seed 3", SeedResult(3, 180, 9000, 180, 9000, None, 500.0, True))
    'seed 3: solved at episode 180, greedy eval mean 500.0'
    >>> outcome_line("walk", SeedResult(0, 100, 600, None, None, None, None, None, rms_error=0.05, predicts=True))
    'walk: learnt V in 100 episodes, RMS error 0.05'
    """
    tail = f", greedy eval mean {result.eval_mean:.1f}" if result.eval_mean is not None else ""
    if result.predicts:  # nothing to solve: its figure is the error of V
        if result.rms_error is not None:
            tail = f", RMS error {result.rms_error:.4g}"
        else:
            tail = " (no exact values to measure V against)"
        return f"{label}: {'interrupted after' if result.interrupted else 'learnt V in'} {result.episodes} episodes{tail}"
    if result.interrupted:
        return f"{label}: interrupted after episode {result.episodes}{tail}"
    if result.solved_episode is not None:
        return f"{label}: solved at episode {result.solved_episode}{tail}"
    return f"{label}: not solved in {result.episodes} episodes{tail}"
