"""Bandit algorithms (Sutton & Barto, chapter 2): how an arm is chosen, how estimates learn.

Plain Python that numba compiles (every function is :func:`~cartpole_q.rl.tabular.compilable`;
:mod:`cartpole_q.engines.bandit` runs them on the testbed), so they run as they are in a
doctest. A learner is a :class:`BanditAgent`: an action-selection rule and its parameters.
Its memory is four arrays of ``k`` entries: ``values`` (the estimates Q, starting at
``q_init``), ``counts`` (N, the times each arm was played), ``preferences`` (H, the gradient
bandit's, starting at 0) and ``probabilities`` (pi, the gradient bandit's softmax, also the
scratch of UCB's scores), with ``average`` (R-bar) beside them.

The rules, stated precisely (``t`` is the step, 1 for the first; ``rng`` the agent's
generator; ties among equal maxima are broken at random, as the book does: among the
``m`` arms with the largest score the ``rng.integers(0, m)``-th in arm order, nothing drawn
when ``m = 1``):

- ``epsilon_greedy``: at ``epsilon <= 0`` greedy, nothing drawn; at ``epsilon >= 1``
  ``rng.integers(0, k)``; otherwise ``rng.random() < epsilon`` decides, then
  ``rng.integers(0, k)`` when exploring, else greedy. Greedy = the largest ``values``, ties
  at random. Optimistic initial values are ``q_init``.
- ``ucb`` (eq. 2.10): while some arms are untried (``N(a) = 0``), one of them: the only one,
  or the ``rng.integers(0, u)``-th of the ``u`` untried in arm order. Then the largest
  ``Q(a) + c * sqrt(log(t) / N(a))`` (natural log, ``t`` as a float), ties at random.
- ``gradient`` (eq. 2.11-2.12): ``pi(a) = exp(H(a) - m) / S`` with ``m = max_b H(b)`` and ``S``
  the sum of ``exp(H(b) - m)`` in arm order from 0.0; then ``u = rng.random()`` (one draw) and
  the first arm ``a`` whose running sum ``pi(0) + ... + pi(a)`` (from 0.0) exceeds ``u``
  (the last arm if rounding leaves none).

Learning, after the reward ``R`` of arm ``A`` at step ``t``: ``N(A) += 1``; ``average +=
(R - average) / t`` (the mean of every reward so far, this one included); then

- value rules: sample averages (``alpha`` 0): ``Q(A) += (R - Q(A)) / N(A)``; constant step:
  ``Q(A) += alpha * (R - Q(A))``;
- gradient: ``b = average`` with the baseline, else 0.0; ``g = alpha * (R - b)``; for each arm
  ``a`` in order: ``H(a) += g * (1.0 - pi(a))`` for ``a = A``, else ``H(a) -= g * pi(a)``, with
  the ``pi`` the arm was drawn from.

>>> import numpy as np
>>> agent = BanditAgent(EPSILON_GREEDY, 0.0, 0.0, 0.0, 0.0, False)
>>> memory = new_memory(agent, 3)
>>> arm = choose(agent, memory, 1, np.random.default_rng(0))
>>> arm
2
>>> learn(agent, memory, arm, 1.5, 1)
>>> memory.values.tolist(), memory.counts.tolist(), float(memory.average[0])
([0.0, 0.0, 1.5], [0, 0, 1], 1.5)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from cartpole_q.rl.tabular import Rng, compilable

EPSILON_GREEDY, UCB, GRADIENT = 0, 1, 2
"""the action-selection rules, as :attr:`BanditAgent.rule` holds them"""
RULES = {"epsilon_greedy": EPSILON_GREEDY, "ucb": UCB, "gradient": GRADIENT}
"""a study file's ``method`` -> the rule"""


class BanditAgent(NamedTuple):
    """A bandit learner: its rule and parameters (the compiled loop reads them by name)."""

    rule: int
    """:data:`EPSILON_GREEDY`, :data:`UCB` or :data:`GRADIENT`"""
    epsilon: float
    """``epsilon_greedy``: the probability of a uniformly random arm"""
    c: float
    """``ucb``: the degree of exploration ``c``"""
    alpha: float
    """the constant step size; 0 = sample averages (value rules only)"""
    q_init: float
    """every arm's initial estimate ``Q_1(a)`` (optimistic: above the true values)"""
    baseline: bool
    """``gradient``: whether the reward baseline is the average reward (else 0)"""


class BanditMemory(NamedTuple):
    """A learner's memory over ``k`` arms."""

    values: np.ndarray
    """float64: the estimates ``Q(a)``"""
    counts: np.ndarray
    """int64: ``N(a)``, the times each arm was played"""
    preferences: np.ndarray
    """float64: the gradient bandit's ``H(a)``"""
    probabilities: np.ndarray
    """float64: the gradient bandit's ``pi(a)``; UCB's scores"""
    average: np.ndarray
    """float64, one entry: the average of the rewards so far (``R-bar``)"""


@compilable
def new_memory(agent: BanditAgent, k: int) -> BanditMemory:
    """A learner's memory before the first step: ``Q = q_init``, ``N = 0``, ``H = 0``."""
    return BanditMemory(
        np.full(k, agent.q_init), np.zeros(k, np.int64), np.zeros(k), np.zeros(k), np.zeros(1)
    )


@compilable
def largest_at_random(scores: np.ndarray, rng: Rng) -> int:
    """An arm with the largest score: the ``rng.integers(0, m)``-th of the ``m`` tied ones.

    Nothing is drawn when one arm is best (or none compares equal: NaN).
    """
    best, first, tied = scores[0], 0, 1
    for arm in range(1, scores.shape[0]):
        if scores[arm] > best:
            best, first, tied = scores[arm], arm, 1
        elif scores[arm] == best:
            tied += 1
    if tied <= 1:
        return first
    pick = int(rng.integers(0, tied))
    for arm in range(first, scores.shape[0]):
        if scores[arm] == best:
            if pick == 0:
                return arm
            pick -= 1
    return first


@compilable
def epsilon_greedy_arm(values: np.ndarray, epsilon: float, rng: Rng) -> int:
    """A uniform random arm with probability ``epsilon``, else a greedy one (ties at random)."""
    if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
        return int(rng.integers(0, values.shape[0]))
    return largest_at_random(values, rng)


@compilable
def ucb_arm(memory: BanditMemory, c: float, t: int, rng: Rng) -> int:
    """An untried arm (at random among them), else the largest upper confidence bound."""
    counts, scores = memory.counts, memory.probabilities
    untried = 0
    for arm in range(counts.shape[0]):
        if counts[arm] == 0:
            untried += 1
    if untried > 0:
        pick = int(rng.integers(0, untried)) if untried > 1 else 0
        for arm in range(counts.shape[0]):
            if counts[arm] == 0:
                if pick == 0:
                    return arm
                pick -= 1
    log_t = math.log(float(t))
    for arm in range(counts.shape[0]):
        scores[arm] = memory.values[arm] + c * math.sqrt(log_t / counts[arm])
    return largest_at_random(scores, rng)


@compilable
def softmax(preferences: np.ndarray, probabilities: np.ndarray) -> None:
    """``probabilities = exp(H - max H) / sum``, the sum in arm order from 0.0."""
    top = preferences[0]
    for arm in range(1, preferences.shape[0]):
        if preferences[arm] > top:
            top = preferences[arm]
    total = 0.0
    for arm in range(preferences.shape[0]):
        probabilities[arm] = math.exp(preferences[arm] - top)
        total += probabilities[arm]
    for arm in range(preferences.shape[0]):
        probabilities[arm] = probabilities[arm] / total


@compilable
def gradient_arm(memory: BanditMemory, rng: Rng) -> int:
    """An arm drawn from the softmax of the preferences: one ``rng.random()``."""
    softmax(memory.preferences, memory.probabilities)
    u = rng.random()
    running = 0.0
    last = int(memory.probabilities.shape[0]) - 1
    for arm in range(last):
        running += memory.probabilities[arm]
        if u < running:
            return arm
    return last


@compilable
def choose(agent: BanditAgent, memory: BanditMemory, t: int, rng: Rng) -> int:
    """The arm to play at step ``t`` (1 for the first), by the agent's rule."""
    if agent.rule == GRADIENT:
        return gradient_arm(memory, rng)
    if agent.rule == UCB:
        return ucb_arm(memory, agent.c, t, rng)
    return epsilon_greedy_arm(memory.values, agent.epsilon, rng)


@compilable
def learn(agent: BanditAgent, memory: BanditMemory, arm: int, reward: float, t: int) -> None:
    """Learn from ``reward`` for ``arm`` at step ``t``: counts, average, then the rule's update."""
    memory.counts[arm] += 1
    memory.average[0] += (reward - memory.average[0]) / t
    if agent.rule == GRADIENT:
        baseline = memory.average[0] if agent.baseline else 0.0
        step = agent.alpha * (reward - baseline)
        for other in range(memory.preferences.shape[0]):
            if other == arm:
                memory.preferences[other] += step * (1.0 - memory.probabilities[other])
            else:
                memory.preferences[other] -= step * memory.probabilities[other]
    elif agent.alpha > 0.0:
        memory.values[arm] += agent.alpha * (reward - memory.values[arm])
    else:
        memory.values[arm] += (reward - memory.values[arm]) / memory.counts[arm]
