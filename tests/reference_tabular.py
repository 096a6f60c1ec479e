"""An independent re-derivation of the training contract for Discrete and Tuple observations.

Written from ``design.md`` alone ("Discrete observations", "Randomness and the training
loop", "Algorithms"), in plain Python on ``gymnasium.make``: it imports nothing from
``cartpole_q``. The tests check that the package's run is byte-identical to it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces


@dataclass
class ReferenceRun:
    q_table: np.ndarray
    visits: np.ndarray
    returns: list[float]
    lengths: list[int]
    solved_episode: int | None


def exponential(start: float, decay: float, end: float) -> Any:
    return lambda episode: max(end, start * decay ** float(episode))


def constant(value: float) -> Any:
    return lambda episode: value


def reference_train(
    env_id: str,
    *,
    algorithm: str,
    gamma: float,
    alpha: Any,
    epsilon: Any,
    q_init: float,
    episodes: int,
    seed: int,
    threshold: float | None,
    kwargs: dict[str, Any] | None = None,
) -> ReferenceRun:
    env = gymnasium.make(env_id, **(kwargs or {}))
    space = env.observation_space
    components = space.spaces if isinstance(space, spaces.Tuple) else (space,)
    sizes = [int(c.n) for c in components]
    starts = [int(c.start) for c in components]

    def row(observation: Any) -> int:
        values = observation if isinstance(space, spaces.Tuple) else (observation,)
        index = 0
        for k, size in enumerate(sizes):
            index = index * size + (int(values[k]) - starts[k])
        return index

    n = int(env.action_space.n)
    shape = (math.prod(sizes), n)
    q = np.full(shape, q_init, dtype=np.float64)
    q_b = np.full(shape, q_init, dtype=np.float64)
    double = algorithm == "double_q_learning"
    visits = np.zeros(shape, dtype=np.int64)
    agent_seq, env_seq, _ = np.random.SeedSequence(seed).spawn(3)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    env_seed = int(env_seq.generate_state(1, dtype=np.uint32)[0])

    def greedy(s: int) -> int:
        values = q[s] + q_b[s] if double else q[s]
        return int(np.argmax(values))

    def choose(s: int, eps: float) -> int:
        if eps <= 0.0:
            return greedy(s)
        if eps >= 1.0 or rng.random() < eps:
            return int(rng.integers(0, n))
        return greedy(s)

    returns: list[float] = []
    lengths: list[int] = []
    solved = None
    for episode in range(episodes):
        eps, rate = epsilon(episode), alpha(episode)
        observation, _ = env.reset(seed=env_seed if episode == 0 else None)
        s = row(observation)
        a = choose(s, eps)
        episode_return, length = 0.0, 0
        while True:
            observation, reward, terminated, truncated, _ = env.step(a)
            length += 1
            episode_return += reward
            s2 = row(observation)
            r = float(reward)
            visits[s, a] += 1
            ended = terminated or truncated
            a2 = -1
            if algorithm == "q_learning":
                y = r if terminated else r + gamma * float(np.max(q[s2]))
                q[s, a] += rate * (y - q[s, a])
            elif algorithm == "sarsa":
                y = r
                if not terminated:
                    a2 = choose(s2, eps)
                    y = r + gamma * q[s2, a2]
                q[s, a] += rate * (y - q[s, a])
            elif algorithm == "expected_sarsa":
                y = r
                if not terminated:
                    total = q[s2, 0]
                    for b in range(1, n):
                        total += q[s2, b]
                    g = int(np.argmax(q[s2]))
                    y = r + gamma * ((1.0 - eps) * q[s2, g] + (eps / n) * total)
                q[s, a] += rate * (y - q[s, a])
            else:
                if rng.random() < 0.5:
                    y = r if terminated else r + gamma * q_b[s2, int(np.argmax(q[s2]))]
                    q[s, a] += rate * (y - q[s, a])
                else:
                    y = r if terminated else r + gamma * q[s2, int(np.argmax(q_b[s2]))]
                    q_b[s, a] += rate * (y - q_b[s, a])
            if ended:
                break
            if algorithm != "sarsa":
                a2 = choose(s2, eps)
            s, a = s2, a2
        returns.append(episode_return)
        lengths.append(length)
        if threshold is not None and episode >= 99:
            total_return = 0.0
            for value in returns[episode - 99 : episode + 1]:
                total_return += value
            if total_return / 100 >= threshold:
                solved = episode + 1
                break
    env.close()
    kept = 0.5 * (q + q_b) if double else q
    return ReferenceRun(
        kept.reshape(*sizes, n), visits.reshape(*sizes, n), returns, lengths, solved
    )
