"""An independent re-derivation of the linear-study contract, written from the text alone.

Source: ``docs/algorithms.md``, "Linear function approximation" (the world, the policies, the
seeds, the feature layers, the run, the algorithms, the errors and the fixed points), with
the parts it refers to: "The tile rule" (under "Tile coding"), "How a world with a
transition table steps", "The 1000-state walk" and "Baird's counterexample" (under
"Worlds"), and "The error" and "State aggregation" (under "Prediction": the reachable and
measured states, ``v_pi`` and the on-policy distribution). It is plain Python on
``gymnasium.make`` and imports nothing from ``cartpole_q``: the tests check that both of the
package's engines give its weights and errors byte for byte.

The weights are lists of Python floats (IEEE float64) and every formula is evaluated as the
text writes it, parenthesised, left to right; every "summed in order" is an explicit loop
from ``0.0``. NumPy serves only for the generators, the returned arrays and the three LAPACK
calls the text names (``numpy.linalg.solve``, ``pinv`` and ``lstsq``).

Where the text allows it, a sum skips terms that are exactly ``±0.0`` products of a zero
feature value (from ``0.0``, adding a zero never changes a finite sum's bits): the matrix
``C`` of the PBE and the TD fixed point's ``A`` and ``c`` are summed over the nonzero
features of each state's row, in the order the dense sum would take them. Everything the
weights pass through (the updates, ``v_hat``, ``delta_bar``, ``g``, ``u``, ``z``) is summed densely.

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

ON_POLICY = ("gradient_mc", "semi_gradient_td", "lstd")
"""Algorithms that need ``behaviour`` equal to ``target`` (on every world)."""

CONTINUING_ONLY = (
    "off_policy_td",
    "tdc",
    "gtd2",
    "emphatic_td",
    "semi_gradient_dp",
    "expected_tdc",
    "expected_emphatic_td",
)
"""Algorithms the text states for continuing worlds."""

EPISODIC_ONLY = ("gradient_mc",)
"""Gradient Monte Carlo learns from an episode's returns."""

EXPECTED = ("semi_gradient_dp", "expected_tdc", "expected_emphatic_td")
"""Algorithms that sweep the model and draw nothing."""

SAMPLED = ("gradient_mc", "semi_gradient_td", "lstd", "off_policy_td", "tdc", "gtd2", "emphatic_td")
"""Algorithms that step the world."""


# The world (docs/algorithms.md, "The world", "How a world with a transition table steps").


@dataclass
class World:
    """A world's transition table and what the study reads from it.

    Attributes:
        env: The environment, from ``gymnasium.make``.
        table: ``table[s][a]``, the outcomes ``(p, s', r, terminated)`` of ``P[s][a]`` in
            list order (``p`` and ``r`` as Python floats).
        n_states: ``N``, the number of states of ``P``.
        n: The number of actions.
        start: The start distribution ``h`` (``initial_state_distrib``), as floats.
        episodic: Whether some outcome of ``P`` terminates.
    """

    env: gymnasium.Env[Any, Any]
    table: list[list[list[tuple[float, int, float, bool]]]]
    n_states: int
    n: int
    start: list[float]
    episodic: bool


def make_world(env_id: str, kwargs: Mapping[str, Any]) -> World:
    """Make a registered world and read its transition table.

    Args:
        env_id: The registered id (``cartpole_q/Baird-v0``, ...).
        kwargs: ``world.kwargs``, forwarded to ``gymnasium.make``.

    Returns:
        The world.
    """
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
    start = [float(h) for h in np.asarray(env.unwrapped.initial_state_distrib).tolist()]  # type: ignore[attr-defined]
    return World(env, table, n_states, n, start, episodic)


def policy_probabilities(spec: str | Sequence[Any], n: int) -> list[float]:
    """A policy's probabilities, the same in every state ("Policies").

    Args:
        spec: ``"random"`` (``1.0 / n`` per action) or a list of ``n`` probabilities (numbers,
            or fractions written ``"6/7"``, read as ``6.0 / 7.0``).
        n: The number of actions.

    Returns:
        The ``n`` probabilities as floats.

    Raises:
        ValueError: A list of the wrong length, a negative entry, or a sum off 1 by 1e-9.
    """
    if isinstance(spec, str):
        if spec != "random":
            raise ValueError(f"unknown policy {spec!r}")
        return [1.0 / n] * n
    probabilities = []
    for item in spec:
        if isinstance(item, str) and "/" in item:
            top, bottom = item.split("/")
            probabilities.append(float(top) / float(bottom))
        else:
            probabilities.append(float(item))
    if len(probabilities) != n:
        raise ValueError(f"a policy of {n} actions needs {n} probabilities")
    total = 0.0
    for p in probabilities:
        if p < 0.0:
            raise ValueError("a probability is negative")
        total = total + p
    if abs(total - 1.0) > 1e-9:
        raise ValueError("the probabilities do not sum to 1")
    return probabilities


def behaviour_action(rng: np.random.Generator, spec: str | Sequence[Any], b: list[float]) -> int:
    """The behaviour's action: ``rng.integers(0, n)`` for ``random``, else one ``rng.random()``.

    Args:
        rng: The agent's generator.
        spec: The behaviour as the study gives it (``"random"`` or a list).
        b: Its probabilities.

    Returns:
        The action: the lowest ``a`` with ``u < c_a`` (``c_a`` the running sum from 0.0), or,
        if rounding leaves none, the last action with ``b(a) > 0``.
    """
    n = len(b)
    if isinstance(spec, str):
        return int(rng.integers(0, n))
    u = float(rng.random())
    c = 0.0
    for a in range(n):
        c = c + b[a]
        if u < c:
            return a
    last = 0
    for a in range(n):
        if b[a] > 0.0:
            last = a
    return last


def current_state(env: gymnasium.Env[Any, Any]) -> int:
    """The state of ``P`` the world is in (the toy-text worlds' ``s``)."""
    return int(env.unwrapped.s)  # type: ignore[attr-defined]


# Feature layers (docs/algorithms.md, "Feature layers"; "The tile rule").


@dataclass
class Layer:
    """Every state's row of ``(index, value)`` pairs and the number of weights ``d``.

    Attributes:
        rows: ``rows[s]``, the pairs ``(i_j, x_j)`` of state ``s`` in row order.
        d: The number of weights.
    """

    rows: list[list[tuple[int, float]]]
    d: int

    def dense(self, s: int) -> list[float]:
        """The dense ``x(s)``: ``x_j`` at ``i_j``, ``0.0`` elsewhere."""
        x = [0.0] * self.d
        for i, value in self.rows[s]:
            x[i] = value
        return x


def _bounds(space: spaces.Space[Any]) -> tuple[list[float], list[float]]:
    assert isinstance(space, spaces.Box)
    low = [float(v) for v in np.asarray(space.low, dtype=np.float32).reshape(-1).tolist()]
    high = [float(v) for v in np.asarray(space.high, dtype=np.float32).reshape(-1).tolist()]
    return low, high


def _exponents(order: int, k: int) -> list[tuple[int, ...]]:
    """Every ``c`` of ``{0 .. order}^k`` in C order (the last component fastest)."""
    vectors: list[tuple[int, ...]] = [()]
    for _ in range(k):
        vectors = [(*vector, e) for vector in vectors for e in range(order + 1)]
    return vectors


def tile_rows(
    point: Sequence[float], bins: list[int], lows: list[float], highs: list[float], tilings: int
) -> list[int]:
    """The tile rule (docs/algorithms.md): the ``T`` rows of a point, in tiling order.

    Args:
        point: The point (float32 values, widened).
        bins: ``bins_d`` per dimension (one-bin dimensions are ignored).
        lows: ``low_d``.
        highs: ``high_d``.
        tilings: ``T``.

    Returns:
        ``row_t`` for ``t = 0 .. T - 1``: the C-order index of ``(t, coord_0, ...)`` in
        ``(T, bins_0 + 1, ...)`` over the binned dimensions.
    """
    xs = [float(x) for x in np.asarray(point, dtype=np.float32).reshape(-1).tolist()]
    rows = []
    for t in range(tilings):
        row, k = t, 0
        for dim, x in enumerate(xs):
            if bins[dim] <= 1:
                continue
            v = (x - lows[dim]) / (highs[dim] - lows[dim]) * bins[dim]
            if not v >= 0.0:
                v = 0.0
            elif v > bins[dim]:
                v = float(bins[dim])
            offset = (t * (1 + 2 * k)) % tilings
            coord = (math.floor(v * tilings) + offset) // tilings
            row = row * (bins[dim] + 1) + coord
            k += 1
        rows.append(row)
    return rows


def make_layer(world: World, features: Mapping[str, Any]) -> Layer:
    """A feature layer's rows for every state of ``P``.

    Args:
        world: The world.
        features: ``{"kind": ...}`` with the kind's keys (``bins``, ``low``, ``high``,
            ``tilings``; ``order``).

    Returns:
        The layer.

    Raises:
        ValueError: An unknown kind, or a kind the world cannot give (no points, no declared
            features).
    """
    unwrapped = world.env.unwrapped
    kind = features["kind"]
    n_states = world.n_states
    rows: list[list[tuple[int, float]]] = []
    if kind == "table":
        observed = getattr(unwrapped, "observation_of_state", None)
        if observed is None:
            d = n_states
            rows = [[(s, 1.0)] for s in range(n_states)]
        else:
            groups = [int(o) for o in np.asarray(observed).tolist()]
            space = world.env.observation_space
            d = int(space.n) if isinstance(space, spaces.Discrete) else max(groups) + 1
            rows = [[(groups[s], 1.0)] for s in range(n_states)]
        return Layer(rows, d)
    if kind == "declared":
        declared = getattr(unwrapped, "features_of_state", None)
        if declared is None:
            raise ValueError("features: the world declares no features_of_state")
        matrix = np.asarray(declared, dtype=np.float64)
        d = int(matrix.shape[1])
        for s in range(n_states):
            values = [float(v) for v in matrix[s].tolist()]
            rows.append([(i, values[i]) for i in range(d) if values[i] != 0.0])
        return Layer(rows, d)
    points = getattr(unwrapped, "point_of_state", None)
    if points is None:
        raise ValueError("features: the world observes no points")
    points = np.asarray(points, dtype=np.float32)
    if kind == "tiles":
        bins = [int(b) for b in features["bins"]]
        lows = [float(v) for v in features["low"]]
        highs = [float(v) for v in features["high"]]
        tilings = int(features.get("tilings", 1))
        d = tilings
        for b in bins:
            d = d * (b + 1 if b > 1 else 1)
        for s in range(n_states):
            rows.append([(row, 1.0) for row in tile_rows(points[s], bins, lows, highs, tilings)])
        return Layer(rows, d)
    if kind not in ("polynomial", "fourier"):
        raise ValueError(f"features: unknown kind {kind!r}")
    order = int(features["order"])
    low, high = _bounds(world.env.observation_space)
    k = int(points.shape[1])
    exponents = _exponents(order, k)
    for s in range(n_states):
        p = [float(v) for v in points[s].tolist()]
        us = [(float(p[j]) - float(low[j])) / (float(high[j]) - float(low[j])) for j in range(k)]
        row = []
        for index, c in enumerate(exponents):
            if kind == "polynomial":
                x = 1.0
                for j in range(k):
                    power = 1.0
                    for _ in range(c[j]):
                        power = power * us[j]
                    x = x * power
            else:
                total = 0.0
                for j in range(k):
                    total = total + float(c[j]) * us[j]
                x = math.cos(math.pi * total)
            row.append((index, x))
        rows.append(row)
    return Layer(rows, len(exponents))


def feature_rows(
    env_id: str, kwargs: Mapping[str, Any], features: Mapping[str, Any]
) -> tuple[np.ndarray, np.ndarray, int]:
    """Every state's row of a feature layer, as arrays.

    Args:
        env_id: The world's id.
        kwargs: ``world.kwargs``.
        features: The curve's ``features``.

    Returns:
        ``(index, value, d)``: int64 and float64 arrays of shape ``(N, K)`` (row ``s`` is
        state ``s``'s pairs in row order) and the number of weights. ``declared`` rows with
        fewer nonzero entries than the longest are padded with index ``-1``, value ``0.0``.
    """
    world = make_world(env_id, kwargs)
    try:
        layer = make_layer(world, features)
    finally:
        world.env.close()
    width = max(len(row) for row in layer.rows)
    index = np.full((world.n_states, width), -1, dtype=np.int64)
    value = np.zeros((world.n_states, width), dtype=np.float64)
    for s, row in enumerate(layer.rows):
        for j, (i, x) in enumerate(row):
            index[s, j] = i
            value[s, j] = x
    return index, value, layer.d


def v_hat(layer: Layer, w: list[float], s: int) -> float:
    """``v_hat(s, w) = 0.0 + w[i_0] * x_0 + ...`` in row order."""
    total = 0.0
    for i, x in layer.rows[s]:
        total = total + w[i] * x
    return total


def add_along(layer: Layer, w: list[float], s: int, amount: float) -> None:
    """*Adding ``amount`` along ``x(s)``*: ``w[i_j] = w[i_j] + amount * x_j`` in row order."""
    for i, x in layer.rows[s]:
        w[i] = w[i] + amount * x


# The model: measured states, mu, v_pi (docs/algorithms.md, "The errors"; "The error").


def _is_terminal(world: World, s: int) -> bool:
    """Every outcome of every action stays in ``s``, pays 0 and terminates."""
    for a in range(world.n):
        for _, s2, r, terminated in world.table[s][a]:
            if not (terminated and r == 0.0 and s2 == s):
                return False
    return True


def transition_matrix(world: World, policy: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """``P_pol`` and ``r_pol`` as "The error" builds them.

    With ``w = policy(a) * p`` per outcome, taken in the order of ``P``: ``r_pol(x) = 0.0 +
    w * r + ...``, ``P_pol(x, x')`` the same sum of ``w`` over the outcomes that do not
    terminate and lead to ``x'``.
    """
    n_states = world.n_states
    matrix = np.zeros((n_states, n_states))
    rewards = np.zeros(n_states)
    for x in range(n_states):
        r_total = 0.0
        for a in range(world.n):
            for p, x2, r, terminated in world.table[x][a]:
                weight = policy[a] * p
                r_total = r_total + weight * r
                if not terminated:
                    matrix[x, x2] = float(matrix[x, x2]) + weight
        rewards[x] = r_total
    return matrix, rewards


def reachable_states(world: World, policy: list[float]) -> list[int]:
    """The states an episode of ``policy`` can be in, ascending ("The error")."""
    following: list[set[int]] = [set() for _ in range(world.n_states)]
    for x in range(world.n_states):
        for a in range(world.n):
            for p, x2, _, terminated in world.table[x][a]:
                if policy[a] * p > 0.0 and not terminated:
                    following[x].add(x2)
    reached = {x for x in range(world.n_states) if world.start[x] > 0.0}
    frontier = sorted(reached)
    while frontier:
        for x2 in sorted(following[frontier.pop()]):
            if x2 not in reached:
                reached.add(x2)
                frontier.append(x2)
    return sorted(reached)


@dataclass
class Model:
    """What the errors and the expected algorithms read from the model.

    Attributes:
        measured: The measured states, ascending.
        mu: ``mu(s)`` of each measured state, in that order.
        mu_of: ``mu`` per state of ``P`` (``0.0`` off the measured states).
        truth: ``v_pi(s)`` of each measured state, in that order.
    """

    measured: list[int]
    mu: list[float]
    mu_of: list[float]
    truth: list[float]


def make_model(world: World, pi: list[float], b: list[float], gamma: float) -> Model:
    """The measured states, the behaviour's distribution ``mu`` and ``v_pi`` on them.

    Episodic: measured are the reachable states of ``b`` but the terminal ones; ``eta = h +
    eta P_b`` on the reachable states (``numpy.linalg.solve`` of the transposed system
    ``(I - P_b[R, R]).T eta = h[R]``), ``mu = eta / eta.sum()`` over the measured states
    (NumPy's ``sum`` of their ``eta`` in state order); ``v_pi = solve(I - gamma P_pi[R, R], r_pi[R])`` on the
    reachable states of ``pi``, read on the measured ones. Continuing: every state;
    ``mu = solve(A, e)`` with ``A = P_b.T - I``, its last row ones, ``e`` zero but a last
    ``1.0``; ``v_pi = solve(I - gamma P_pi, r_pi)``.
    """
    n_states = world.n_states
    p_b, _ = transition_matrix(world, b)
    p_pi, r_pi = transition_matrix(world, pi)
    if not world.episodic:
        measured = list(range(n_states))
        system = p_b.T - np.eye(n_states)
        system[n_states - 1, :] = 1.0
        e = np.zeros(n_states)
        e[n_states - 1] = 1.0
        mu_all = np.linalg.solve(system, e)
        mu = [float(mu_all[s]) for s in measured]
        values = np.linalg.solve(np.eye(n_states) - gamma * p_pi, r_pi)
        truth = [float(values[s]) for s in measured]
    else:
        reach_b = reachable_states(world, b)
        measured = [s for s in reach_b if not _is_terminal(world, s)]
        h = np.array([world.start[s] for s in reach_b])
        eta_r = np.linalg.solve((np.eye(len(reach_b)) - p_b[np.ix_(reach_b, reach_b)]).T, h)
        eta = dict(zip(reach_b, (float(v) for v in eta_r), strict=True))
        total = float(np.asarray([eta[s] for s in measured]).sum())  # NumPy's sum, as written
        mu = [eta[s] / total for s in measured]
        reach_pi = reachable_states(world, pi)
        system = np.eye(len(reach_pi)) - gamma * p_pi[np.ix_(reach_pi, reach_pi)]
        solved = np.linalg.solve(system, r_pi[reach_pi])
        values_of = dict(zip(reach_pi, (float(v) for v in solved), strict=True))
        truth = [values_of[s] for s in measured]
    mu_of = [0.0] * n_states
    for s, m in zip(measured, mu, strict=True):
        mu_of[s] = m
    return Model(measured, mu, mu_of, truth)


@dataclass
class Expectation:
    """The target's expected outcomes of a state, for ``e(s)``, ``x_bar'(s)`` and ``r_bar(s)``.

    Attributes:
        outcomes: ``outcomes[s]``: ``(pi(a) * p, s', r, terminated)`` over the actions ``a``
            ascending with ``pi(a) > 0`` and their outcomes in ``P[s][a]``'s order.
        next_features: ``x_bar'(s)``, dense: ``0.0 + sum (pi(a) * p) * x(s')`` in that order over
            the outcomes that do not terminate (a terminal state's row is never read).
    """

    outcomes: list[list[tuple[float, int, float, bool]]]
    next_features: list[list[float]]


def make_expectation(world: World, layer: Layer, pi: list[float]) -> Expectation:
    """The target's outcomes and ``x_bar'`` of every state."""
    outcomes = []
    next_features = []
    for s in range(world.n_states):
        listed = []
        for a in range(world.n):
            if not pi[a] > 0.0:
                continue
            for p, s2, r, terminated in world.table[s][a]:
                listed.append((pi[a] * p, s2, r, terminated))
        outcomes.append(listed)
        x_bar = [0.0] * layer.d
        for weight, s2, _, terminated in listed:
            if terminated:
                continue
            x2 = layer.dense(s2)
            for i in range(layer.d):
                x_bar[i] = x_bar[i] + weight * x2[i]
        next_features.append(x_bar)
    return Expectation(outcomes, next_features)


def expected_errors(
    layer: Layer, expectation: Expectation, w: list[float], gamma: float, states: Sequence[int]
) -> dict[int, float]:
    """``delta_bar(s) = e(s) - v_hat(s)`` of the given states, from ``w``.

    ``e(s) = 0.0 + sum (pi(a) * p) * (r + gamma * v_hat(s'))``, a terminated outcome's ``v_hat(s')``
    being ``0.0``.
    """
    values: dict[int, float] = {}
    result = {}
    for s in states:
        total = 0.0
        for weight, s2, r, terminated in expectation.outcomes[s]:
            if terminated:
                following = 0.0
            else:
                if s2 not in values:
                    values[s2] = v_hat(layer, w, s2)
                following = values[s2]
            total = total + weight * (r + gamma * following)
        if s not in values:
            values[s] = v_hat(layer, w, s)
        result[s] = total - values[s]
    return result


# The errors (docs/algorithms.md, "The errors").


def square_ve(layer: Layer, model: Model, w: list[float]) -> float:
    """``sqrt VE``: ``VE = 0.0 + sum_s mu(s) * (err * err)``, ``err = v_hat(s, w) - v_pi(s)``."""
    total = 0.0
    for s, m, truth in zip(model.measured, model.mu, model.truth, strict=True):
        err = v_hat(layer, w, s) - truth
        total = total + m * (err * err)
    return math.sqrt(total)


def projection(layer: Layer, model: Model) -> list[list[float]]:
    """``C+ = numpy.linalg.pinv(C)``, ``C_ij = 0.0 + sum_s (mu(s) * x_i(s)) * x_j(s)``.

    The sum over ``s`` (ascending) skips the states where ``x_i(s)`` or ``x_j(s)`` is 0.0:
    their terms are zeros, which never change the sum's bits.
    """
    d = layer.d
    c = [[0.0] * d for _ in range(d)]
    for s, m in zip(model.measured, model.mu, strict=True):
        for i, xi in layer.rows[s]:
            left = m * xi
            for j, xj in layer.rows[s]:
                c[i][j] = c[i][j] + left * xj
    pinv = np.linalg.pinv(np.array(c, dtype=np.float64))
    return [[float(v) for v in row] for row in pinv.tolist()]


def square_pbe(
    layer: Layer,
    model: Model,
    expectation: Expectation,
    c_plus: list[list[float]],
    w: list[float],
    gamma: float,
) -> float:
    """``sqrt PBE`` (eq. 11.22) of ``w``, every sum dense and from 0.0 in ascending order."""
    d = layer.d
    deltas = expected_errors(layer, expectation, w, gamma, model.measured)
    dense = {s: layer.dense(s) for s in model.measured}
    g = [0.0] * d
    for i in range(d):
        total = 0.0
        for s, m in zip(model.measured, model.mu, strict=True):
            total = total + (m * deltas[s]) * dense[s][i]
        g[i] = total
    u = [0.0] * d
    for i in range(d):
        total = 0.0
        for j in range(d):
            total = total + c_plus[i][j] * g[j]
        u[i] = total
    pbe = 0.0
    for s, m in zip(model.measured, model.mu, strict=True):
        z = 0.0
        x = dense[s]
        for i in range(d):
            z = z + x[i] * u[i]
        pbe = pbe + m * (z * z)
    return math.sqrt(pbe)


# The run (docs/algorithms.md, "The run", "Algorithms").


class Learner:
    """One curve's weights and the algorithm's memory.

    Attributes:
        layer: The feature layer.
        w: The weights.
        v: The auxiliary weights of TDC and GTD2 (``0.0``).
        algorithm: The curve's algorithm.
        alpha: ``alpha``.
        beta: ``beta``.
        gamma: ``gamma``.
    """

    def __init__(
        self,
        layer: Layer,
        w0: float | Sequence[float],
        algorithm: str,
        *,
        alpha: float,
        beta: float,
        gamma: float,
        epsilon: float,
    ) -> None:
        d = layer.d
        if isinstance(w0, (int, float)):
            self.w = [float(w0)] * d
        else:
            self.w = [float(x) for x in w0]
            if len(self.w) != d:
                raise ValueError(f"w0: {len(self.w)} numbers for {d} weights")
        self.v = [0.0] * d
        self.layer = layer
        self.algorithm = algorithm
        self.alpha = float(alpha)
        self.beta = float(beta)
        self.gamma = float(gamma)
        # lstd: M = (1.0 / epsilon) I, c = 0
        if algorithm == "lstd":
            diagonal = 1.0 / float(epsilon)
            self.m = [[diagonal if i == j else 0.0 for j in range(d)] for i in range(d)]
            self.c = [0.0] * d
        # emphatic_td: M = 0.0, rho_prev = 0.0 before the first step
        self.emphasis = 0.0
        self.rho_prev = 0.0
        # gradient_mc: the episode's (S_t, R_{t+1})
        self.episode: list[tuple[int, float]] = []

    def step(self, s: int, r: float, s2: int, terminated: bool, rho: float) -> None:
        """A sampled algorithm's step from ``S = s`` with reward ``R = r`` to ``S' = s2``."""
        layer, w, gamma, alpha = self.layer, self.w, self.gamma, self.alpha
        name = self.algorithm
        if name == "gradient_mc":
            self.episode.append((s, r))
            return
        if name == "lstd":
            self._lstd(s, r, s2, terminated)
            return
        following = 0.0 if terminated else v_hat(layer, w, s2)
        delta = r + gamma * following - v_hat(layer, w, s)
        if name == "semi_gradient_td":
            add_along(layer, w, s, alpha * delta)
        elif name == "off_policy_td":
            add_along(layer, w, s, alpha * rho * delta)
        elif name == "emphatic_td":
            self.emphasis = gamma * self.rho_prev * self.emphasis + 1.0
            add_along(layer, w, s, alpha * self.emphasis * rho * delta)
            self.rho_prev = rho
        elif name in ("tdc", "gtd2"):
            d = layer.d
            x = layer.dense(s)
            x2 = [0.0] * d if terminated else layer.dense(s2)
            v = self.v
            h = 0.0
            for i in range(d):
                h = h + v[i] * x[i]
            step_w = alpha * rho
            step_v = self.beta * rho
            for i in range(d):
                if name == "tdc":
                    w[i] = w[i] + step_w * (delta * x[i] - gamma * x2[i] * h)
                else:
                    w[i] = w[i] + step_w * (x[i] - gamma * x2[i]) * h
                v[i] = v[i] + step_v * (delta - h) * x[i]
        else:
            raise ValueError(f"unknown algorithm {name!r}")

    def _lstd(self, s: int, r: float, s2: int, terminated: bool) -> None:
        """The LSTD box: a Sherman-Morrison step of ``M``, then ``w = M c``."""
        layer, gamma = self.layer, self.gamma
        d = layer.d
        m, c, w = self.m, self.c, self.w
        x = layer.dense(s)
        x2 = [0.0] * d if terminated else layer.dense(s2)
        y = [x[i] - gamma * x2[i] for i in range(d)]
        v = [0.0] * d
        for j in range(d):
            total = 0.0
            for i in range(d):
                total = total + m[i][j] * y[i]
            v[j] = total
        u = [0.0] * d
        for i in range(d):
            total = 0.0
            row = m[i]
            for j in range(d):
                total = total + row[j] * x[j]
            u[i] = total
        dot = 0.0
        for j in range(d):
            dot = dot + v[j] * x[j]
        den = 1.0 + dot
        for i in range(d):
            row = m[i]
            for j in range(d):
                row[j] = row[j] - (u[i] * v[j]) / den
        for i in range(d):
            c[i] = c[i] + r * x[i]
        for i in range(d):
            total = 0.0
            row = m[i]
            for j in range(d):
                total = total + row[j] * c[j]
            w[i] = total

    def end_episode(self, last: int, truncated: bool) -> None:
        """Gradient Monte Carlo's updates after the episode's last step (else nothing).

        Args:
            last: ``S_T``, the last step's next state.
            truncated: Whether the episode was truncated (not terminated).
        """
        if self.algorithm != "gradient_mc":
            return
        layer, w, gamma = self.layer, self.w, self.gamma
        g = v_hat(layer, w, last) if truncated else 0.0
        returns = [0.0] * len(self.episode)
        for t in range(len(self.episode) - 1, -1, -1):
            g = self.episode[t][1] + gamma * g
            returns[t] = g
        for t, (s, _) in enumerate(self.episode):
            add_along(layer, w, s, self.alpha * (returns[t] - v_hat(layer, w, s)))
        self.episode = []


class Sweeper:
    """An expected algorithm's synchronous sweeps over the model."""

    def __init__(
        self,
        learner: Learner,
        world: World,
        expectation: Expectation,
        mu_of: list[float],
    ) -> None:
        self.learner = learner
        self.world = world
        self.expectation = expectation
        self.mu = mu_of
        self.states = list(range(world.n_states))
        self.dense = [learner.layer.dense(s) for s in self.states]
        # expected_emphatic_td: f(s) = mu(s) * 1.0
        self.f = [m * 1.0 for m in mu_of]

    def sweep(self, pi: list[float]) -> None:
        """One sweep of the learner's algorithm, every state from the sweep's starting ``w``."""
        learner = self.learner
        layer, w, v = learner.layer, learner.w, learner.v
        alpha, beta, gamma = learner.alpha, learner.beta, learner.gamma
        d = layer.d
        deltas = expected_errors(layer, self.expectation, w, gamma, self.states)
        mu, dense, states = self.mu, self.dense, self.states
        name = learner.algorithm
        if name == "semi_gradient_dp":
            g = [0.0] * d
            for i in range(d):
                total = 0.0
                for s in states:
                    total = total + (mu[s] * deltas[s]) * dense[s][i]
                g[i] = total
            for i in range(d):
                w[i] = w[i] + alpha * g[i]
        elif name == "expected_tdc":
            h = [0.0] * len(states)
            for s in states:
                total = 0.0
                for i in range(d):
                    total = total + v[i] * dense[s][i]
                h[s] = total
            x_bar = self.expectation.next_features
            g = [0.0] * d
            k = [0.0] * d
            for i in range(d):
                total_g = 0.0
                total_k = 0.0
                for s in states:
                    total_g = total_g + mu[s] * (
                        deltas[s] * dense[s][i] - gamma * x_bar[s][i] * h[s]
                    )
                    total_k = total_k + mu[s] * ((deltas[s] - h[s]) * dense[s][i])
                g[i] = total_g
                k[i] = total_k
            for i in range(d):
                w[i] = w[i] + alpha * g[i]
                v[i] = v[i] + beta * k[i]
        elif name == "expected_emphatic_td":
            f = self.f
            g = [0.0] * d
            for i in range(d):
                total = 0.0
                for s in states:
                    total = total + (f[s] * deltas[s]) * dense[s][i]
                g[i] = total
            for i in range(d):
                w[i] = w[i] + alpha * g[i]
            q = [0.0] * len(states)
            for s in states:
                for a in range(self.world.n):
                    if not pi[a] > 0.0:
                        continue
                    for p, s2, _, _ in self.world.table[s][a]:
                        q[s2] = q[s2] + (pi[a] * p) * f[s]
            self.f = [mu[s] * 1.0 + gamma * q[s] for s in states]
        else:
            raise ValueError(f"unknown algorithm {name!r}")


def _policies(
    world: World, target: str | Sequence[Any], behaviour: str | Sequence[Any] | None
) -> tuple[list[float], list[float], str | Sequence[Any]]:
    pi = policy_probabilities(target, world.n)
    spec = target if behaviour is None else behaviour
    b = policy_probabilities(spec, world.n)
    return pi, b, spec


def _same_policy(pi: list[float], b: list[float]) -> bool:
    return all(x == y for x, y in zip(pi, b, strict=True))


def run_linear(
    env_id: str,
    kwargs: Mapping[str, Any],
    features: Mapping[str, Any],
    algorithm: str,
    *,
    gamma: float,
    seed: int,
    episodes: int | None = None,
    steps: int | None = None,
    alpha: float = 0.0,
    beta: float = 0.0,
    epsilon: float = 1.0,
    w0: float | Sequence[float] = 0.0,
    target: str | Sequence[float] = "random",
    behaviour: str | Sequence[float] | None = None,
    record_every: int = 1,
    errors: Sequence[str] = ("ve",),
) -> dict[str, np.ndarray]:
    """One curve's run, as the contract states it.

    Args:
        env_id: The world's id (``world.id``).
        kwargs: ``world.kwargs``.
        features: The curve's feature layer.
        algorithm: The curve's algorithm.
        gamma: The study's ``gamma``.
        seed: The run's seed (an expected algorithm draws nothing and ignores it).
        episodes: ``E`` (episodic worlds).
        steps: ``T`` (continuing worlds): steps, or an expected algorithm's sweeps.
        alpha: ``alpha``.
        beta: ``beta`` (TDC, GTD2, expected TDC).
        epsilon: LSTD's ``epsilon``.
        w0: The starting weights: one number for all, or ``d`` numbers.
        target: ``pi``: ``"random"`` or ``n`` probabilities.
        behaviour: ``b`` (``None``: the target).
        record_every: ``k``: records at ``0, k, 2k, ...`` and at the last.
        errors: Which errors each record holds: ``"ve"`` and/or ``"pbe"``.

    Returns:
        ``at`` (int64 ``(R,)``: the episode, step or sweep count of each record),
        ``weights`` (float64 ``(R, d)``), and ``ve`` and ``pbe`` (float64 ``(R,)``: ``sqrt VE``
        and ``sqrt PBE``) for those ``errors`` lists.

    Raises:
        ValueError: A run the contract refuses (``steps`` on an episodic world, an off-policy
            behaviour for an on-policy algorithm, ...).
    """
    if algorithm not in SAMPLED + EXPECTED:
        raise ValueError(f"unknown algorithm {algorithm!r}")
    world = make_world(env_id, kwargs)
    try:
        return _run(
            world, features, algorithm, gamma=float(gamma), seed=seed, episodes=episodes,
            steps=steps, alpha=alpha, beta=beta, epsilon=epsilon, w0=w0, target=target,
            behaviour=behaviour, record_every=record_every, errors=errors,
        )  # fmt: skip
    finally:
        world.env.close()


def _run(
    world: World,
    features: Mapping[str, Any],
    algorithm: str,
    *,
    gamma: float,
    seed: int,
    episodes: int | None,
    steps: int | None,
    alpha: float,
    beta: float,
    epsilon: float,
    w0: float | Sequence[float],
    target: str | Sequence[float],
    behaviour: str | Sequence[float] | None,
    record_every: int,
    errors: Sequence[str],
) -> dict[str, np.ndarray]:
    pi, b, behaviour_spec = _policies(world, target, behaviour)
    if world.episodic:
        if episodes is None or steps is not None:
            raise ValueError("steps: an episodic world's study gives episodes")
        if algorithm in CONTINUING_ONLY:
            raise ValueError(f"algorithm: {algorithm} runs on continuing worlds")
        if not _same_policy(pi, b):
            raise ValueError("behaviour: an episodic world needs behaviour equal to target")
        total = int(episodes)
    else:
        if steps is None or episodes is not None:
            raise ValueError("episodes: a continuing world's study gives steps")
        if algorithm in EPISODIC_ONLY:
            raise ValueError(f"algorithm: {algorithm} runs on episodic worlds")
        if gamma >= 1.0:
            raise ValueError("gamma: a continuing world needs gamma < 1")
        total = int(steps)
    if algorithm in ON_POLICY and not _same_policy(pi, b):
        raise ValueError(f"behaviour: {algorithm} needs behaviour equal to target")
    if record_every < 1:
        raise ValueError("record_every: at least 1")

    layer = make_layer(world, features)
    model = make_model(world, pi, b, gamma)
    expectation = make_expectation(world, layer, pi)
    c_plus = projection(layer, model) if "pbe" in errors else None
    learner = Learner(layer, w0, algorithm, alpha=alpha, beta=beta, gamma=gamma, epsilon=epsilon)

    at: list[int] = []
    weights: list[list[float]] = []
    ve: list[float] = []
    pbe: list[float] = []

    def record(count: int) -> None:
        at.append(count)
        weights.append(list(learner.w))
        if "ve" in errors:
            ve.append(square_ve(layer, model, learner.w))
        if "pbe" in errors:
            assert c_plus is not None
            pbe.append(square_pbe(layer, model, expectation, c_plus, learner.w, gamma))

    def after(count: int) -> None:
        if count % record_every == 0 or count == total:
            record(count)

    record(0)
    if algorithm in EXPECTED:
        sweeper = Sweeper(learner, world, expectation, model.mu_of)
        for count in range(1, total + 1):
            sweeper.sweep(pi)
            after(count)
    else:
        env = world.env
        agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
        rng = np.random.Generator(np.random.PCG64(agent_seq))
        env_seed = int(env_seq.generate_state(1, dtype=np.uint32)[0])

        def act(s: int) -> tuple[int, float, int, bool, bool]:
            a = behaviour_action(rng, behaviour_spec, b)
            _, reward, terminated, truncated, _ = env.step(a)
            s2 = current_state(env)
            rho = pi[a] / b[a]
            learner.step(s, float(reward), s2, bool(terminated), rho)
            return a, rho, s2, bool(terminated), bool(truncated) and not bool(terminated)

        if world.episodic:
            for count in range(1, total + 1):
                env.reset(seed=env_seed if count == 1 else None)
                s = current_state(env)
                while True:
                    _, _, s2, terminated, truncated = act(s)
                    s = s2
                    if terminated or truncated:
                        break
                learner.end_episode(s, truncated)
                after(count)
        else:
            env.reset(seed=env_seed)
            s = current_state(env)
            for count in range(1, total + 1):
                _, _, s2, _, _ = act(s)
                s = s2
                after(count)

    result = {
        "at": np.array(at, dtype=np.int64),
        "weights": np.array(weights, dtype=np.float64).reshape(len(at), layer.d),
    }
    if "ve" in errors:
        result["ve"] = np.array(ve, dtype=np.float64)
    if "pbe" in errors:
        result["pbe"] = np.array(pbe, dtype=np.float64)
    return result


# Fixed points (docs/algorithms.md, "Fixed points").


def _fixed_point_setup(
    env_id: str,
    kwargs: Mapping[str, Any],
    features: Mapping[str, Any],
    gamma: float,
    target: str | Sequence[float],
    behaviour: str | Sequence[float] | None,
) -> tuple[World, Layer, Model, list[float]]:
    world = make_world(env_id, kwargs)
    pi, b, _ = _policies(world, target, behaviour)
    layer = make_layer(world, features)
    model = make_model(world, pi, b, float(gamma))
    return world, layer, model, pi


def td_fixed_point(
    env_id: str,
    kwargs: Mapping[str, Any],
    features: Mapping[str, Any],
    *,
    gamma: float,
    target: str | Sequence[float] = "random",
    behaviour: str | Sequence[float] | None = None,
) -> np.ndarray:
    """The TD fixed point: ``numpy.linalg.lstsq(A, c)``.

    ``A = X.T D (X - gamma X_bar')`` and ``c = X.T D r_bar`` over the measured states, evaluated as
    ``A_ij = 0.0 + sum_s (X[s, i] * mu(s)) * (X[s, j] - gamma * X_bar'[s, j])`` and ``c_i = 0.0 +
    sum_s (X[s, i] * mu(s)) * r_bar(s)`` (``s`` ascending; states with ``X[s, i] = 0.0`` skipped),
    ``r_bar(s) = 0.0 + sum (pi(a) * p) * r`` over the target's outcomes in order.

    Returns:
        The weights, float64 ``(d,)`` (``lstsq``'s least-norm solution where ``A`` is
        singular).
    """
    world, layer, model, pi = _fixed_point_setup(env_id, kwargs, features, gamma, target, behaviour)
    try:
        expectation = make_expectation(world, layer, pi)
    finally:
        world.env.close()
    d = layer.d
    g = float(gamma)
    a_matrix = [[0.0] * d for _ in range(d)]
    c = [0.0] * d
    for s, m in zip(model.measured, model.mu, strict=True):
        x = layer.dense(s)
        x_bar = expectation.next_features[s]
        difference = [x[j] - g * x_bar[j] for j in range(d)]
        r_bar = 0.0
        for weight, _, r, _ in expectation.outcomes[s]:
            r_bar = r_bar + weight * r
        for i, xi in layer.rows[s]:
            left = xi * m
            row = a_matrix[i]
            for j in range(d):
                row[j] = row[j] + left * difference[j]
            c[i] = c[i] + left * r_bar
    solution = np.linalg.lstsq(np.array(a_matrix, dtype=np.float64), np.array(c), rcond=None)[0]
    return np.asarray(solution, dtype=np.float64)


def mc_fixed_point(
    env_id: str,
    kwargs: Mapping[str, Any],
    features: Mapping[str, Any],
    *,
    gamma: float,
    target: str | Sequence[float] = "random",
    behaviour: str | Sequence[float] | None = None,
) -> np.ndarray:
    """Gradient Monte Carlo's fixed point, the weights of least ``VE``.

    ``numpy.linalg.lstsq(D^(1/2) X, D^(1/2) v_pi)``: row ``s`` of ``X`` (a measured state's
    dense features) and ``v_pi(s)`` each multiplied by ``math.sqrt(mu(s))``.

    Returns:
        The weights, float64 ``(d,)``.
    """
    world, layer, model, _ = _fixed_point_setup(env_id, kwargs, features, gamma, target, behaviour)
    world.env.close()
    rows = []
    values = []
    for s, m, truth in zip(model.measured, model.mu, model.truth, strict=True):
        root = math.sqrt(m)
        rows.append([root * x for x in layer.dense(s)])
        values.append(root * truth)
    solution = np.linalg.lstsq(
        np.array(rows, dtype=np.float64), np.array(values, dtype=np.float64), rcond=None
    )[0]
    return np.asarray(solution, dtype=np.float64)
