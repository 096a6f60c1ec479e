"""Sutton & Barto's 10-armed testbed (chapter 2, Figures 2.2-2.6) as a Gymnasium environment.

A bandit has one state and ``k`` arms. At ``reset`` each arm's true value ``q*(a)`` is drawn
from a normal distribution of mean ``mean`` (0; Figure 2.5: 4) and standard deviation
``spread`` (1); each step pays a reward drawn from ``N(q*(a), 1)`` for the arm ``a`` played.
With ``walk > 0`` the task is nonstationary (Exercise 2.5): after every step each ``q*(a)``
moves by an independent ``N(0, walk)`` increment (the exercise: ``walk=0.01``, ``spread=0``,
every arm starting equal).

**Draws**, all from the environment's ``np_random`` (``reset(seed=...)`` seeds it), each a
scalar ``np_random.normal(loc, scale)``:

- ``reset``: ``q*(a) = normal(mean, spread)`` for ``a = 0, 1, ..., k - 1`` in arm order
  (``k`` draws, also when ``spread`` is 0);
- ``step(a)``: the reward ``normal(q*(a), 1.0)``; then, when ``walk > 0``, ``q*(b) +=
  normal(0.0, walk)`` for ``b = 0, ..., k - 1`` in arm order (``k`` draws).

``info["optimal"]`` says whether the arm played has the largest true value at that step
(before the step's walk; ties: every arm with the largest value is optimal);
``info["q_star"]`` is a copy of the true values it was played against. The observation is
always 0; the testbed never ends an episode itself (registered with the book's 1,000 steps as
its time limit; ``cartpole-q bandit`` makes it with its study's ``steps``).
A compiled twin that draws the same numbers from a generator seeded the same way is
:mod:`cartpole_q.families.bandit.twin`.

>>> import gymnasium, cartpole_q
>>> env = gymnasium.make("cartpole_q/Bandit-v0")
>>> env.reset(seed=0)[0], env.action_space, env.observation_space
(0, Discrete(10), Discrete(1))
>>> _, reward, terminated, truncated, info = env.step(3)
>>> round(reward, 4), terminated, truncated, info["optimal"]
(-0.5184, False, False, False)
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

ARMS = 10
"""the book's ``k``"""
REWARD_STD = 1.0
"""the standard deviation of a reward around ``q*(a)`` (the book: variance 1)"""


class BanditEnv(gymnasium.Env[Any, Any]):
    """The k-armed testbed.

    Args:
        k: the number of arms (10).
        mean: the mean of the true values drawn at reset (0; Figure 2.5: 4).
        spread: their standard deviation (1; Exercise 2.5: 0, every arm equal).
        walk: the standard deviation of each true value's random step after every step
            (0: stationary; Exercise 2.5: 0.01).
    """

    metadata = {"render_modes": [], "render_fps": 4}  # noqa: RUF012 - gymnasium.Env declares it

    def __init__(
        self, k: int = ARMS, mean: float = 0.0, spread: float = 1.0, walk: float = 0.0
    ) -> None:
        if isinstance(k, bool) or not isinstance(k, int) or k < 1:
            raise ValueError(f"`k` must be a whole number of arms >= 1, got {k!r}")
        for name, value in (("mean", mean), ("spread", spread), ("walk", walk)):
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"`{name}` must be a number, got {value!r}")
            if not math.isfinite(value) or (name != "mean" and value < 0):
                raise ValueError(f"`{name}` must be finite{'' if name == 'mean' else ' and >= 0'}")
        self.k, self.mean, self.spread, self.walk = k, float(mean), float(spread), float(walk)
        self.observation_space = spaces.Discrete(1)
        self.action_space = spaces.Discrete(k)
        self.q_star = np.zeros(k)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Draw the true values: ``k`` draws ``normal(mean, spread)`` in arm order."""
        super().reset(seed=seed)
        for arm in range(self.k):
            self.q_star[arm] = self.np_random.normal(self.mean, self.spread)
        return 0, {"q_star": self.q_star.copy()}

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Pay ``normal(q*(action), 1)``; then, when ``walk > 0``, move every true value."""
        arm = int(action)
        played = self.q_star.copy()
        optimal = bool(played[arm] == played.max())
        reward = float(self.np_random.normal(played[arm], REWARD_STD))
        if self.walk > 0.0:
            for other in range(self.k):
                self.q_star[other] += self.np_random.normal(0.0, self.walk)
        return 0, reward, False, False, {"optimal": optimal, "q_star": played}
