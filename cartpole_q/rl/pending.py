"""The queue of pending steps of the n-step methods: a ring buffer of (state, action, reward).

A step joins the queue when it is taken and leaves it when its n-step return is settled:
``n`` steps later, or when the episode ends. The queue is four arrays of the algorithm's
memory: ``states``, ``actions``, ``rewards`` (each of length ``n``) and ``counter`` =
``[head, count]``, the oldest slot and how many steps are pending.

>>> import numpy as np
>>> states, actions, rewards, counter = queue_memory(2)
>>> push(states, actions, rewards, counter, 3, 1, 0.5)
>>> push(states, actions, rewards, counter, 4, 0, 1.5)
>>> drop_oldest(counter, 2)
>>> push(states, actions, rewards, counter, 5, 1, 2.5)
>>> [int(states[slot(counter, 2, i)]) for i in range(int(counter[1]))]
[4, 5]
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Param
from cartpole_q.rl.tabular import Rates, Table, compilable, update, value

N = Param(
    "n", 4, "the number of rewards before bootstrapping (1: the one-step method)",
    kind="int", low=1, high=10_000,
)  # fmt: skip
"""``agent.n`` of the n-step methods"""


@compilable
def push(
    states: np.ndarray, actions: np.ndarray, rewards: np.ndarray, counter: np.ndarray,
    state: int, action: int, reward: float,
) -> None:  # fmt: skip
    """Append a step as the newest pending one (the caller keeps the count at most ``n``)."""
    where = (counter[0] + counter[1]) % states.shape[0]
    states[where] = state
    actions[where] = action
    rewards[where] = reward
    counter[1] += 1


@compilable
def slot(counter: np.ndarray, n: int, position: int) -> int:
    """The slot of the pending step at ``position`` (0: the oldest)."""
    return int((counter[0] + position) % n)


@compilable
def drop_oldest(counter: np.ndarray, n: int) -> None:
    """Remove the oldest pending step."""
    counter[0] = (counter[0] + 1) % n
    counter[1] -= 1


@compilable
def oldest_is_due(counter: np.ndarray, n: int, ended: bool) -> bool:
    """Whether the oldest pending step is settled now.

    At the episode's end while any step is pending; else once the queue holds ``n`` steps.
    The n-step hooks settle in one loop on this, so that their settle is called (and, as
    compiled code inlines every call, compiled) from one place.
    """
    return bool(counter[1] > 0 and (ended or counter[1] == n))


@compilable
def settle_oldest(
    q: Table, states: np.ndarray, actions: np.ndarray, rewards: np.ndarray,
    counter: np.ndarray, next_state: int, next_action: int, bootstrap: bool, rates: Rates,
) -> None:  # fmt: skip
    """Update the oldest pending step toward its return, and remove it from the queue."""
    alpha, gamma = rates.alpha, rates.gamma
    n = states.shape[0]
    pending = counter[1]
    oldest = slot(counter, n, 0)
    target = rewards[oldest]
    for i in range(1, pending):
        target = target + gamma ** float(i) * rewards[slot(counter, n, i)]
    if bootstrap:
        target = target + gamma ** float(pending) * value(q, next_state, next_action)
    update(q, states[oldest], actions[oldest], target, alpha)
    drop_oldest(counter, n)


def queue_memory(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """An empty queue for ``n`` steps: states, actions, rewards and ``[head, count]``."""
    return (
        np.zeros(n, dtype=np.int64),
        np.zeros(n, dtype=np.int64),
        np.zeros(n, dtype=np.float64),
        np.zeros(2, dtype=np.int64),
    )
