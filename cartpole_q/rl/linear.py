"""Linear methods on a feature layer: their updates and their errors (Sutton & Barto 9, 11).

Every method learns ``v̂(s, w) = wᵀx(s)`` for a target policy ``π``, reading the features
through one layer (:mod:`cartpole_q.rl.features`): a state's row of ``(index, value)``
pairs. The functions here are plain Python, marked compilable: the engines
(:mod:`cartpole_q.engines.linear`) compile them with numba, and both engines call the same
compiled code, so their floats agree byte for byte. The contract, formula by formula, is
docs/algorithms.md, "Linear function approximation".

- sampled, one step at a time (:func:`learn_step`): semi-gradient TD(0) (9.3), LSTD (9.8),
  semi-gradient off-policy TD(0) (11.1), TDC and GTD2 (11.7), emphatic TD(0) (11.8);
  gradient Monte Carlo (9.3) learns from a whole episode (:func:`learn_episode`);
- expected, one synchronous sweep over the states from the model (:func:`sweep`):
  semi-gradient DP (11.2's right panel), expected TDC (Figure 11.5), expected emphatic TD
  (Figure 11.6);
- the errors: ``√VE`` (eq. 9.1, :func:`root_ve`) and ``√PBE`` (eq. 11.22,
  :func:`root_pbe`), with the ``μ`` and ``v_π`` of :mod:`cartpole_q.rl.solvers`;
- the fixed points drawn beside the curves (:func:`least_ve_weights`, :func:`td_fixed_point`).

The records the compiled functions take are named tuples (numba types them field by field):
:class:`Learner` (a curve's features, step sizes and weights), :class:`Model` (the world's
outcomes, for the expected sweeps and the errors), :class:`Errors` (what the errors are
measured against).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.rl.tabular import compilable

SAMPLED = ("gradient_mc", "semi_gradient_td", "lstd", "off_policy_td", "tdc", "gtd2", "emphatic_td")
"""the algorithms that learn from the world's steps (in :data:`CODES` order)"""
EXPECTED = ("semi_gradient_dp", "expected_tdc", "expected_emphatic_td")
"""the algorithms that sweep the model instead"""
ALGORITHMS = SAMPLED + EXPECTED
CODES = {name: code for code, name in enumerate(ALGORITHMS)}
"""each algorithm's number in the compiled code"""
GRADIENT_MC, SEMI_GRADIENT_TD, LSTD, OFF_POLICY_TD, TDC, GTD2, EMPHATIC_TD = range(7)
SEMI_GRADIENT_DP, EXPECTED_TDC, EXPECTED_EMPHATIC_TD = range(7, 10)
ON_POLICY = ("gradient_mc", "semi_gradient_td", "lstd")
"""the algorithms whose behaviour must be their target"""
EPISODIC_ONLY = ("gradient_mc",)
CONTINUING_ONLY = ("off_policy_td", "tdc", "gtd2", "emphatic_td", *EXPECTED)
WITH_BETA = ("tdc", "gtd2", "expected_tdc")
"""the algorithms with a second step size (their auxiliary weights ``v``)"""
EMPHASIS, PREVIOUS_RATIO = 0, 1
"""emphatic TD's scalars: ``M`` and the previous step's ``rho``"""


class Learner(NamedTuple):
    """One curve's learner: its algorithm, step sizes, features and weights (mutable arrays)."""

    code: int
    """the algorithm (:data:`CODES`)"""
    alpha: float
    beta: float
    gamma: float
    indices: np.ndarray
    """int64 ``(N, K)``: the layer's rows' weight indices"""
    value: np.ndarray
    """float64 ``(N, K)``: the rows' feature values"""
    w: np.ndarray
    """float64 ``(d,)``: the weights"""
    aux: np.ndarray
    """float64 ``(d,)``: TDC's and GTD2's ``v`` (zeros otherwise)"""
    matrix: np.ndarray
    """float64 ``(d, d)``: LSTD's ``M`` (``(0, 0)`` otherwise)"""
    vector: np.ndarray
    """float64 ``(d,)``: LSTD's ``c``"""
    scalars: np.ndarray
    """float64 ``(2,)``: emphatic TD's ``M`` and previous ``rho``"""
    x: np.ndarray
    """float64 ``(d,)``: room for a dense ``x(S)``"""
    x_next: np.ndarray
    """float64 ``(d,)``: room for a dense ``x(S')`` (or ``x̄'(s)``)"""
    gradient: np.ndarray
    """float64 ``(d,)``: room for a sweep's sum"""
    second: np.ndarray
    """float64 ``(d,)``: room for a sweep's second sum"""


class Model(NamedTuple):
    """A world's outcomes as flat arrays in ``P``'s order, with the target policy."""

    first: np.ndarray
    """int64 ``(N + 1,)``: state ``s``'s outcomes are ``first[s] .. first[s + 1] - 1``"""
    action: np.ndarray
    probability: np.ndarray
    next_state: np.ndarray
    reward: np.ndarray
    terminated: np.ndarray
    """bool"""
    target: np.ndarray
    """float64 ``(n,)``: ``π(a)``, the same in every state"""
    mu: np.ndarray
    """float64 ``(N,)``: the behaviour's distribution, 0 on states not measured"""
    emphasis: np.ndarray
    """float64 ``(N,)``: expected emphatic TD's ``f`` (updated by its sweeps)"""
    spare: np.ndarray
    """float64 ``(N,)``: room for the values of every state, then ``q``"""


class Errors(NamedTuple):
    """What the errors are measured against."""

    measured: np.ndarray
    """int64: the measured states, ascending"""
    mu: np.ndarray
    """float64: ``μ`` on them"""
    truth: np.ndarray
    """float64: ``v_π`` on them"""
    pseudo_inverse: np.ndarray
    """float64 ``(d, d)``: ``C⁺`` (``(0, 0)`` when ``√PBE`` is not measured)"""
    delta: np.ndarray
    """float64 ``(N,)``: room for ``δ̄``"""


def new_learner(
    algorithm: str, alpha: float, beta: float, gamma: float, epsilon: float,
    index: np.ndarray, value: np.ndarray, w0: np.ndarray,
) -> Learner:  # fmt: skip
    """A learner at its start: ``w = w0``, ``v = 0``, LSTD's ``M = (1 / ε) I``, ``M = 0``."""
    d = w0.shape[0]
    matrix = np.zeros((d, d) if algorithm == "lstd" else (0, 0))
    for i in range(matrix.shape[0]):
        matrix[i, i] = 1.0 / epsilon
    return Learner(
        CODES[algorithm], float(alpha), float(beta), float(gamma), index, value,
        w0.astype(np.float64, copy=True), np.zeros(d), matrix, np.zeros(d), np.zeros(2),
        np.zeros(d), np.zeros(d), np.zeros(d), np.zeros(d),
    )  # fmt: skip


# -- the layer ------------------------------------------------------------------------------


@compilable
def estimate(index: Any, value: Any, w: Any, state: int) -> float:
    """``v̂(s, w)``: the row's ``w[i] * x`` summed in row order from 0.0."""
    total = 0.0
    for j in range(index.shape[1]):
        total = total + w[index[state, j]] * value[state, j]
    return total


@compilable
def add_along(index: Any, value: Any, w: Any, state: int, amount: float) -> None:
    """Add ``amount`` along ``x(s)``: ``w[i] = w[i] + amount * x`` for the row's pairs in order."""
    for j in range(index.shape[1]):
        w[index[state, j]] = w[index[state, j]] + amount * value[state, j]


@compilable
def fill_dense(index: Any, value: Any, state: int, out: Any) -> None:
    """``out = x(s)`` as a vector (zeros but the row's pairs)."""
    for i in range(out.shape[0]):
        out[i] = 0.0
    for j in range(index.shape[1]):
        out[index[state, j]] = value[state, j]


# -- sampled updates ------------------------------------------------------------------------


@compilable
def learn_step(
    learner: Any, state: int, ratio: float, reward: float, following: int, terminated: bool
) -> None:
    """One step's update of a sampled algorithm but gradient MC (which waits for the end)."""
    code = learner.code
    index, value, w = learner.indices, learner.value, learner.w
    following_value = 0.0 if terminated else estimate(index, value, w, following)
    delta = reward + learner.gamma * following_value - estimate(index, value, w, state)
    if code == SEMI_GRADIENT_TD:
        add_along(index, value, w, state, learner.alpha * delta)
    elif code == OFF_POLICY_TD:
        add_along(index, value, w, state, learner.alpha * ratio * delta)
    elif code == EMPHATIC_TD:
        scalars = learner.scalars
        scalars[EMPHASIS] = learner.gamma * scalars[PREVIOUS_RATIO] * scalars[EMPHASIS] + 1.0
        add_along(index, value, w, state, learner.alpha * scalars[EMPHASIS] * ratio * delta)
        scalars[PREVIOUS_RATIO] = ratio
    elif code in (TDC, GTD2):
        _gradient_td_step(learner, state, ratio, delta, following, terminated)
    elif code == LSTD:
        _lstd_step(learner, state, reward, following, terminated)


@compilable
def _gradient_td_step(
    learner: Any, state: int, ratio: float, delta: float, following: int, terminated: bool
) -> None:
    """TDC's or GTD2's update of ``w`` and then ``v``, on dense vectors."""
    x, x_next, v, w = learner.x, learner.x_next, learner.aux, learner.w
    fill_dense(learner.indices, learner.value, state, x)
    if terminated:
        for i in range(x_next.shape[0]):
            x_next[i] = 0.0
    else:
        fill_dense(learner.indices, learner.value, following, x_next)
    h = 0.0
    for i in range(x.shape[0]):
        h = h + v[i] * x[i]
    scale = learner.alpha * ratio
    gamma = learner.gamma
    for i in range(x.shape[0]):
        if learner.code == TDC:
            w[i] = w[i] + scale * (delta * x[i] - gamma * x_next[i] * h)
        else:
            w[i] = w[i] + scale * (x[i] - gamma * x_next[i]) * h
    aux_scale = learner.beta * ratio
    for i in range(x.shape[0]):
        v[i] = v[i] + aux_scale * (delta - h) * x[i]


@compilable
def _lstd_step(learner: Any, state: int, reward: float, following: int, terminated: bool) -> None:
    """The LSTD box's step: ``M`` by Sherman-Morrison, ``c``, then ``w = M c``."""
    x, y, m, c, w = learner.x, learner.x_next, learner.matrix, learner.vector, learner.w
    d = x.shape[0]
    gamma = learner.gamma
    fill_dense(learner.indices, learner.value, state, x)
    if terminated:
        for i in range(d):
            y[i] = x[i]
    else:
        fill_dense(learner.indices, learner.value, following, y)
        for i in range(d):
            y[i] = x[i] - gamma * y[i]
    v, u = learner.gradient, learner.second
    for j in range(d):
        total = 0.0
        for i in range(d):
            total = total + m[i, j] * y[i]
        v[j] = total
    for i in range(d):
        total = 0.0
        for j in range(d):
            total = total + m[i, j] * x[j]
        u[i] = total
    product = 0.0
    for j in range(d):
        product = product + v[j] * x[j]
    denominator = 1.0 + product
    for i in range(d):
        for j in range(d):
            m[i, j] = m[i, j] - (u[i] * v[j]) / denominator
    for i in range(d):
        c[i] = c[i] + reward * x[i]
    for i in range(d):
        total = 0.0
        for j in range(d):
            total = total + m[i, j] * c[j]
        w[i] = total


@compilable
def learn_episode(
    learner: Any, states: Any, rewards: Any, length: int, truncated: bool, returns: Any
) -> None:
    """Gradient MC after an episode of ``length`` steps: the returns, then the updates first to last.

    ``states[t]`` is ``S_t`` (``t = 0 .. length``), ``rewards[t]`` is ``R_{t+1}``.
    """
    index, value, w = learner.indices, learner.value, learner.w
    g = estimate(index, value, w, states[length]) if truncated else 0.0
    for t in range(length - 1, -1, -1):
        g = rewards[t] + learner.gamma * g
        returns[t] = g
    for t in range(length):
        state = states[t]
        add_along(
            index, value, w, state, learner.alpha * (returns[t] - estimate(index, value, w, state))
        )


# -- expected sweeps ------------------------------------------------------------------------


@compilable
def state_values(learner: Any, out: Any) -> None:
    """``out[s] = v̂(s, w)`` for every state."""
    for state in range(out.shape[0]):
        out[state] = estimate(learner.indices, learner.value, learner.w, state)


@compilable
def expected_error(learner: Any, model: Any, values: Any, state: int) -> float:
    """``δ̄(s) = e(s) - v̂(s)``: ``e(s)`` the target's expected ``r + gamma v̂(s')`` from the model."""
    expected = 0.0
    for o in range(model.first[state], model.first[state + 1]):
        chance = model.target[model.action[o]]
        if chance > 0.0:
            following = 0.0 if model.terminated[o] else values[model.next_state[o]]
            expected = expected + (chance * model.probability[o]) * (
                model.reward[o] + learner.gamma * following
            )
    delta: float = expected - values[state]
    return delta


@compilable
def expected_next(learner: Any, model: Any, state: int, out: Any) -> None:
    """``out = x̄'(s)``: the target's expected next features from the model (terminal: none)."""
    for i in range(out.shape[0]):
        out[i] = 0.0
    for o in range(model.first[state], model.first[state + 1]):
        chance = model.target[model.action[o]]
        if chance > 0.0 and not model.terminated[o]:
            weight = chance * model.probability[o]
            following = model.next_state[o]
            for j in range(learner.indices.shape[1]):
                i = learner.indices[following, j]
                out[i] = out[i] + weight * learner.value[following, j]


@compilable
def sweep(learner: Any, model: Any) -> None:
    """One synchronous sweep of an expected algorithm over every state, from the model."""
    values = model.spare
    state_values(learner, values)
    g, k, w, v = learner.gradient, learner.second, learner.w, learner.aux
    x, x_next = learner.x, learner.x_next
    d = w.shape[0]
    for i in range(d):
        g[i] = 0.0
        k[i] = 0.0
    code = learner.code
    for state in range(values.shape[0]):
        delta = expected_error(learner, model, values, state)
        fill_dense(learner.indices, learner.value, state, x)
        if code in (SEMI_GRADIENT_DP, EXPECTED_EMPHATIC_TD):
            weight = model.mu[state] if code == SEMI_GRADIENT_DP else model.emphasis[state]
            coefficient = weight * delta
            for i in range(d):
                g[i] = g[i] + coefficient * x[i]
        else:  # expected TDC
            h = 0.0
            for i in range(d):
                h = h + v[i] * x[i]
            expected_next(learner, model, state, x_next)
            mu = model.mu[state]
            for i in range(d):
                g[i] = g[i] + mu * (delta * x[i] - learner.gamma * x_next[i] * h)
                k[i] = k[i] + mu * ((delta - h) * x[i])
    for i in range(d):
        w[i] = w[i] + learner.alpha * g[i]
    if code == EXPECTED_TDC:
        for i in range(d):
            v[i] = v[i] + learner.beta * k[i]
    elif code == EXPECTED_EMPHATIC_TD:
        _next_emphasis(learner, model)


@compilable
def _next_emphasis(learner: Any, model: Any) -> None:
    """``f(s) = μ(s) * 1.0 + gamma q[s]``, ``q[s']`` the emphasis the target carries into ``s'``."""
    q = model.spare
    f = model.emphasis
    for state in range(q.shape[0]):
        q[state] = 0.0
    for state in range(q.shape[0]):
        for o in range(model.first[state], model.first[state + 1]):
            chance = model.target[model.action[o]]
            if chance > 0.0 and not model.terminated[o]:
                following = model.next_state[o]
                q[following] = q[following] + (chance * model.probability[o]) * f[state]
    for state in range(q.shape[0]):
        f[state] = model.mu[state] * 1.0 + learner.gamma * q[state]


# -- errors ---------------------------------------------------------------------------------


@compilable
def root_ve(learner: Any, errors: Any) -> float:
    """``√VE``: ``sqrt(sum μ(s) (v̂(s) - v_π(s))²)`` over the measured states in order."""
    total = 0.0
    for k in range(errors.measured.shape[0]):
        state = errors.measured[k]
        difference = estimate(learner.indices, learner.value, learner.w, state) - errors.truth[k]
        total = total + errors.mu[k] * (difference * difference)
    result: float = math.sqrt(total)
    return result


@compilable
def root_pbe(learner: Any, model: Any, errors: Any) -> float:
    """``√PBE``: the ``μ``-norm of the projected Bellman error (eq. 11.22)."""
    values = model.spare
    state_values(learner, values)
    g, u = learner.gradient, learner.second
    d = g.shape[0]
    for i in range(d):
        g[i] = 0.0
    for k in range(errors.measured.shape[0]):
        state = errors.measured[k]
        coefficient = errors.mu[k] * expected_error(learner, model, values, state)
        for j in range(learner.indices.shape[1]):
            i = learner.indices[state, j]
            g[i] = g[i] + coefficient * learner.value[state, j]
    for i in range(d):
        total = 0.0
        for j in range(d):
            total = total + errors.pseudo_inverse[i, j] * g[j]
        u[i] = total
    pbe = 0.0
    for k in range(errors.measured.shape[0]):
        state = errors.measured[k]
        z = 0.0
        for j in range(learner.indices.shape[1]):
            z = z + learner.value[state, j] * u[learner.indices[state, j]]
        pbe = pbe + errors.mu[k] * (z * z)
    return math.sqrt(pbe)


def feature_covariance(dense: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """``C_ij = sum_s (μ(s) x_i(s)) x_j(s)`` over the measured states' dense rows, in order."""
    d = dense.shape[1]
    c = np.zeros((d, d))
    for k in range(dense.shape[0]):
        for i in range(d):
            if dense[k, i] == 0.0:
                continue
            scaled = mu[k] * dense[k, i]
            for j in range(d):
                c[i, j] = c[i, j] + scaled * dense[k, j]
    return c


# -- fixed points ---------------------------------------------------------------------------


def least_ve_weights(dense: np.ndarray, mu: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Gradient MC's fixed point: the ``w`` of least ``VE`` (``lstsq`` of ``D^½ X w = D^½ v_π``)."""
    root = np.sqrt(mu)
    solution: np.ndarray = np.linalg.lstsq(dense * root[:, None], truth * root, rcond=None)[0]
    return solution


def td_fixed_point(
    dense: np.ndarray, expected_next_rows: np.ndarray, mu: np.ndarray, rewards: np.ndarray,
    gamma: float,
) -> np.ndarray:  # fmt: skip
    """The TD fixed point: ``A w = c``, ``A = Xᵀ D (X - gamma X̄')``, ``c = Xᵀ D r̄`` (``lstsq``)."""
    weighted = dense.T * mu
    a = weighted @ (dense - gamma * expected_next_rows)
    c = weighted @ rewards
    solution: np.ndarray = np.linalg.lstsq(a, c, rcond=None)[0]
    return solution
