"""TensorBoard event files of a run (``train --tensorboard``), with CleanRL's and SB3's names.

Users coming from CleanRL and Stable-Baselines3 watch runs in TensorBoard; a run with
``train.tensorboard: true`` also writes ``RUN/tensorboard/events.out.tfevents.*`` from
what the run keeps anyway: the columns of ``metrics.csv``, the periodic evaluations of
``evaluations.csv`` and the figures of ``summary.json``. It is written after training,
with the run's other files (never from inside the compiled loop), and changes no byte of
them. The writer is the optional ``tensorboardX`` package
(``pip install "cartpole-q[tensorboard]"``); viewing needs ``tensorboard`` itself.

| tag | value | written |
| --- | --- | --- |
| ``charts/episodic_return`` | the episode's return (``metrics.csv``'s ``return``) | every episode |
| ``charts/episodic_length`` | its length in env steps (``length``) | every episode |
| ``charts/epsilon`` | its exploration rate (``epsilon``) | every episode |
| ``charts/learning_rate`` | its step size (``alpha``; none under ``sample_average``) | every episode |
| ``rollout/ep_rew_mean`` | mean return of the last (up to) 100 episodes | every episode |
| ``rollout/ep_len_mean`` | mean length of the last (up to) 100 episodes | every episode |
| ``eval/mean_reward`` | a periodic greedy evaluation's mean (``evaluations.csv``) | every ``train.eval_every`` episodes |
| ``charts/SPS`` | env steps per second of training (``summary.json``'s ``steps_per_second``) | once, at the last step |
| ``summary/eval_mean`` | the final greedy evaluation's mean (``summary.json``'s ``eval.mean``) | once, at the last step |
| ``summary/success`` | 1 when that mean reaches the threshold, else 0 | once, at the last step |
| ``summary/solved_episode`` | the solve episode, when the run solved | once, at the last step |

The step of every scalar is the env steps taken by the end of that episode (CleanRL's and
SB3's ``global_step``), so curves line up with theirs. TensorBoard keeps scalars as
float32: the values are ``metrics.csv``'s, rounded to float32.

The resolved config is logged as hyperparameters (dotted keys; lists as JSON), with one
event directory per run, so ``tensorboard --logdir`` on a multi-seed run's directory
(``seed-*/tensorboard``) or on several run directories lets the HParams view compare them;
TensorBoard gathers the hyperparameters and metrics of all the runs it finds. A sweep
whose points have ``train.tensorboard`` writes ``SWEEP/tensorboard/<point>/seed-<S>/``, a
tune study ``TUNE/tensorboard/trial-<N>/seed-<S>/``: one session per run, its point's or
trial's config as hyperparameters. Studies keep returns and lengths only, so their runs
have no ``charts/epsilon``, ``charts/learning_rate`` or ``eval/mean_reward``.

Each training session (a new run, a resumed or extended one) writes the whole history
again into one new event file and removes the earlier ones, so the directory always holds
exactly what ``metrics.csv`` holds. The file is written in a temporary directory and moved
into place, like every other file of the run.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cartpole_q.errors import UserError
from cartpole_q.rl.solve import SOLVE_WINDOW
from cartpole_q.store.atomic import atomic_write_bytes, make_directory

if TYPE_CHECKING:
    from cartpole_q.results import SeedResult
    from cartpole_q.training import TrainResult

TENSORBOARD_DIR = "tensorboard"
"""the event directory inside a run directory"""
EVENT_FILE_PREFIX = "events.out.tfevents."
"""how TensorBoard's event files are named"""
SKIPPED_HPARAMS = ("train.tensorboard", "train.seeds")
"""config keys that say nothing about a run's hyperparameters (always true; always null)"""


def require_writer(option: str = "--tensorboard") -> None:
    """Check that the TensorBoard writer is installed, before anything is trained.

    Args:
        option: how the user asked for it, for the message.

    Raises:
        UserError: ``tensorboardX`` is not installed, naming the extra to install.
    """
    try:
        import tensorboardX  # noqa: F401 - only checked here
    except ImportError:
        raise UserError(
            f"{option}: writing TensorBoard event files needs the optional TensorBoard "
            'writer: install it with `pip install "cartpole-q[tensorboard]"` (tensorboardX; '
            "`pip install tensorboard` to view the runs), or train without it."
        ) from None


def hparams_of(config_mapping: Mapping[str, Any]) -> dict[str, bool | str | float]:
    """The config as TensorBoard hyperparameters: dotted keys, lists and nulls as JSON.

    >>> hparams_of({"seed": 3, "env": {"id": "CartPole-v1", "kwargs": {}},
    ...             "discretization": {"bins": [1, 6]}, "train": {"seeds": None}})
    {'seed': 3.0, 'env.id': 'CartPole-v1', 'env.kwargs': '{}', 'discretization.bins': '[1, 6]'}
    """
    flat: dict[str, bool | str | float] = {}
    for key, value in _flatten(config_mapping, ""):
        if key in SKIPPED_HPARAMS:
            continue
        if isinstance(value, bool | str):
            flat[key] = value
        elif isinstance(value, int | float):
            flat[key] = float(value)
        else:  # None, lists, an empty mapping: compared as their text
            flat[key] = json.dumps(value)
    return flat


def _flatten(mapping: Mapping[str, Any], prefix: str) -> Iterator[tuple[str, Any]]:
    for key, value in mapping.items():
        if isinstance(value, Mapping) and value:
            yield from _flatten(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def moving_means(values: np.ndarray, window: int = SOLVE_WINDOW) -> np.ndarray:
    """Mean of the last (up to) ``window`` values at each position, as SB3's ``ep_rew_mean``.

    >>> moving_means(np.array([1.0, 3.0, 5.0, 7.0]), window=2).tolist()
    [1.0, 2.0, 4.0, 6.0]
    """
    values = np.asarray(values, dtype=np.float64)
    return np.array(
        [values[max(0, i + 1 - window) : i + 1].mean() for i in range(len(values))],
        dtype=np.float64,
    )


@dataclass(frozen=True)
class Session:
    """What one run's event file holds, from whichever place the run was trained."""

    config: Mapping[str, Any]
    """the run's resolved config (``Config.to_dict()``), logged as hyperparameters"""
    result: SeedResult
    """what it achieved: the final scalars"""
    returns: np.ndarray
    lengths: np.ndarray
    epsilons: np.ndarray | None = None
    """each episode's exploration rate (a sweep or a tune trial does not keep them)"""
    alphas: np.ndarray | None = None
    evaluations: Sequence[Mapping[str, Any]] = ()
    """the periodic greedy evaluations (``evaluations.csv``'s records)"""
    steps_per_second: float | None = None
    """``summary.json``'s figure (default: the result's env steps per training second)"""


def write_tensorboard(run_dir: Path, result: TrainResult, steps_per_second: float) -> Path:
    """Write ``run_dir/tensorboard/`` from a training result; return the event file.

    Args:
        run_dir: the run directory.
        result: the run's training result (the whole history, also after a resume).
        steps_per_second: ``summary.json``'s figure, logged as ``charts/SPS``.

    Raises:
        UserError: ``tensorboardX`` is not installed.
        WriteError: the event file cannot be written.
    """
    from cartpole_q.results import SeedResult

    session = Session(
        result.config.to_dict(), SeedResult.of_train(result), result.metrics.returns,
        result.metrics.lengths, result.metrics.epsilons, result.metrics.alphas,
        result.evaluations, steps_per_second,
    )  # fmt: skip
    return write_session(run_dir / TENSORBOARD_DIR, session)


def write_session(directory: Path, session: Session) -> Path:
    """Write one run's event file into ``directory``; return its path.

    Earlier event files there (from the sessions before a resume, or a run a killed
    study had started) are removed once the new one, which holds the whole history, is
    in place.

    Raises:
        UserError: ``tensorboardX`` is not installed.
        WriteError: the event file cannot be written.
    """
    require_writer("train.tensorboard")
    make_directory(directory)
    earlier = sorted(directory.glob(f"{EVENT_FILE_PREFIX}*"))
    with tempfile.TemporaryDirectory(prefix="cartpole-q-tensorboard-") as scratch:
        _write_events(Path(scratch), session)
        (written,) = Path(scratch).glob(f"{EVENT_FILE_PREFIX}*")
        target = directory / written.name
        atomic_write_bytes(target, written.read_bytes())
    for stale in earlier:
        if stale != target:
            stale.unlink(missing_ok=True)
    return target


def final_scalars(session: Session) -> dict[str, float]:
    """The scalars logged once, at the last step: speed, the final evaluation, the solve.

    >>> from cartpole_q.results import SeedResult
    >>> result = SeedResult(0, 150, 30000, 120, 20000, 18000, 500.0, True, 475.0, 0.5)
    >>> final_scalars(Session({}, result, np.zeros(0), np.zeros(0)))
    {'charts/SPS': 60000.0, 'summary/eval_mean': 500.0, 'summary/success': 1.0, 'summary/solved_episode': 120.0}
    """
    result = session.result
    speed = session.steps_per_second
    if speed is None:
        speed = result.env_steps / result.train_seconds if result.train_seconds > 0 else 0.0
    finals = {"charts/SPS": float(speed)}
    if result.eval_mean is not None:
        finals["summary/eval_mean"] = float(result.eval_mean)
    if result.success is not None:
        finals["summary/success"] = float(result.success)
    if result.solved_episode is not None:
        finals["summary/solved_episode"] = float(result.solved_episode)
    return finals


def _write_events(scratch: Path, session: Session) -> None:
    from tensorboardX import SummaryWriter
    from tensorboardX.summary import hparams

    steps = np.cumsum(session.lengths, dtype=np.int64)
    last_step = int(steps[-1]) if len(steps) else 0
    per_episode = [
        ("charts/episodic_return", session.returns),
        ("charts/episodic_length", session.lengths),
        ("charts/epsilon", session.epsilons),
        ("charts/learning_rate", session.alphas),
        ("rollout/ep_rew_mean", moving_means(session.returns)),
        ("rollout/ep_len_mean", moving_means(session.lengths)),
    ]
    # Under agent.alpha: sample_average every episode's alpha is NaN: no chart rather than one of
    # nothing.
    columns = [
        (tag, values)
        for tag, values in per_episode
        if values is not None and not (len(values) and np.isnan(values).all())
    ]
    # max_queue: everything is written at once; one flush at close is enough.
    with SummaryWriter(str(scratch), max_queue=1000, flush_secs=3600) as writer:
        _, session_start, session_end = hparams(hparams_of(session.config), {})
        # Only the session's start and end, no experiment of its own: TensorBoard then
        # builds the HParams table from every run under its --logdir, this one included.
        writer.file_writer.add_summary(session_start)
        for index, step in enumerate(steps.tolist()):
            for tag, values in columns:
                writer.add_scalar(tag, float(values[index]), step)
        for record in session.evaluations:
            writer.add_scalar("eval/mean_reward", float(record["mean"]), int(record["env_steps"]))
        for tag, value in final_scalars(session).items():
            writer.add_scalar(tag, value, last_step)
        if not session.result.interrupted:
            # An interrupted run is unfinished: no end, so TensorBoard does not call it done.
            writer.file_writer.add_summary(session_end)
