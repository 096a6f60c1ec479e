"""An independent re-derivation of the average-reward contract, written from the text alone.

Source: ``docs/algorithms.md``, "Average reward" (the world, the seeds, the layer, the
choice, ``differential_sarsa``, what is recorded, the optimum), with the parts it refers
to: "How a world with a transition table steps" and "Access control" (under "Worlds"), and
design.md's epsilon-greedy. It is plain Python on ``gymnasium.make`` and imports nothing from
``cartpole_q``: the tests check that both of the package's engines give its records and
weights byte for byte, and that its relative value iteration gives the package's gain.

The weights are a list of Python floats (IEEE float64) and every formula is evaluated as the
text writes it, parenthesised, left to right; every "summed in order" is an explicit loop
from ``0.0``. NumPy serves only for the generators and the returned arrays.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium
import numpy as np


def run_differential_sarsa(
    env_id: str, kwargs: Mapping[str, Any], alpha: float, beta: float, epsilon: float,
    w0: float, r_bar0: float, seed: int, steps: int, record_every: int,
) -> dict[str, np.ndarray]:  # fmt: skip
    """One run with the ``table`` layer: the records, the final ``w`` and the visits."""
    env = gymnasium.make(env_id, **dict(kwargs))
    n = int(env.action_space.n)  # type: ignore[attr-defined]
    n_states = len(env.unwrapped.P)  # type: ignore[attr-defined]
    w = [float(w0)] * (n_states * n)  # table: the pair (s * n + a, 1.0)
    r_bar = float(r_bar0)
    visits = [0] * n_states
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    env.reset(seed=int(env_seq.generate_state(1, dtype=np.uint32)[0]))

    def q(s: int, a: int) -> float:
        return 0.0 + w[s * n + a] * 1.0

    def greedy(s: int) -> int:
        best = 0
        for a in range(1, n):
            if q(s, a) > q(s, best):
                best = a
        return best

    def choose(s: int) -> int:
        if epsilon <= 0.0:
            return greedy(s)
        if epsilon >= 1.0:
            return int(rng.integers(0, n))
        if rng.random() < epsilon:
            return int(rng.integers(0, n))
        return greedy(s)

    state = int(env.unwrapped.s)  # type: ignore[attr-defined]
    action = choose(state)
    at, r_bars, rates = [], [], []
    since, total = 0, 0.0
    for t in range(1, steps + 1):
        _, reward, _, _, _ = env.step(action)
        following = int(env.unwrapped.s)  # type: ignore[attr-defined]
        next_action = choose(following)
        visits[state] += 1
        delta = ((float(reward) - r_bar) + q(following, next_action)) - q(state, action)
        r_bar = r_bar + beta * delta
        w[state * n + action] = w[state * n + action] + (alpha * delta) * 1.0
        state, action = following, next_action
        total = total + float(reward)
        since += 1
        if t % record_every == 0 or t == steps:
            at.append(t)
            r_bars.append(r_bar)
            rates.append(total / since)
            since, total = 0, 0.0
    env.close()
    return {
        "at": np.array(at, dtype=np.int64), "r_bar": np.array(r_bars), "rate": np.array(rates),
        "w": np.array(w), "visits": np.array(visits, dtype=np.int64),
    }  # fmt: skip


def relative_value_iteration(env_id: str, kwargs: Mapping[str, Any]) -> tuple[float, list[int]]:
    """The optimal gain and policy as "Average reward" states them (plain loops)."""
    env = gymnasium.make(env_id, **dict(kwargs))
    table = env.unwrapped.P  # type: ignore[attr-defined]
    n = int(env.action_space.n)  # type: ignore[attr-defined]
    env.close()
    n_states = len(table)

    def backups(v: list[float]) -> list[list[float]]:
        found = []
        for s in range(n_states):
            row = []
            for a in range(n):
                total = 0.0
                for p, following, r, _ in table[s][a]:
                    total = total + p * (r + v[following])
                row.append(total)
            found.append(row)
        return found

    v = [0.0] * n_states
    while True:
        t_v = [max(row) for row in backups(v)]
        change = [t_v[s] - v[s] for s in range(n_states)]
        gain = t_v[0]
        v = [t_v[s] - gain for s in range(n_states)]
        if max(change) - min(change) <= 1e-12:
            break
    policy = []
    for row in backups(v):
        values = [x - gain for x in row]
        best = max(values)
        policy.append(next(a for a in range(n) if values[a] >= best - 1e-9))
    return gain, policy
