"""The access-control queuing task (Sutton & Barto Example 10.2, Figure 10.5).

Ten servers; customers wait in one queue, and the one at its head has a priority of 1, 2, 4
or 8, which it pays if it is served. Each step the agent **accepts** that customer (action
1: a free server takes it, reward its priority) or **rejects** it (action 0: reward 0);
with no free server the customer is rejected whatever the action. Then each busy server
frees, independently, with probability ``0.06``, and the next customer's priority is drawn
uniformly from the four. Nothing ends: a continuing task, for the average-reward setting
(``kind: average_reward`` studies, and ``cartpole-q optimum``'s relative value iteration).

**States.** ``state = priority_index * (servers + 1) + free``, ``priority_index`` 0-3 for
the priorities 1, 2, 4, 8 and ``free`` 0-``servers``: 44 states by default, the components
``(4, 11)`` in C order. The start has every server free, the priority drawn uniformly.
The first outcome below: no busy server freed (0.94), the next customer of priority 1.

**Outcomes.** ``P[s][a]`` lists, for ``freed = 0 .. busy`` (``busy`` counted after the
acceptance) and then each next priority, the outcome ``(C(busy, freed) p^freed (1 -
p)^(busy - freed) / 4, next state, reward, False)``, the binomial factor as
``math.comb(busy, freed) * p**freed * (1 - p)**(busy - freed)`` in float64, divided by 4
after. So a step is one draw against the running sums, as every table world's.

>>> world = AccessControlEnv()
>>> len(world.P), world.P[state_of(3, 10)][ACCEPT][0]  # priority 8, all free: accept pays 8,
(44, (0.235, 9, 8.0, False))
>>> world.P[state_of(0, 0)][ACCEPT] == world.P[state_of(0, 0)][REJECT]  # no free server
True
"""

from __future__ import annotations

import math

import numpy as np

from cartpole_q.families.tables.world import Outcome, Table, TableWorld

REJECT, ACCEPT = 0, 1
"""the actions"""
PRIORITIES = (1.0, 2.0, 4.0, 8.0)
"""what a served customer pays, by priority index"""
SERVERS = 10
FREE_PROBABILITY = 0.06
"""the chance that a busy server frees in one step"""


def state_of(priority_index: int, free: int, servers: int = SERVERS) -> int:
    """The state of a customer of ``PRIORITIES[priority_index]`` at the head, ``free`` servers free.

    >>> state_of(0, 0), state_of(1, 0), state_of(3, 10)
    (0, 11, 43)
    """
    return priority_index * (servers + 1) + free


class AccessControlEnv(TableWorld):
    """Example 10.2: accept or reject the customer at the head of the queue.

    Args:
        servers: how many servers (1 to 20).
        free_probability: the chance a busy server frees in a step, in ``(0, 1]``.
    """

    def __init__(self, servers: int = SERVERS, free_probability: float = FREE_PROBABILITY) -> None:
        if isinstance(servers, bool) or not isinstance(servers, int) or not 1 <= servers <= 20:
            raise ValueError(f"servers must be a whole number from 1 to 20, got {servers!r}")
        if not 0.0 < float(free_probability) <= 1.0:
            raise ValueError(f"free_probability must be in (0, 1], got {free_probability!r}")
        p = float(free_probability)
        n_priorities = len(PRIORITIES)
        super().__init__(n_states=n_priorities * (servers + 1), n_actions=2, start=0)
        self.initial_state_distrib = np.zeros(n_priorities * (servers + 1))
        for index in range(n_priorities):
            self.initial_state_distrib[state_of(index, servers, servers)] = 1.0 / n_priorities
        self.servers = servers
        self.free_probability = p
        table: Table = {}
        for index, priority in enumerate(PRIORITIES):
            for free in range(servers + 1):
                state = state_of(index, free, servers)
                table[state] = {}
                for action in (REJECT, ACCEPT):
                    served = action == ACCEPT and free > 0
                    after = free - 1 if served else free
                    reward = priority if served else 0.0
                    busy = servers - after
                    outcomes: list[Outcome] = []
                    for freed in range(busy + 1):
                        chance = math.comb(busy, freed) * p**freed * (1.0 - p) ** (busy - freed)
                        for following in range(n_priorities):
                            outcomes.append(
                                (
                                    chance / n_priorities,
                                    state_of(following, after + freed, servers),
                                    reward,
                                    False,
                                )
                            )
                    table[state][action] = outcomes
        self.P = table
