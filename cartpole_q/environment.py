"""Gymnasium environments: making them, and checking a config against one.

Everything that can be wrong about a config only once the environment is known (an
unknown id, unsupported spaces, a grid of the wrong dimension, a Q-table too large to
allocate) is found here, before any run directory exists.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from dataclasses import dataclass
from typing import Any

from cartpole_q.config import Config, ConfigError, EnvConfig

SOLVE_WINDOW = 100
"""episodes in the moving average of training returns compared with the reward threshold"""


@dataclass(frozen=True)
class EnvInfo:
    """What training needs to know about an environment."""

    id: str
    """the Gymnasium id"""
    observation_dim: int
    """length of the 1-D Box observation"""
    n_actions: int
    """size of the Discrete action space"""
    reward_threshold: float | None
    """return that counts as solved (config's ``train.reward_threshold`` or the env's)"""
    max_episode_steps: int | None
    """the time limit after which an episode is truncated"""


def make_env(env: EnvConfig, render_mode: str | None = None) -> Any:
    """Return ``gymnasium.make(env.id, **env.kwargs)``, optionally with a render mode."""
    import gymnasium

    kwargs = dict(env.kwargs)
    if render_mode is not None:
        kwargs["render_mode"] = render_mode
    with warnings.catch_warnings():
        # Gymnasium warns about out-of-date versions such as CartPole-v0; the user chose it.
        warnings.simplefilter("ignore", category=DeprecationWarning)
        return gymnasium.make(env.id, **kwargs)


def inspect_env(config: Config, source: str = "config") -> EnvInfo:
    """Make the config's environment once and check that the config can train on it.

    Args:
        config: the validated config.
        source: the config's file (or another label) for error messages.

    Raises:
        ConfigError: naming ``env.id``, ``env.kwargs``, ``discretization.bins`` or
            ``agent.max_q_table_bytes``, when the environment cannot be made, its spaces
            are not a 1-D Box and a Discrete, the grid's dimension differs from the
            observation's, or the Q-table would exceed the size limit.
    """
    import gymnasium
    from gymnasium import spaces

    env_id = config.env.id
    try:
        env = make_env(config.env)
    except gymnasium.error.DependencyNotInstalled as error:
        raise ConfigError(
            f"{source}: env.id: {env_id!r} needs a package that is not installed ({error})."
        ) from None
    except gymnasium.error.Error as error:
        raise ConfigError(f"{source}: env.id: cannot make {env_id!r}: {error}") from None
    except TypeError as error:
        raise ConfigError(
            f"{source}: env.kwargs: {env_id!r} does not accept these arguments ({error})."
        ) from None
    try:
        observation_space, action_space, spec = env.observation_space, env.action_space, env.spec
    finally:
        env.close()
    if not isinstance(action_space, spaces.Discrete) or int(action_space.start) != 0:
        raise ConfigError(
            f"{source}: env.id: {env_id!r} has action space {action_space}; tabular "
            "Q-learning here needs Discrete actions numbered from 0."
        )
    if not isinstance(observation_space, spaces.Box) or len(observation_space.shape) != 1:
        raise ConfigError(
            f"{source}: env.id: {env_id!r} has observation space {observation_space}; the "
            "discretiser needs a 1-D Box."
        )
    observation_dim = int(observation_space.shape[0])
    bins = config.discretization.bins
    if len(bins) != observation_dim:
        raise ConfigError(
            f"{source}: discretization.bins: has {len(bins)} entries but {env_id!r} "
            f"observations have {observation_dim} dimensions; give bins, low and high "
            "one entry per dimension."
        )
    n_actions = int(action_space.n)
    table_bytes = q_table_bytes(bins, n_actions)
    limit = config.agent.max_q_table_bytes
    if table_bytes > limit:
        raise ConfigError(
            f"{source}: discretization.bins: the Q-table would hold {math.prod(bins):,} "
            f"states x {n_actions} actions = {_size(table_bytes)}, above the limit of "
            f"{_size(limit)} (agent.max_q_table_bytes); use fewer bins or raise the limit."
        )
    threshold = config.train.reward_threshold
    if threshold is None and spec is not None and spec.reward_threshold is not None:
        threshold = float(spec.reward_threshold)
    max_steps = config.env.kwargs.get("max_episode_steps", spec.max_episode_steps if spec else None)
    return EnvInfo(
        id=env_id,
        observation_dim=observation_dim,
        n_actions=n_actions,
        reward_threshold=threshold,
        max_episode_steps=max_steps,
    )


def q_table_bytes(bins: tuple[int, ...], n_actions: int) -> int:
    """Bytes of a float64 Q-table of shape ``(*bins, n_actions)``."""
    return math.prod(bins) * n_actions * 8


def has_display() -> bool:
    """Whether a window can be opened: on Linux and BSD, an X11 or Wayland display is set.

    macOS and Windows open windows without these variables.
    """
    if sys.platform == "darwin" or sys.platform.startswith("win"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _size(n_bytes: int) -> str:
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:,.1f} {unit}"
    return f"{n_bytes} bytes"
