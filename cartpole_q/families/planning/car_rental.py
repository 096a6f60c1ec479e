"""Jack's car rental (Sutton & Barto, Example 4.2, Figure 4.2).

Jack has two locations of at most ``max_cars`` cars each (20). Each night he moves up to
``max_move`` cars (5) between them at $2 a car; each day a location rents out as many cars
as are requested and it has, at $10 a car, and then gets cars back, which can be rented the
next day. Requests and returns are Poisson: 3 and 4 requests, 3 and 2 returns a day at the
first and second location. Cars beyond ``max_cars`` at a location (after the move, or
after the returns) go back to the nationwide company. A continuing task (the book
discounts with gamma 0.9); Gymnasium's time limit (1,000 days) cuts its episodes.

**States.** ``first * (max_cars + 1) + second``: the cars at each location at the end of a
day. An episode starts in a state drawn uniformly.

**Actions.** Action ``a`` moves ``a - max_move`` cars from the first location to the second
(negative: the other way), so ``Discrete(2 * max_move + 1)``; a move of more cars than the
location has moves those it has (and costs only them). :meth:`CarRentalEnv.allowed_actions`
leaves such moves out of dynamic programming, as Zhang's script does.

**Model** (:meth:`CarRentalEnv.dense_model`). Exact, with the returns random, as the book
states the problem (Zhang's script, by default, returns the expected counts, 3 and 2, every
day). The Poisson tails are not cut: a request for more cars than a location has rents all
of them, so the probabilities of ``n`` or more requests are one outcome (``P(N >= n)``),
and a return that fills the location past ``max_cars`` fills it, so the probabilities of
``max_cars - left`` or more returns are one outcome too; every row sums to 1 exactly (to the
last bits of the floats). The reward of a (state, action) is its expected one: ``10 *
E[cars rented]`` minus ``2 * |cars moved|``.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

MAX_CARS = 20
MAX_MOVE = 5
RENTAL_CREDIT = 10.0
MOVE_COST = 2.0
REQUESTS = (3.0, 4.0)
"""the mean requests a day at the first and second location"""
RETURNS = (3.0, 2.0)
"""the mean returns a day at the first and second location"""


def poisson_pmf(mean: float, count: int) -> np.ndarray:
    """``P(N = k)`` for ``k = 0 .. count - 1``, ``N`` Poisson with ``mean``."""
    return np.array([math.exp(-mean) * mean**k / math.factorial(k) for k in range(count)])


def day_at_location(
    requested: float, returned: float, max_cars: int
) -> tuple[np.ndarray, np.ndarray]:
    """One location's day, from ``n`` cars in the morning: where it ends, and what it rents.

    Returns:
        ``following[n, c]``, the probability of ending the day with ``c`` cars, and
        ``rented[n]``, the expected number of cars rented.
    """
    size = max_cars + 1
    request_pmf = poisson_pmf(requested, size)
    return_pmf = poisson_pmf(returned, size)
    following = np.zeros((size, size))
    rented = np.zeros(size)
    for morning in range(size):
        # Requests of `morning` or more rent every car: their tail is one outcome.
        rent = np.append(request_pmf[:morning], 1.0 - request_pmf[:morning].sum())
        rented[morning] = rent @ np.arange(morning + 1)
        for count, p_rent in enumerate(rent):
            left = morning - count
            # Returns of `max_cars - left` or more fill the location: one outcome too.
            back = np.append(
                return_pmf[: max_cars - left], 1.0 - return_pmf[: max_cars - left].sum()
            )
            following[morning, left:] += p_rent * back
    return following, rented


class CarRentalEnv(gymnasium.Env[Any, Any]):
    """Jack's car rental: move cars overnight, rent them by day.

    Args:
        max_cars: the most cars a location holds.
        max_move: the most cars moved in a night.
    """

    metadata = {"render_modes": [], "render_fps": 4}  # noqa: RUF012 - gymnasium.Env declares it

    def __init__(self, max_cars: int = MAX_CARS, max_move: int = MAX_MOVE) -> None:
        for name, value in (("max_cars", max_cars), ("max_move", max_move)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"`{name}` must be a whole number of at least 1, got {value!r}")
        self.max_cars, self.max_move = max_cars, max_move
        self.observation_space = spaces.Discrete((max_cars + 1) ** 2)
        self.action_space = spaces.Discrete(2 * max_move + 1)
        self.action_values = tuple(range(-max_move, max_move + 1))
        """the cars each action moves from the first location to the second"""
        self.cars = (0, 0)

    def state_of(self, first: int, second: int) -> int:
        """The state of ``first`` and ``second`` cars."""
        return first * (self.max_cars + 1) + second

    def moved(self, first: int, second: int, action: int) -> int:
        """The cars ``action`` moves from the first location (at most those there are)."""
        return min(max(int(action) - self.max_move, -second), first)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Start in a state drawn uniformly."""
        super().reset(seed=seed)
        size = self.max_cars + 1
        state = int(self.np_random.integers(size * size))
        self.cars = divmod(state, size)
        return state, {}

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Move the cars, then a day: requests, then returns, each Poisson from ``np_random``."""
        first, second = self.cars
        moved = self.moved(first, second, action)
        morning = (min(first - moved, self.max_cars), min(second + moved, self.max_cars))
        reward = -MOVE_COST * abs(moved)
        evening = []
        for cars, requested, returned in zip(morning, REQUESTS, RETURNS, strict=True):
            rented = min(int(self.np_random.poisson(requested)), cars)
            reward += RENTAL_CREDIT * rented
            evening.append(
                min(cars - rented + int(self.np_random.poisson(returned)), self.max_cars)
            )
        self.cars = (evening[0], evening[1])
        return self.state_of(*self.cars), reward, False, False, {"moved": moved}

    def allowed_actions(self) -> np.ndarray:
        """bool, ``(states, actions)``: the moves of no more cars than a location has."""
        size = self.max_cars + 1
        first, second = np.divmod(np.arange(size * size), size)
        move = np.array(self.action_values)[None, :]
        allowed: np.ndarray = (move <= first[:, None]) & (-move <= second[:, None])
        return allowed

    def dense_model(self) -> tuple[np.ndarray, np.ndarray]:
        """The exact model (see the module's notes).

        Returns:
            ``transition[s, a, s']`` and the expected ``reward[s, a]``.
        """
        size = self.max_cars + 1
        days = [day_at_location(REQUESTS[i], RETURNS[i], self.max_cars) for i in range(2)]
        states, actions = size * size, 2 * self.max_move + 1
        transition = np.zeros((states, actions, states))
        reward = np.zeros((states, actions))
        for first in range(size):
            for second in range(size):
                state = self.state_of(first, second)
                for action in range(actions):
                    moved = self.moved(first, second, action)
                    one = min(first - moved, self.max_cars)
                    two = min(second + moved, self.max_cars)
                    transition[state, action] = np.outer(days[0][0][one], days[1][0][two]).ravel()
                    rented = days[0][1][one] + days[1][1][two]
                    reward[state, action] = RENTAL_CREDIT * rented - MOVE_COST * abs(moved)
        return transition, reward
