"""An independent re-derivation of the policy-gradient contract, written from the text alone.

Source: ``docs/algorithms.md``, "Policy gradient" (the world, the seeds, the feature layers,
the policy, the draw, the eligibility vector, an episode, the three algorithms and the
figure's optimum), with the parts it refers to: "Feature layers" (under "Linear function
approximation": ``v_hat`` and *adding along*) and "How a world with a transition table
steps" and "Time limits" (under "Worlds"). It is plain Python on ``gymnasium.make`` and
imports nothing from ``cartpole_q``: the tests check that both of the package's engines give
its rewards, lengths and weights byte for byte.

The weights are lists of Python floats (IEEE float64) and every formula is evaluated as the
text writes it, parenthesised, left to right; every "summed in order" is an explicit loop
from ``0.0``; the exponential is ``math.exp``. NumPy serves only for the generators, the
returned arrays and the one LAPACK call the text names (``numpy.linalg.solve``).

The package's worlds are registered when ``cartpole_q`` is imported (the test session does
that); this module only calls ``gymnasium.make("cartpole_q/...")``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

ALGORITHMS = ("reinforce", "reinforce_baseline", "actor_critic", "actor_critic_lambda")
PER_STEP = ("actor_critic", "actor_critic_lambda")
CUT = 10_000  # an episode of a world without a time limit is cut after this many steps


# The world (docs/algorithms.md, "The world"; "How a world with a transition table steps").


@dataclass
class World:
    """A world: ``env``, ``table[s][a]`` (``P[s][a]``'s outcomes ``(p, s', r, terminated)`` in
    list order, ``p`` and ``r`` as floats), ``N``, ``n`` actions, the start distribution ``d_0``."""

    env: gymnasium.Env[Any, Any]
    table: list[list[list[tuple[float, int, float, bool]]]]
    n_states: int
    n: int
    start: list[float]


def make_world(env_id: str, kwargs: Mapping[str, Any]) -> World:
    """Make a registered world and read ``P``; a continuing one is refused, naming ``world``."""
    env = gymnasium.make(env_id, **dict(kwargs))
    raw = env.unwrapped.P  # type: ignore[attr-defined]
    assert isinstance(env.action_space, spaces.Discrete)
    n = int(env.action_space.n)
    n_states = len(raw)
    table = []
    episodic = False
    for s in range(n_states):
        per_action = []
        for a in range(n):
            outcomes = []
            for p, s2, r, terminated in raw[s][a]:
                outcomes.append((float(p), int(s2), float(r), bool(terminated)))
                episodic = episodic or bool(terminated)
            per_action.append(outcomes)
        table.append(per_action)
    if not episodic:
        env.close()
        raise ValueError("world: a policy-gradient study needs an episodic world")
    start = [float(h) for h in np.asarray(env.unwrapped.initial_state_distrib).tolist()]  # type: ignore[attr-defined]
    return World(env, table, n_states, n, start)


def current_state(env: gymnasium.Env[Any, Any]) -> int:
    """The state of ``P`` the world is in (the toy-text worlds' ``s``)."""
    return int(env.unwrapped.s)  # type: ignore[attr-defined]


# Feature layers (docs/algorithms.md, "Feature layers" of "Policy gradient").

Row = list[tuple[int, float]]


def observations(world: World) -> tuple[list[int], int]:
    """``o(s)`` per state (the state, or its group) and ``O``, the number of observations."""
    observed = getattr(world.env.unwrapped, "observation_of_state", None)
    if observed is None:
        return list(range(world.n_states)), world.n_states
    groups = [int(o) for o in np.asarray(observed).tolist()]
    space = world.env.observation_space
    count = int(space.n) if isinstance(space, spaces.Discrete) else max(groups) + 1
    return groups, count


def policy_layer(world: World, kind: str | None) -> tuple[list[list[Row]], int]:
    """The policy's rows ``rows[s][a]`` and ``d`` (``None``: ``declared`` if the world declares)."""
    declared = getattr(world.env.unwrapped, "features_of_action", None)
    if kind is None:
        kind = "table" if declared is None else "declared"
    n = world.n
    if kind == "declared":
        if declared is None:
            raise ValueError("policy_features: the world declares no features_of_action")
        array = np.asarray(declared, dtype=np.float64)
        d = int(array.shape[2])
        rows = []
        for s in range(world.n_states):
            per_action = []
            for a in range(n):
                values = [float(v) for v in array[s, a].tolist()]
                per_action.append([(i, values[i]) for i in range(d) if values[i] != 0.0])
            rows.append(per_action)
        return rows, d
    if kind == "table":
        o, count = observations(world)
        rows = [[[(o[s] * n + a, 1.0)] for a in range(n)] for s in range(world.n_states)]
        return rows, count * n
    raise ValueError(f"policy_features: unknown kind {kind!r}")


def value_layer(world: World, kind: str | None) -> tuple[list[Row], int]:
    """The value's rows ``rows[s]`` and ``d_w`` (``None``: ``constant``)."""
    if kind is None or kind == "constant":
        return [[(0, 1.0)] for _ in range(world.n_states)], 1
    if kind == "table":
        o, count = observations(world)
        return [[(o[s], 1.0)] for s in range(world.n_states)], count
    raise ValueError(f"value_features: unknown kind {kind!r}")


def v_hat(row: Row, w: list[float]) -> float:
    """``v_hat(s, w) = 0.0 + w[i_0] * x_0 + ...`` in row order."""
    total = 0.0
    for i, x in row:
        total = total + w[i] * x
    return total


def add_along(row: Row, w: list[float], amount: float) -> None:
    """*Adding ``amount`` along ``x(s)``*: ``w[i_j] = w[i_j] + amount * x_j`` in row order."""
    for i, x in row:
        w[i] = w[i] + amount * x


# The policy (docs/algorithms.md, "The policy").


def policy(rows_s: list[Row], theta: list[float], floor: float) -> list[float]:
    """``pi(a | s)`` for every action, from the rows of ``(s, a)`` and the current ``theta``.

    With a floor (two actions), the smaller probability (action 0 on a tie) is raised to it
    and the other's is ``1.0 - floor``.
    """
    h = []
    for row in rows_s:
        total = 0.0
        for i, x in row:
            total = total + theta[i] * x
        h.append(total)
    m = h[0]
    for value in h[1:]:
        if value > m:
            m = value
    e = [math.exp(value - m) for value in h]
    z = 0.0
    for value in e:
        z = z + value
    pi = [value / z for value in e]
    if floor > 0.0:
        low = 0 if pi[0] <= pi[1] else 1
        if pi[low] < floor:
            pi[low] = floor
            pi[1 - low] = 1.0 - floor
    return pi


def draw(rng: np.random.Generator, pi: list[float]) -> int:
    """One ``u = rng.random()``; the lowest ``a`` with ``u < c_a``, else the last with ``pi > 0``."""
    u = float(rng.random())
    c = 0.0
    for a, p in enumerate(pi):
        c = c + p
        if u < c:
            return a
    last = 0
    for a, p in enumerate(pi):
        if p > 0.0:
            last = a
    return last


def eligibility(rows_s: list[Row], a: int, theta: list[float], d: int, floor: float) -> list[float]:
    """``g = grad ln pi(a | s, theta)``, dense, with ``pi`` from ``theta`` as it is now."""
    pi = policy(rows_s, theta, floor)
    g = [0.0] * d
    for i, x in rows_s[a]:
        g[i] = g[i] + x
    for b in range(len(rows_s)):
        for i, x in rows_s[b]:
            g[i] = g[i] - pi[b] * x
    return g


def move(theta: list[float], k: float, g: list[float]) -> None:
    """*Moving ``theta`` by ``k``*: ``theta[i] = theta[i] + k * g[i]``, ``i`` ascending."""
    for i in range(len(theta)):
        theta[i] = theta[i] + k * g[i]


def _start_weights(value: float | Sequence[float], d: int, name: str) -> list[float]:
    if isinstance(value, (int, float)):
        return [float(value)] * d
    weights = [float(v) for v in value]
    if len(weights) != d:
        raise ValueError(f"{name}: {d} numbers needed, got {len(weights)}")
    return weights


# The run (docs/algorithms.md, "Seeds", "An episode", "Algorithms").


def run_policy_gradient(
    env_id: str,
    kwargs: Mapping[str, Any],
    gamma: float,
    algorithm: str,
    alpha: float,
    alpha_w: float,
    policy_features: str | None,
    value_features: str | None,
    theta0: float | Sequence[float],
    w0: float | Sequence[float],
    seed: int,
    episodes: int,
    min_probability: float = 0.0,
    lambda_theta: float = 0.0,
    lambda_w: float = 0.0,
) -> dict[str, np.ndarray]:
    """One run of a curve, as the contract states it.

    Returns:
        ``rewards`` (float64 ``(episodes,)``: each episode's total reward), ``lengths`` (int64
        ``(episodes,)``), and the final ``theta`` (float64 ``(d,)``) and ``w`` (float64
        ``(d_w,)``; ``reinforce`` leaves it at ``w0``).
    """
    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r}")
    gamma, alpha, alpha_w = float(gamma), float(alpha), float(alpha_w)
    world = make_world(env_id, kwargs)
    try:
        return _run(world, gamma, algorithm, alpha, alpha_w, policy_features, value_features,
                    theta0, w0, seed, int(episodes), float(min_probability),
                    (float(lambda_theta), float(lambda_w)))  # fmt: skip
    finally:
        world.env.close()


def _run(world: World, gamma: float, algorithm: str, alpha: float, alpha_w: float,
         policy_features: str | None, value_features: str | None,
         theta0: float | Sequence[float], w0: float | Sequence[float], seed: int,
         episodes: int, floor: float,
         lambdas: tuple[float, float]) -> dict[str, np.ndarray]:  # fmt: skip
    rows, d = policy_layer(world, policy_features)
    value_rows, d_w = value_layer(world, value_features)
    theta = _start_weights(theta0, d, "theta0")
    w = _start_weights(w0, d_w, "w0")

    env = world.env
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    env_seed = int(env_seq.generate_state(1, dtype=np.uint32)[0])

    rewards: list[float] = []
    lengths: list[int] = []
    for episode in range(episodes):
        env.reset(seed=env_seed if episode == 0 else None)
        s = current_state(env)
        states: list[int] = []
        actions: list[int] = []
        step_rewards: list[float] = []
        big_i = 1.0
        z_theta = [0.0] * d
        z_w = [0.0] * d_w
        while True:
            a = draw(rng, policy(rows[s], theta, floor))
            _, reward, terminated, truncated, _ = env.step(a)
            s2 = current_state(env)
            r = float(reward)
            terminated = bool(terminated)
            states.append(s)
            actions.append(a)
            step_rewards.append(r)
            cut = env.spec is not None and env.spec.max_episode_steps is None and len(states) >= CUT
            ended = terminated or bool(truncated) or cut
            if algorithm == "actor_critic":
                following = 0.0 if terminated else v_hat(value_rows[s2], w)
                delta = r + gamma * following - v_hat(value_rows[s], w)
                add_along(value_rows[s], w, alpha_w * delta)
                g = eligibility(rows[s], a, theta, d, floor)
                move(theta, (alpha * big_i) * delta, g)
                big_i = gamma * big_i
            elif algorithm == "actor_critic_lambda":
                following = 0.0 if terminated else v_hat(value_rows[s2], w)
                delta = r + gamma * following - v_hat(value_rows[s], w)
                for i in range(d_w):
                    z_w[i] = (gamma * lambdas[1]) * z_w[i]
                add_along(value_rows[s], z_w, 1.0)
                g = eligibility(rows[s], a, theta, d, floor)
                for i in range(d):
                    z_theta[i] = (gamma * lambdas[0]) * z_theta[i] + big_i * g[i]
                for i in range(d_w):
                    w[i] = w[i] + (alpha_w * delta) * z_w[i]
                for i in range(d):
                    theta[i] = theta[i] + (alpha * delta) * z_theta[i]
                big_i = gamma * big_i
            s = s2
            if ended:
                break
        steps = len(states)
        if algorithm not in PER_STEP:
            returns = [0.0] * steps
            big_g = 0.0
            for t in range(steps - 1, -1, -1):
                big_g = step_rewards[t] + gamma * big_g
                returns[t] = big_g
            k = 1.0
            for t in range(steps):
                if algorithm == "reinforce":
                    g = eligibility(rows[states[t]], actions[t], theta, d, floor)
                    move(theta, (alpha * k) * returns[t], g)
                else:
                    delta = returns[t] - v_hat(value_rows[states[t]], w)
                    add_along(value_rows[states[t]], w, alpha_w * delta)
                    g = eligibility(rows[states[t]], actions[t], theta, d, floor)
                    move(theta, (alpha * k) * delta, g)
                k = k * gamma
        total = 0.0
        for r in step_rewards:
            total = total + r
        rewards.append(total)
        lengths.append(steps)

    return {
        "rewards": np.array(rewards, dtype=np.float64).reshape(episodes),
        "lengths": np.array(lengths, dtype=np.int64).reshape(episodes),
        "theta": np.array(theta, dtype=np.float64),
        "w": np.array(w, dtype=np.float64),
    }


# The figure's optimum (docs/algorithms.md, "What is recorded and drawn").


def _start_value(world: World, p: float) -> float:
    """``0.0 + sum_s d_0(s) * v_p(s)``, ``v_p = solve(I - P_p, r_p)``, ``pi = (1.0 - p, p)``."""
    if world.n != 2:
        raise ValueError("figure.optimum: a world of two actions is needed")
    pi = [1.0 - p, p]
    n_states = world.n_states
    matrix = np.zeros((n_states, n_states))
    r_p = np.zeros(n_states)
    for s in range(n_states):
        r_total = 0.0
        for a in range(world.n):
            for prob, s2, r, terminated in world.table[s][a]:
                r_total = r_total + pi[a] * (prob * r)
                if not terminated:
                    matrix[s, s2] = float(matrix[s, s2]) + pi[a] * prob
        r_p[s] = r_total
    values = np.linalg.solve(np.eye(n_states) - matrix, r_p)
    total = 0.0
    for s in range(n_states):
        total = total + world.start[s] * float(values[s])
    return total


def start_value(env_id: str, kwargs: Mapping[str, Any], p: float) -> float:
    """The start value of the state-independent policy with ``P(action 1) = p``."""
    world = make_world(env_id, kwargs)
    try:
        return _start_value(world, float(p))
    finally:
        world.env.close()


def best_start_value(env_id: str, kwargs: Mapping[str, Any]) -> tuple[float, float]:
    """``(p, value)``: the largest start value over ``p = k / 10000``, ``k = 1 .. 9999``.

    The lowest ``k`` wins a tie (a later ``k`` replaces the best only when strictly larger).
    """
    world = make_world(env_id, kwargs)
    try:
        best_p, best = 0.0, -math.inf
        for k in range(1, 10_000):
            p = k / 10000
            value = _start_value(world, p)
            if k == 1 or value > best:
                best_p, best = p, value
        return best_p, best
    finally:
        world.env.close()
