"""Average reward on a continuing task: differential semi-gradient SARSA (Sutton & Barto 10.3).

The agent learns action values ``q̂(s, a, w) = wᵀx(s, a)`` on a layer of state-action rows
(one row per pair ``s * n + a``: the ``table`` layer is one weight per observation and
action, the tabular case) and ``R̄``, its estimate of the reward per step. Each step of the
book's box (page 251): ``δ = R - R̄ + q̂(S', A') - q̂(S, A)``, ``R̄ = R̄ + β δ``, ``w = w + alpha δ
∇q̂(S, A)``, the actions ε-greedy on ``q̂``. Every function here is compiled by the engines
(:mod:`cartpole_q.engines.average_reward`); the arithmetic and its order are the contract of
docs/algorithms.md ("Average reward"), which ``tests/reference_average_reward.py``
re-derives.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from cartpole_q.rl.linear import add_along, estimate
from cartpole_q.rl.tabular import compilable

ALGORITHMS = ("differential_sarsa",)
CODES = {name: code for code, name in enumerate(ALGORITHMS)}
LAYERS = ("table", "declared")
"""the action-value layers: one weight per (observation, action), or the world's own
features of its actions"""


class Agent(NamedTuple):
    """One curve's learner: step sizes, exploration, its layer, ``w`` and ``R̄``."""

    code: int
    """the algorithm (:data:`CODES`)"""
    alpha: float
    beta: float
    """``R̄``'s step size"""
    epsilon: float
    n_actions: int
    feature_index: np.ndarray
    """int64 ``(N * n, K)``: the layer's rows, row ``s * n + a``"""
    feature_value: np.ndarray
    w: np.ndarray
    """float64 ``(d,)``"""
    r_bar: np.ndarray
    """float64 ``(1,)``: ``R̄``"""
    visits: np.ndarray
    """int64 ``(N,)``: the steps taken from each state"""


def new_agent(
    algorithm: str, alpha: float, beta: float, epsilon: float, n_actions: int,
    rows: tuple[np.ndarray, np.ndarray], w0: np.ndarray, r_bar0: float, n_states: int,
) -> Agent:  # fmt: skip
    """An agent at its start: ``w = w0`` (copied), ``R̄ = r_bar0``, no visits."""
    return Agent(
        CODES[algorithm], float(alpha), float(beta), float(epsilon), int(n_actions), rows[0],
        rows[1], w0.astype(np.float64, copy=True), np.array([float(r_bar0)]),
        np.zeros(n_states, dtype=np.int64),
    )  # fmt: skip


@compilable
def action_value(agent: Any, state: int, action: int) -> float:
    """``q̂(state, action, w)``: the row's ``w[i] * x`` summed in row order from 0.0."""
    return estimate(
        agent.feature_index, agent.feature_value, agent.w, state * agent.n_actions + action
    )


@compilable
def greedy(agent: Any, state: int) -> int:
    """The lowest action with the largest ``q̂(state, ·)``."""
    best = action_value(agent, state, 0)
    chosen = 0
    for action in range(1, agent.n_actions):
        found = action_value(agent, state, action)
        if found > best:
            best, chosen = found, action
    return chosen


@compilable
def choose(agent: Any, state: int, rng: Any) -> int:
    """ε-greedy, as design.md draws it.

    ε ≤ 0: greedy, nothing drawn; ε ≥ 1: ``rng.integers(0, n)``; else ``rng.random() < ε``
    decides, then ``rng.integers(0, n)`` when exploring.
    """
    if agent.epsilon <= 0.0:
        return greedy(agent, state)
    if agent.epsilon >= 1.0:
        return int(rng.integers(0, agent.n_actions))
    if rng.random() < agent.epsilon:
        return int(rng.integers(0, agent.n_actions))
    return greedy(agent, state)


@compilable
def learn_step(
    agent: Any, state: int, action: int, reward: float, following: int, next_action: int
) -> None:
    """One step of differential semi-gradient SARSA, after ``next_action`` was drawn.

    ``δ = ((R - R̄) + q̂(S', A')) - q̂(S, A)`` with both values from ``w`` before the step;
    then ``R̄ = R̄ + β * δ``; then ``w`` moves by ``alpha * δ`` along ``x(S, A)``.
    """
    agent.visits[state] += 1
    now = action_value(agent, state, action)
    later = action_value(agent, following, next_action)
    delta = ((reward - agent.r_bar[0]) + later) - now
    agent.r_bar[0] = agent.r_bar[0] + agent.beta * delta
    add_along(
        agent.feature_index,
        agent.feature_value,
        agent.w,
        state * agent.n_actions + action,
        agent.alpha * delta,
    )
