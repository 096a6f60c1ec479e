"""Playing a policy-gradient run: episodes of the learned policy, the agent updated.

Two engines play a run with the same compiled updates (:mod:`cartpole_q.rl.policy_gradient`)
and the same draws, so their records agree byte for byte (``tests/test_policy_gradient.py``):

- ``numba``: compiled episodes over the world's table (the table twin), up to
  :data:`~cartpole_q.engines.linear.EPISODES_PER_CALL` episodes per call;
- ``gymnasium``: a Python loop over ``gymnasium.make(world)``, the draws and the updates
  compiled.

A call ends after at most :data:`~cartpole_q.engines.linear.EPISODES_PER_CALL` episodes,
or sooner, after the episode that reaches
:data:`~cartpole_q.engines.linear.STEPS_PER_CALL` steps (a policy that never reaches the
goal plays 10,000-step episodes); between calls the run's ``should_stop`` is asked, so a
stop is seen within a fraction of a second. **Seeds** as a linear run's (:func:`~cartpole_q.engines.linear.run_generators`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.engines.compile import LoopSet
from cartpole_q.engines.linear import EPISODES_PER_CALL, STEPS_PER_CALL, World, run_generators
from cartpole_q.families.tables.twin import initial_state, table_step
from cartpole_q.rl.policy_gradient import (
    ACTOR_CRITIC,
    Agent,
    choose,
    clear_traces,
    learn_episode,
    learn_step,
)

ENGINES = ("numba", "gymnasium")


class Buffers(NamedTuple):
    """Room for one episode of up to ``cap`` steps, and the records of a chunk."""

    states: np.ndarray
    """int64 ``(cap + 1,)``"""
    actions: np.ndarray
    rewards: np.ndarray
    returns: np.ndarray
    discount: np.ndarray
    """float64 ``(1,)``: actor-critic's ``I``"""


def new_buffers(cap: int) -> Buffers:
    """Empty room for an episode of ``cap`` steps."""
    return Buffers(
        np.zeros(cap + 1, dtype=np.int64), np.zeros(cap, dtype=np.int64), np.zeros(cap),
        np.zeros(cap), np.ones(1),
    )  # fmt: skip


def _play_episodes(
    agent: Any, params: Any, agent_rng: Any, env_rng: Any, cap: int, buffers: Any,
    totals: Any, lengths: Any, most_steps: int,
) -> int:  # fmt: skip
    """Up to ``len(totals)`` episodes on the table (compiled), each one's reward and length kept.

    Returns after the episode that brings the steps to ``most_steps`` (a call stays short
    when episodes are long): the number of episodes played.
    """
    states, actions, rewards, returns, discount = buffers
    steps = 0
    for episode in range(totals.shape[0]):
        state = initial_state(params, env_rng)
        states[0] = state
        discount[0] = 1.0
        clear_traces(agent)
        length = 0
        total = 0.0
        while True:
            action = choose(agent, state, agent_rng)
            following, reward, terminated = table_step(state, action, env_rng, params)
            actions[length] = action
            rewards[length] = reward
            total = total + reward
            length += 1
            states[length] = following
            if agent.code >= ACTOR_CRITIC:
                learn_step(agent, state, action, reward, following, terminated, discount)
            state = following
            if terminated or length >= cap:
                break
        if agent.code < ACTOR_CRITIC:
            learn_episode(agent, states, actions, rewards, length, returns)
        totals[episode] = total
        lengths[episode] = length
        steps += length
        if steps >= most_steps:
            return episode + 1
    return int(totals.shape[0])


LOOP_NAMES = (
    "policy_gradient_play_episodes", "policy_gradient_choose", "policy_gradient_learn_step",
    "policy_gradient_learn_episode", "policy_gradient_clear_traces",
)  # fmt: skip
"""the compiled functions, by their cache names"""
LOOPS = LoopSet(
    dict(zip(LOOP_NAMES, (_play_episodes, choose, learn_step, learn_episode, clear_traces),
             strict=True)),
    "compiling the policy-gradient loops: once per machine and version, a few seconds...",
)  # fmt: skip
compiled = LOOPS
"""``compiled(name)``: the compiled function cached on disk under ``name``"""
compile_notice = LOOPS.notice
"""a sentence when the loops are not compiled yet (the first run), else ``None``"""


class Records(NamedTuple):
    """A run's records: every episode's total reward and length."""

    totals: np.ndarray
    """float64 ``(episodes,)``"""
    lengths: np.ndarray
    """int64 ``(episodes,)``"""


def run(
    agent: Agent, world: World, seed: int, episodes: int, engine: str,
    should_stop: Callable[[], bool] = lambda: False,
    report: Callable[[int], None] = lambda n: None,
) -> Records | None:  # fmt: skip
    """Play ``episodes`` episodes of one run; ``None`` when ``should_stop`` ended it early."""
    totals = np.zeros(episodes)
    lengths = np.zeros(episodes, dtype=np.int64)
    chunk = (_numba_chunk if engine == "numba" else _gymnasium_chunk)(agent, world, seed)
    done = 0
    while done < episodes:
        if should_stop():
            return None
        size = min(EPISODES_PER_CALL, episodes - done)
        done += chunk(totals[done : done + size], lengths[done : done + size])
        report(done)
    return Records(totals, lengths)


Chunk = Callable[[np.ndarray, np.ndarray], int]
"""plays up to ``len(totals)`` episodes (fewer once they took :data:`STEPS_PER_CALL`
steps), filling ``totals`` and ``lengths``; returns how many it played"""


def _numba_chunk(agent: Agent, world: World, seed: int) -> Chunk:
    """Episodes on the compiled table."""
    agent_rng, env_seed = run_generators(seed)
    env_rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(env_seed)))
    buffers = new_buffers(world.cap)
    episodes = compiled("policy_gradient_play_episodes")
    return lambda totals, lengths: int(
        episodes(
            agent,
            world.params,
            agent_rng,
            env_rng,
            world.cap,
            buffers,
            totals,
            lengths,
            STEPS_PER_CALL,
        )
    )


def _gymnasium_chunk(agent: Agent, world: World, seed: int) -> Chunk:
    """Episodes on ``gymnasium.make``: the loop in Python, the draws and updates compiled."""
    agent_rng, env_seed = run_generators(seed)
    env = world.make()
    choose_action = compiled("policy_gradient_choose")
    step_update = compiled("policy_gradient_learn_step")
    episode_update = compiled("policy_gradient_learn_episode")
    new_episode = compiled("policy_gradient_clear_traces")
    buffers = new_buffers(world.cap)
    seeds = [env_seed]

    def episodes(totals: np.ndarray, lengths: np.ndarray) -> int:
        steps = 0
        for episode in range(totals.shape[0]):
            env.reset(seed=seeds.pop() if seeds else None)
            state = int(env.unwrapped.s)
            buffers.states[0] = state
            buffers.discount[0] = 1.0
            new_episode(agent)
            length, total = 0, 0.0
            while True:
                action = int(choose_action(agent, state, agent_rng))
                _, reward, terminated, cut, _ = env.step(action)
                following = int(env.unwrapped.s)
                buffers.actions[length] = action
                buffers.rewards[length] = float(reward)
                total = total + float(reward)
                length += 1
                buffers.states[length] = following
                if agent.code >= ACTOR_CRITIC:
                    step_update(
                        agent, state, action, float(reward), following, bool(terminated),
                        buffers.discount,
                    )  # fmt: skip
                state = following
                if terminated or cut or length >= world.cap:
                    break
            if agent.code < ACTOR_CRITIC:
                episode_update(
                    agent, buffers.states, buffers.actions, buffers.rewards, length,
                    buffers.returns,
                )  # fmt: skip
            totals[episode] = total
            lengths[episode] = length
            steps += length
            if steps >= STEPS_PER_CALL:
                return episode + 1
        return int(totals.shape[0])

    return episodes


def warm_up() -> None:
    """Compile (or load from the cache) every loop: a tiny run of each algorithm on each engine.

    The loops take every world and layer alike (their argument types do not change), so
    this compiles what every policy-gradient study plays (``cartpole-q compile --all``).
    """
    from cartpole_q.engines.linear import warm_up_world
    from cartpole_q.rl.policy_gradient import ALGORITHMS, Layer, Settings, new_agent

    world, n_states, n_actions = warm_up_world("cartpole_q/ShortCorridor-v0", False, 20)
    policy_rows = (
        np.arange(n_states * n_actions, dtype=np.int64).reshape(-1, 1),
        np.ones((n_states * n_actions, 1)),
    )
    value_rows = (np.zeros((n_states, 1), dtype=np.int64), np.ones((n_states, 1)))
    for algorithm in ALGORITHMS:
        for engine in ENGINES:
            agent = new_agent(
                algorithm, Settings(0.01, 0.01, 1.0, 0.05, (0.5, 0.5)), n_actions,
                Layer(*policy_rows, np.zeros(n_states * n_actions)), Layer(*value_rows, np.zeros(1)),
            )  # fmt: skip
            run(agent, world, 0, 1, engine)
