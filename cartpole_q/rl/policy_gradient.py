"""Policy-gradient methods: a softmax policy on linear preferences, and its updates (13.1-13.5).

The policy in state ``s`` is the softmax of ``h(s, a, θ) = θᵀx(s, a)`` over the actions
(Sutton & Barto eq. 13.2), ``x(s, a)`` a row of the policy's feature layer (pairs of a
weight index and a value, one row per state-action pair ``s * n + a``). REINFORCE (13.3),
REINFORCE with a baseline (13.4) and one-step actor-critic (13.5) move ``θ`` along the
eligibility vector ``∇ ln π(a | s, θ)``; the last two also learn ``v̂(s, w) = wᵀx(s)`` on a
second layer. Every function here is compiled by the engines
(:mod:`cartpole_q.engines.policy_gradient`); the arithmetic and its order are the contract
of docs/algorithms.md ("Policy gradient"), which ``tests/reference_policy_gradient.py``
re-derives.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.rl.linear import add_along, estimate
from cartpole_q.rl.tabular import compilable

ALGORITHMS = ("reinforce", "reinforce_baseline", "actor_critic", "actor_critic_lambda")
CODES = {name: code for code, name in enumerate(ALGORITHMS)}
REINFORCE, REINFORCE_BASELINE, ACTOR_CRITIC, ACTOR_CRITIC_LAMBDA = range(len(ALGORITHMS))
WITH_VALUE = ("reinforce_baseline", "actor_critic", "actor_critic_lambda")
"""the algorithms that learn ``v̂`` too (and take ``alpha_w``)"""
PER_STEP = ("actor_critic", "actor_critic_lambda")
"""the algorithms that learn after every step (the others after the episode)"""
WITH_TRACES = ("actor_critic_lambda",)
"""the algorithms that take ``lambda_theta`` and ``lambda_w``"""
POLICY_LAYERS = ("declared", "table")
VALUE_LAYERS = ("constant", "table")


class Agent(NamedTuple):
    """One curve's learner: its algorithm, step sizes, both layers, and room to work in."""

    code: int
    """the algorithm (:data:`CODES`)"""
    alpha: float
    """the policy's step size (the book's alpha, or alpha^theta)"""
    alpha_w: float
    gamma: float
    floor: float
    """two actions: the least probability either may have (0.0: none; Zhang's script: 0.05)"""
    lambda_theta: float
    lambda_w: float
    """the traces' decays (actor-critic with traces)"""
    n_actions: int
    policy_index: np.ndarray
    """int64 ``(N * n, K)``: the policy layer's rows, row ``s * n + a``"""
    policy_value: np.ndarray
    theta: np.ndarray
    """float64 ``(d,)``"""
    value_index: np.ndarray
    """int64 ``(N, K_w)``: the value layer's rows"""
    value_value: np.ndarray
    w: np.ndarray
    """float64 ``(d_w,)``"""
    probabilities: np.ndarray
    """float64 ``(n,)``: room for ``π(· | s)``"""
    gradient: np.ndarray
    """float64 ``(d,)``: room for ``∇ ln π``"""
    trace_theta: np.ndarray
    """float64 ``(d,)``: ``z^θ`` (actor-critic with traces)"""
    trace_w: np.ndarray
    """float64 ``(d_w,)``: ``z^w``"""


class Settings(NamedTuple):
    """A curve's step sizes, discount, floor and trace decays: what :func:`new_agent` copies."""

    alpha: float
    """the policy's step size (the book's alpha, or alpha^theta)"""
    alpha_w: float
    """the value layer's step size (0.0 without one)"""
    gamma: float
    floor: float = 0.0
    """two actions: the least probability either may have (0.0: none)"""
    lambdas: tuple[float, float] = (0.0, 0.0)
    """``(λ^θ, λ^w)``: the traces' decays (actor-critic with traces)"""


class Layer(NamedTuple):
    """A linear layer at its start: its rows (pairs of a weight index and a value) and weights."""

    indices: np.ndarray
    """int64 ``(rows, K)``: each row's weight indices"""
    values: np.ndarray
    """float64 ``(rows, K)``: each row's feature values"""
    weights: np.ndarray
    """the start weights (copied by :func:`new_agent`)"""


def new_agent(
    algorithm: str, settings: Settings, n_actions: int, policy_layer: Layer, value_layer: Layer
) -> Agent:
    """An agent at its start: ``θ`` and ``w`` copied from the layers' start weights."""
    theta0, w0 = policy_layer.weights, value_layer.weights
    return Agent(
        CODES[algorithm], float(settings.alpha), float(settings.alpha_w), float(settings.gamma),
        float(settings.floor), float(settings.lambdas[0]), float(settings.lambdas[1]),
        int(n_actions),
        policy_layer.indices, policy_layer.values, theta0.astype(np.float64, copy=True),
        value_layer.indices, value_layer.values, w0.astype(np.float64, copy=True),
        np.zeros(n_actions), np.zeros(theta0.shape[0]), np.zeros(theta0.shape[0]),
        np.zeros(w0.shape[0]),
    )  # fmt: skip


@compilable
def policy(agent: Any, state: int) -> None:
    """``agent.probabilities = π(· | state)``: the softmax of the preferences, from the largest.

    With a floor (two actions), the smaller probability is raised to it.
    """
    n = agent.n_actions
    out = agent.probabilities
    for a in range(n):
        out[a] = estimate(agent.policy_index, agent.policy_value, agent.theta, state * n + a)
    largest = out[0]
    for a in range(1, n):
        if out[a] > largest:
            largest = out[a]
    for a in range(n):
        out[a] = math.exp(out[a] - largest)
    total = 0.0
    for a in range(n):
        total = total + out[a]
    for a in range(n):
        out[a] = out[a] / total
    if agent.floor > 0.0:  # two actions: the smaller (action 0 on a tie) raised to the floor
        low = 0 if out[0] <= out[1] else 1
        if out[low] < agent.floor:
            out[low] = agent.floor
            out[1 - low] = 1.0 - agent.floor


@compilable
def draw(probabilities: Any, rng: Any) -> int:
    """One ``rng.random()`` against the running sums; the last possible action if none is above."""
    u = rng.random()
    running = 0.0
    for a in range(probabilities.shape[0]):
        running = running + probabilities[a]
        if u < running:
            return a
    last: int = probabilities.shape[0] - 1
    while last > 0 and not probabilities[last] > 0.0:
        last -= 1
    return last


@compilable
def choose(agent: Any, state: int, rng: Any) -> int:
    """The action drawn from ``π(· | state)`` with the current ``θ``."""
    policy(agent, state)
    return draw(agent.probabilities, rng)


@compilable
def eligibility(agent: Any, state: int, action: int) -> None:
    """``agent.gradient = ∇ ln π(action | state, θ)``, from the current ``θ``."""
    policy(agent, state)
    n = agent.n_actions
    index, value, g = agent.policy_index, agent.policy_value, agent.gradient
    for i in range(g.shape[0]):
        g[i] = 0.0
    row = state * n + action
    for j in range(index.shape[1]):
        g[index[row, j]] = g[index[row, j]] + value[row, j]
    for b in range(n):
        row = state * n + b
        for j in range(index.shape[1]):
            g[index[row, j]] = g[index[row, j]] - agent.probabilities[b] * value[row, j]


@compilable
def move_policy(agent: Any, state: int, action: int, amount: float) -> None:
    """``θ = θ + amount * ∇ ln π(action | state, θ)``, the gradient from the current ``θ``."""
    eligibility(agent, state, action)
    theta, g = agent.theta, agent.gradient
    for i in range(theta.shape[0]):
        theta[i] = theta[i] + amount * g[i]


@compilable
def learn_episode(
    agent: Any, states: Any, actions: Any, rewards: Any, length: int, returns: Any
) -> None:
    """REINFORCE (with or without a baseline) after an episode of ``length`` steps.

    ``states[t]`` is ``S_t``, ``actions[t]`` is ``A_t``, ``rewards[t]`` is ``R_{t+1}``.
    """
    g = 0.0
    for t in range(length - 1, -1, -1):
        g = rewards[t] + agent.gamma * g
        returns[t] = g
    k = 1.0
    for t in range(length):
        state = states[t]
        if agent.code == REINFORCE_BASELINE:
            delta = returns[t] - estimate(agent.value_index, agent.value_value, agent.w, state)
            add_along(agent.value_index, agent.value_value, agent.w, state, agent.alpha_w * delta)
            move_policy(agent, state, actions[t], (agent.alpha * k) * delta)
        else:
            move_policy(agent, state, actions[t], (agent.alpha * k) * returns[t])
        k = k * agent.gamma


@compilable
def learn_step(
    agent: Any, state: int, action: int, reward: float, following: int, terminated: bool,
    discount: Any,
) -> None:  # fmt: skip
    """Actor-critic after a step (one-step, or with traces); ``discount[0]`` is the episode's ``I``."""
    index, value, w = agent.value_index, agent.value_value, agent.w
    after = 0.0 if terminated else estimate(index, value, w, following)
    delta = reward + agent.gamma * after - estimate(index, value, w, state)
    if agent.code == ACTOR_CRITIC_LAMBDA:
        _traces_step(agent, state, action, delta, discount[0])
    else:
        add_along(index, value, w, state, agent.alpha_w * delta)
        move_policy(agent, state, action, (agent.alpha * discount[0]) * delta)
    discount[0] = agent.gamma * discount[0]


@compilable
def _traces_step(agent: Any, state: int, action: int, delta: float, discount: float) -> None:
    """Actor-critic with traces (13.5): both traces decay and grow, then both weights move."""
    z_w, z_theta = agent.trace_w, agent.trace_theta
    decay_w = agent.gamma * agent.lambda_w
    for i in range(z_w.shape[0]):
        z_w[i] = decay_w * z_w[i]
    add_along(agent.value_index, agent.value_value, z_w, state, 1.0)
    eligibility(agent, state, action)
    g = agent.gradient
    decay_theta = agent.gamma * agent.lambda_theta
    for i in range(z_theta.shape[0]):
        z_theta[i] = decay_theta * z_theta[i] + discount * g[i]
    step_w = agent.alpha_w * delta
    w = agent.w
    for i in range(w.shape[0]):
        w[i] = w[i] + step_w * z_w[i]
    step_theta = agent.alpha * delta
    theta = agent.theta
    for i in range(theta.shape[0]):
        theta[i] = theta[i] + step_theta * z_theta[i]


@compilable
def clear_traces(agent: Any) -> None:
    """``z^θ = z^w = 0`` (an episode's start)."""
    for i in range(agent.trace_theta.shape[0]):
        agent.trace_theta[i] = 0.0
    for i in range(agent.trace_w.shape[0]):
        agent.trace_w[i] = 0.0
