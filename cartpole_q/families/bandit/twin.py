"""The compiled twin of the k-armed testbed (``cartpole_q/Bandit-v0``, chapter 2).

It draws what :class:`~cartpole_q.families.bandit.world.BanditEnv` draws, in the same order, from a
generator seeded as Gymnasium seeds ``env.np_random`` (``reset(seed=s)``:
``Generator(PCG64(SeedSequence(s)))``): at reset ``normal(mean, spread)`` per arm in arm
order; per step the reward ``normal(q*(a), 1.0)``, then, when ``walk > 0``, ``normal(0.0,
walk)`` added to each true value in arm order. numba's ``Generator.normal`` is NumPy's
(``loc + scale * standard_normal``, the same ziggurat), so the draws are the same floats:
``tests/test_bandits.py`` checks the twin against ``gymnasium.make`` step for step.

Plain Python marked :func:`~cartpole_q.rl.tabular.compilable`: the bandit engine
(:mod:`cartpole_q.engines.bandit`) compiles it into its loop.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cartpole_q.rl.tabular import Rng, compilable

REWARD_STD = 1.0
"""the standard deviation of a reward around ``q*(a)`` (as ``worlds/bandit.py``)"""


class ArmedTestbed(NamedTuple):
    """The ``gymnasium.make("cartpole_q/Bandit-v0", ...)`` arguments the twin plays."""

    k: int
    """arms"""
    mean: float
    """the mean of the true values drawn at reset"""
    spread: float
    """their standard deviation"""
    walk: float
    """the standard deviation of each true value's step after every step (0: none)"""


@compilable
def reset_testbed(testbed: ArmedTestbed, q_star: np.ndarray, rng: Rng) -> None:
    """Draw the true values: ``normal(mean, spread)`` for each arm in order."""
    for arm in range(testbed.k):
        q_star[arm] = rng.normal(testbed.mean, testbed.spread)


@compilable
def step_testbed(
    testbed: ArmedTestbed, q_star: np.ndarray, arm: int, rng: Rng
) -> tuple[float, bool]:
    """Play ``arm``: the reward and whether the arm was optimal; then the walk, if any."""
    best = q_star[0]
    for other in range(1, testbed.k):
        if q_star[other] > best:
            best = q_star[other]
    optimal = q_star[arm] == best
    reward = rng.normal(q_star[arm], REWARD_STD)
    if testbed.walk > 0.0:
        for other in range(testbed.k):
            q_star[other] += rng.normal(0.0, testbed.walk)
    return reward, optimal
