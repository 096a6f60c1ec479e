"""Greedy evaluation of a Q-table: in real Gymnasium environments, or on their compiled twins.

``cartpole-q eval`` plays here, by default in ``gymnasium.make(env.id, **env.kwargs)`` (the
proof): the first episode's reset is seeded with the evaluation seed, later resets continue
that environment's random stream. ``--engine numba`` plays the same episodes on the
environment's compiled twin, which gives exactly the same returns (the twins are
bit-identical to Gymnasium, a test compares them) some thirty times faster (a hundred
seeds' tables of CartPole, 100 episodes each).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import MAX_EPISODES, Config, ConfigError, load_config
from cartpole_q.engines.base import AgentParams
from cartpole_q.engines.plan import env_facts
from cartpole_q.engines.play import FrameCallback, play_greedy
from cartpole_q.envs.gym import EnvInfo, config_time_limit, make_env
from cartpole_q.envs.models import GREEDY_STEP_CAP
from cartpole_q.errors import RunError

PLAY_ENGINES = {"gymnasium": "gymnasium", "numba": "twin"}
"""where each ``eval --engine`` plays, as ``played_in`` records it: ``gymnasium.make``, or
the numba engine's compiled twin of the environment"""

GreedyPlay = Callable[[np.ndarray, int, int], np.ndarray]
"""``play(q, episodes, seed)``: the returns of a 2-D ``(n_states, n_actions)`` table's greedy
policy over ``episodes`` episodes, the first reset seeded with ``seed``"""


@dataclass(frozen=True)
class EvalReport:
    """Returns of a greedy evaluation and their statistics."""

    returns: tuple[float, ...]
    """the return of each episode, in order"""
    seed: int
    """the seed of the first reset"""
    played_in: str | None = None
    """``gymnasium`` (``gymnasium.make``) or ``twin`` (the compiled twin); ``None``: not said"""

    @property
    def episodes(self) -> int:
        """Number of episodes played."""
        return len(self.returns)

    @property
    def mean(self) -> float:
        """Mean return."""
        return float(np.mean(self.returns))

    @property
    def std(self) -> float:
        """Population standard deviation of the returns."""
        return float(np.std(self.returns))

    def to_dict(self) -> dict[str, Any]:
        """Return ``mean, std, min, max, episodes, seed`` as ``eval --json`` prints them.

        ``played_in`` follows when the report says where it was played.
        """
        data: dict[str, Any] = {
            "mean": self.mean,
            "std": self.std,
            "min": float(np.min(self.returns)),
            "max": float(np.max(self.returns)),
            "episodes": self.episodes,
            "seed": self.seed,
        }
        if self.played_in is not None:
            data["played_in"] = self.played_in
        return data

    @classmethod
    def from_returns(
        cls, returns: np.ndarray, seed: int, played_in: str | None = None
    ) -> EvalReport:
        """Build a report from an array of returns."""
        return cls(returns=tuple(float(r) for r in returns), seed=seed, played_in=played_in)


def under_conditions(
    config: Config,
    physics: Mapping[str, Any] | None = None,
    max_steps: int | None = None,
    *,
    source: str = "--physics",
) -> Config:
    """The config with other physics (merged onto its ``env.physics``) or another horizon.

    Checked like a config: an unknown key, a bad value, or physics on an environment that
    is not CartPole is a ``ConfigError`` naming it and ``source`` (the option that gave
    the physics: ``eval --physics``, ``robustness --vary``; the horizon is ``--max-steps``).

    Another horizon also judges success by the environment's own threshold for it
    (``train.reward_threshold`` becomes null: CartPole's 475 of 500 steps scales, 9,500 at
    10,000 steps): a threshold the run was trained with is a stopping rule for its own
    horizon (``robust``'s 1995 of 2000 steps), no yardstick at another one.
    """
    overrides: dict[str, Any] = {}
    if physics:
        overrides["env.physics"] = {**config.env.physics, **physics}
    if max_steps is not None:
        overrides["env.kwargs.max_episode_steps"] = max_steps
        explicit = config.train.reward_threshold is not None
        if explicit and max_steps != config_time_limit(config):
            overrides["train.reward_threshold"] = None
    if not overrides:
        return config
    label = source if physics else "--max-steps"
    return load_config(config.to_dict(), overrides, source="run config", override_source=label)


def evaluate(
    q_table: np.ndarray,
    config: Config,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    render_mode: str | None = None,
    on_frame: FrameCallback | None = None,
    engine: str = "gymnasium",
) -> EvalReport:
    """Evaluate a Q-table's greedy policy in ``gymnasium.make`` (or on its compiled twin).

    Args:
        q_table: the table, shape ``(*bins, n_actions)`` as saved in ``q_table.npy``.
        config: the config it was trained with (environment and discretisation).
        episodes: episodes to play; default ``config.eval.episodes``.
        seed: seed of the first reset; default ``config.eval.seed``.
        render_mode: passed to ``gymnasium.make`` (``rgb_array`` for video, ``human``).
        on_frame: called after every reset and step.
        engine: ``gymnasium`` (``gymnasium.make``), or ``numba``: the compiled twin, the
            same returns exactly (see :func:`greedy_play`).

    Raises:
        ConfigError: ``episodes`` is not between 1 and ``MAX_EPISODES``; ``numba`` where
            the environment has no twin, or with ``render_mode`` or ``on_frame``.
        RunError: the table does not fit the config and environment.
    """
    (report,) = evaluate_tables(
        [q_table], config, episodes=episodes, seed=seed, render_mode=render_mode,
        on_frame=on_frame, engine=engine,
    )  # fmt: skip
    return report


def evaluate_tables(
    q_tables: Sequence[np.ndarray],
    config: Config,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    render_mode: str | None = None,
    on_frame: FrameCallback | None = None,
    engine: str = "gymnasium",
) -> list[EvalReport]:
    """Evaluate several Q-tables of one config (a multi-seed run's seeds), as :func:`evaluate`.

    The environment is inspected, and on the twin the compiled play loaded, once for all.

    Raises:
        ConfigError, RunError: as :func:`evaluate` (a table is named by its position).
    """
    episodes = config.eval.episodes if episodes is None else episodes
    if not 1 <= episodes <= MAX_EPISODES:
        raise ConfigError(
            f"--episodes: must be between 1 and {MAX_EPISODES:,} greedy episodes, got {episodes:,}."
        )
    env_info = env_facts(config)
    for number, q_table in enumerate(q_tables):
        name = "the Q-table" if len(q_tables) == 1 else f"Q-table {number + 1}"
        check_q_table(q_table, env_info.state_shape, env_info.n_actions, name)
    seed = config.eval.seed if seed is None else seed
    play = greedy_play(config, env_info, engine, render_mode=render_mode, on_frame=on_frame)
    reports = []
    for q_table in q_tables:
        returns = play(q_table.reshape(-1, env_info.n_actions), episodes, seed)
        reports.append(EvalReport.from_returns(returns, seed, PLAY_ENGINES[engine]))
    return reports


def greedy_play(
    config: Config,
    env_info: EnvInfo,
    engine: str = "gymnasium",
    *,
    render_mode: str | None = None,
    on_frame: FrameCallback | None = None,
) -> GreedyPlay:
    """Greedy play under ``config``'s environment (physics and time limit included).

    ``gymnasium`` plays each call in a fresh ``gymnasium.make``: the proof. ``numba`` plays
    on the environment's compiled twin, the numba engine's own evaluation: the same returns,
    bit for bit, where a twin reproduces the environment under these settings (the twins'
    tests compare them step by step, and ``eval --engine numba`` against the default).

    Raises:
        ConfigError: ``numba`` where no twin reproduces the environment (naming why), or
            with ``render_mode`` or ``on_frame`` (a twin draws nothing).
    """
    if engine not in PLAY_ENGINES:
        raise ConfigError(f"--engine {engine}: choose one of {', '.join(PLAY_ENGINES)}.")
    if engine == "numba":
        from cartpole_q.engines import make_engine
        from cartpole_q.envs.registry import TwinSettings, twin_settings

        if render_mode is not None or on_frame is not None:
            raise ConfigError(
                "--engine numba plays on the compiled twin, which draws nothing: record or "
                "show episodes in gymnasium.make (--engine gymnasium, the default)."
            )
        settings = twin_settings(
            config.env.id, config.env.kwargs, env_info.max_episode_steps, config.env.physics
        )
        if not isinstance(settings, TwinSettings):
            raise ConfigError(
                f"--engine numba: {settings}; play in gymnasium.make (--engine gymnasium, "
                "the default)."
            )
        twin = make_engine("numba", config, env_info, env_seed=0, twin=settings)
        return twin.evaluate
    params = AgentParams.from_config(config, env_info)
    step_cap = None if env_info.max_episode_steps else GREEDY_STEP_CAP

    def play(q: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        env = make_env(config.env, render_mode=render_mode)
        try:
            return play_greedy(
                env, q, params.grid, episodes, seed, on_frame, step_cap, params.tilings
            )
        finally:
            env.close()

    return play


def check_q_table(
    q_table: np.ndarray, bins: tuple[int, ...] | None, n_actions: int | None, source: str
) -> None:
    """Check a Q-table against its config's grid (and the environment's actions).

    Args:
        q_table: the table.
        bins: its shape without the action axis (the grid's bins, or a Discrete
            observation's sizes); ``None``: unknown here (no grid), checked against the
            environment later.
        n_actions: the environment's actions, if known.
        source: the file or object named in errors.

    Raises:
        RunError: wrong dtype or shape, or a non-finite value.
    """
    if q_table.dtype != np.float64:
        raise RunError(f"{source}: must hold float64 values, found {q_table.dtype}.")
    check_q_table_shape(q_table.shape, bins, n_actions, source)
    if not np.isfinite(q_table).all():
        raise RunError(f"{source}: holds NaN or infinite values.")


def check_q_table_shape(
    shape: tuple[int, ...], bins: tuple[int, ...] | None, n_actions: int | None, source: str
) -> None:
    """Check a Q-table's shape alone (as :func:`check_q_table` does), e.g. a file's header.

    >>> check_q_table_shape((1, 1, 2, 10, 2), (1, 1, 2, 10), 2, "q.npy")
    >>> check_q_table_shape((16, 4), (1, 1, 2, 10), None, "q.npy")
    Traceback (most recent call last):
    ...
    cartpole_q.errors.RunError: q.npy: has shape (16, 4), which does not match its config: expected (*bins, n_actions) = (1, 1, 2, 10, n_actions).

    Raises:
        RunError: the shape is not ``(*bins, n_actions)``.
    """
    shape = tuple(shape)
    if bins is None:
        if len(shape) < 2:
            raise RunError(f"{source}: has shape {shape}; expected (*states, n_actions).")
        bins = shape[:-1]
    expected = f"(*bins, n_actions) = ({', '.join(map(str, bins))}, {n_actions or 'n_actions'})"
    if len(shape) != len(bins) + 1 or shape[:-1] != tuple(bins):
        raise RunError(
            f"{source}: has shape {shape}, which does not match its config: expected {expected}."
        )
    if n_actions is not None and shape[-1] != n_actions:
        raise RunError(
            f"{source}: has {shape[-1]} actions per state but the environment has "
            f"{n_actions}: expected {expected}."
        )


@dataclass(frozen=True)
class ExactReport:
    """A greedy policy's exact expected return beside the optimum, from the environment's model.

    ``return``: undiscounted, within the episode's step limit (the time limit, or the
    greedy cap where there is none), from the start distribution: what ``eval``'s mean
    estimates (for FrozenLake the success probability). The optimum here is the best of
    all policies, also those that change with the steps left (backward induction).
    ``discounted``: infinite-horizon, with the run's ``agent.gamma`` (what the agent
    optimises; left out when ``gamma`` is 1). ``gap`` = optimum - greedy.
    """

    note: str
    """what ``return`` measures, in a few words"""
    horizon: int
    gamma: float
    optimum: float
    greedy: float | None
    optimum_discounted: float | None
    greedy_discounted: float | None
    optimal_policy: tuple[int, ...] = ()
    """the best first action per Q-table row (undiscounted, all steps left), lowest on ties"""

    def to_dict(self) -> dict[str, Any]:
        """The figures as ``eval --json`` adds them (``greedy`` and ``gap`` only with a table)."""
        optimum: dict[str, Any] = {"return": self.optimum, "horizon": self.horizon}
        if self.optimum_discounted is not None:
            optimum.update(discounted=self.optimum_discounted, gamma=self.gamma)
        result: dict[str, Any] = {"optimum": optimum, "note": self.note}
        if self.greedy is not None:
            greedy: dict[str, Any] = {"return": self.greedy}
            gap: dict[str, Any] = {"return": self.optimum - self.greedy}
            if self.greedy_discounted is not None and self.optimum_discounted is not None:
                greedy["discounted"] = self.greedy_discounted
                gap["discounted"] = self.optimum_discounted - self.greedy_discounted
            result.update(greedy=greedy, gap=gap)
        return result


def exact_report(
    config: Config, q_table: np.ndarray | None = None, gamma: float | None = None
) -> ExactReport | str:
    """The optimum (and ``q_table``'s greedy policy) computed exactly, or why it cannot be.

    Args:
        config: the environment (``env``) and, unless ``gamma`` is given, the discount.
        q_table: a learned table, shape ``(*states, n_actions)``; ``None``: the optimum alone.
        gamma: the discount of the discounted figures (default ``config.agent.gamma``).

    Returns:
        The report, or a sentence saying why the environment has no exact model.
    """
    from cartpole_q.rl.solvers import policy_horizon_values, policy_values

    gamma = config.agent.gamma if gamma is None else gamma
    found = _model(config.env.id, _frozen(config.env.kwargs))
    if isinstance(found, str):
        return found
    env_model, note = found
    optimum, optimum_discounted, best = _optimum(config.env.id, _frozen(config.env.kwargs), gamma)
    greedy = greedy_discounted = None
    if q_table is not None:
        rows = q_table.reshape(-1, q_table.shape[-1])
        if rows.shape[0] <= int(env_model.row_of_state.max()):
            raise RunError(
                f"the Q-table has {rows.shape[0]} states, fewer than the environment's model."
            )
        policy = np.argmax(rows[env_model.row_of_state], axis=1)
        greedy = policy_horizon_values(env_model.model, policy, env_model.horizon).start_value
        if gamma < 1.0:
            greedy_discounted = policy_values(env_model.model, policy, gamma).start_value
    return ExactReport(
        note, env_model.horizon, gamma, optimum, greedy, optimum_discounted, greedy_discounted,
        best,
    )  # fmt: skip


def _frozen(kwargs: Mapping[str, Any]) -> str:
    import json

    return json.dumps(dict(kwargs), sort_keys=True, default=str)


@functools.cache
def _model(env_id: str, kwargs_json: str) -> tuple[Any, str] | str:
    """The environment's exact model (built once per process) and what its values mean."""
    import json

    from cartpole_q.config import EnvConfig
    from cartpole_q.envs.models import env_model, optimum_note

    found = env_model(EnvConfig(id=env_id, kwargs=json.loads(kwargs_json)))
    if isinstance(found, str):
        return found
    return found, optimum_note(found)


@functools.cache
def _optimum(
    env_id: str, kwargs_json: str, gamma: float
) -> tuple[float, float | None, tuple[int, ...]]:
    from cartpole_q.rl.solvers import finite_horizon, value_iteration

    found = _model(env_id, kwargs_json)
    assert not isinstance(found, str)
    env_model = found[0]
    within = finite_horizon(env_model.model, env_model.horizon)
    discounted = value_iteration(env_model.model, gamma).start_value if gamma < 1.0 else None
    n_rows = int(env_model.row_of_state.max()) + 1
    best = np.zeros(n_rows, dtype=np.int64)
    best[env_model.row_of_state] = within.policy  # a natural's row is its observation's
    best[env_model.row_of_state[:n_rows]] = within.policy[:n_rows]
    return within.start_value, discounted, tuple(int(a) for a in best)
