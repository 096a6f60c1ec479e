"""Checkpoints: everything ``train --resume`` needs, in one atomic ``checkpoint.npz``.

Arrays are stored as arrays (``allow_pickle=False``): ``q``, ``visits``, the algorithm's
memory as ``memory_0``, ``memory_1``, ... (whatever it keeps: Double Q-learning's second
table, traces, buffers, a model), the metrics, ``solved_q``, and with ``train.info_metric``
the per-episode ``info`` sums; the rest (generator states,
the config the run was trained with, counters) as one JSON string. Checkpoints written
before algorithms kept memory stored Double Q-learning's second table as ``q_b`` (empty for
the others): it loads as ``memory_0``.
"""

from __future__ import annotations

import io
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cartpole_q.config import Config, load_config, load_yaml_text, shorten
from cartpole_q.engines.base import EpisodeMetrics, Tables
from cartpole_q.errors import RunError
from cartpole_q.store.atomic import atomic_write_bytes
from cartpole_q.store.reading import load_npz
from cartpole_q.training import Checkpoint

CHECKPOINT_FILE = "checkpoint.npz"
MAX_META_CHARS = 16 * 2**20
"""the longest meta record read (a checkpoint's is a few kilobytes, its config included)"""
MEMORY_PREFIX = "memory_"
"""the keys of the algorithm's memory arrays: ``memory_0``, ``memory_1``, ..."""
INFO_ARRAY = "info"
"""the finished episodes' sums of ``info[train.info_metric]``, when the config names one"""
ERRORS_ARRAY = "rms_errors"
"""a prediction run's finished episodes' RMS errors, when it measures them"""


def write_checkpoint(run_dir: Path, checkpoint: Checkpoint) -> None:
    """Save a :class:`~cartpole_q.training.Checkpoint` as one atomic ``checkpoint.npz``."""
    atomic_write_bytes(run_dir / CHECKPOINT_FILE, checkpoint_bytes(checkpoint))


def checkpoint_bytes(checkpoint: Checkpoint) -> bytes:
    """The ``checkpoint.npz`` file's bytes (a worker on another machine sends them back)."""
    meta = {
        "engine": checkpoint.engine,
        "episode": checkpoint.episode,
        "env_steps": checkpoint.env_steps,
        "agent_rng_state": checkpoint.agent_rng_state,
        "env_rng_state": checkpoint.env_rng_state,
        "physics_rng_state": checkpoint.physics_rng_state,
        "solved_episode": checkpoint.solved_episode,
        "evaluations": checkpoint.evaluations,
        "train_seconds": checkpoint.train_seconds,
        "wall_seconds": checkpoint.wall_seconds,
        "config": None if checkpoint.config is None else checkpoint.config.to_yaml(),
    }
    tables = checkpoint.tables
    arrays = {
        "q": tables.q,
        "visits": tables.visits,
        **{f"{MEMORY_PREFIX}{index}": array for index, array in enumerate(tables.memory)},
        **checkpoint.metrics._asdict(),  # returns, lengths, epsilons, alphas
        "meta": np.array(json.dumps(meta)),
    }
    if checkpoint.solved_q is not None:
        arrays["solved_q"] = checkpoint.solved_q
    if checkpoint.info is not None:  # train.info_metric's sums (absent without it)
        arrays[INFO_ARRAY] = checkpoint.info
    if checkpoint.errors is not None:  # a prediction run's errors (absent without them)
        arrays[ERRORS_ARRAY] = checkpoint.errors
    buffer = io.BytesIO()
    np.savez(buffer, allow_pickle=False, **arrays)
    return buffer.getvalue()


def load_checkpoint(run_dir: Path) -> Checkpoint:
    """Read ``checkpoint.npz`` back as a :class:`~cartpole_q.training.Checkpoint`.

    Raises:
        RunError: the checkpoint is missing or damaged.
    """
    path = run_dir / CHECKPOINT_FILE
    if not path.is_file():
        raise RunError(f"{path}: no checkpoint; there is nothing to resume in {run_dir}.")
    try:
        content = path.read_bytes()
    except OSError as error:
        raise RunError(
            f"{path}: the checkpoint is damaged and cannot be resumed ({error})."
        ) from None
    return checkpoint_from_bytes(content, str(path))


def checkpoint_from_bytes(content: bytes, where: str) -> Checkpoint:
    """A checkpoint back from its file's bytes (``where`` names it in errors).

    Raises:
        RunError: the bytes are not a checkpoint.
    """
    try:
        data = load_npz(content, where)
        meta = _meta(data)
        return Checkpoint(
            engine=meta["engine"],
            episode=int(meta["episode"]),
            env_steps=int(meta["env_steps"]),
            tables=Tables(q=data["q"], visits=data["visits"], memory=_memory(data)),
            metrics=EpisodeMetrics(*(data[name] for name in EpisodeMetrics._fields)),
            agent_rng_state=meta["agent_rng_state"],
            env_rng_state=meta["env_rng_state"],
            # checkpoints older than env.randomize have none (nothing was drawn)
            physics_rng_state=meta.get("physics_rng_state"),
            solved_episode=meta["solved_episode"],
            solved_q=data.get("solved_q"),
            evaluations=meta["evaluations"],
            train_seconds=float(meta["train_seconds"]),
            wall_seconds=float(meta["wall_seconds"]),
            config=_checkpoint_config(meta.get("config")),
            info=data.get(INFO_ARRAY),
            errors=data.get(ERRORS_ARRAY),
        )
    except (ValueError, KeyError, TypeError, RecursionError) as error:
        # RunError (a damaged archive) and ConfigError (its recorded config) are ValueErrors
        raise _damaged(where, error) from None


def _damaged(where: str, error: BaseException) -> RunError:
    detail = str(error).removeprefix(f"{where}: ")
    return RunError(
        f"{where}: the checkpoint is damaged and cannot be resumed ({shorten(detail, 200)})."
    )


def _meta(data: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """The checkpoint's JSON record (its generator states, config, counters)."""
    text = str(data["meta"])
    if len(text) > MAX_META_CHARS:
        raise ValueError("its meta record is larger than any checkpoint writes")
    meta = json.loads(text)
    if not isinstance(meta, dict):
        raise ValueError("its meta is not a JSON object")
    return meta


def _memory(data: Mapping[str, np.ndarray]) -> tuple[np.ndarray, ...]:
    """The algorithm's memory arrays, in order (an old checkpoint's ``q_b`` as the first)."""
    count = sum(1 for name in data if name.startswith(MEMORY_PREFIX))
    if count:
        return tuple(data[f"{MEMORY_PREFIX}{index}"] for index in range(count))
    if "q_b" in data and data["q_b"].size:
        return (data["q_b"],)
    return ()


def _checkpoint_config(text: Any) -> Config | None:
    """The config a checkpoint recorded (``None`` for checkpoints older than that)."""
    if text is None:
        return None
    try:
        data = load_yaml_text(text)
    except yaml.YAMLError:
        raise ValueError("its recorded config is not valid YAML") from None
    if not isinstance(data, dict):
        raise ValueError("its recorded config is not a mapping")
    return load_config(data)


def read_checkpoint_meta(run_dir: Path) -> dict[str, Any] | None:
    """The small part of ``checkpoint.npz`` (episode, engine, ...), without its arrays.

    Returns:
        ``None`` when there is no checkpoint.

    Raises:
        RunError: the checkpoint is damaged.
    """
    path = run_dir / CHECKPOINT_FILE
    if not path.is_file():
        return None
    try:
        return _meta(load_npz(path, str(path)))
    except (ValueError, KeyError, TypeError, RecursionError) as error:
        raise _damaged(str(path), error) from None
