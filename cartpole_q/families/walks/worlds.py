"""Sutton & Barto's random walks: 5 states (Example 6.2) and 19 states (Example 7.1).

A walk's states ``1 .. states`` are numbered left to right; ``0`` and ``states + 1`` are its
two ends (absorbing, as FrozenLake's goal). Episodes start in the middle. Stepping into
the right end earns +1, into the left end ``left_reward``, any other step 0:

- ``cartpole_q/RandomWalk5-v0``: Example 6.2's walk, states A-E (1-5) between a 0 end and a
  +1 end, started in C; the random policy's values are 1/6, 2/6, ..., 5/6 (undiscounted).
- ``cartpole_q/RandomWalk-v0``: Example 7.1's 19 states between a -1 end and a +1 end
  (Figure 7.2, chapter 12), started in state 10; true values -0.9, -0.8, ..., 0.9.
- ``cartpole_q/RandomWalk1000-v0``: Example 9.1's 1000 states between a -1 end and a +1 end,
  started in state 500, each step a jump to one of the 100 states on the left or the 100 on
  the right (:class:`JumpingWalkEnv`); ``groups`` aggregates the states (Figures 9.1, 9.2).

The book's walks have no actions: a step goes left or right with equal probability. Here
the walk has two actions, left (0) and right (1), so that it can be trained as well as
evaluated: the prediction algorithms (``agent.policy: random``) learn the book's ``v(s)``;
a uniformly random policy is the book's walk. The optimal policy goes right (+1).
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from cartpole_q.families.tables.world import Outcome, Table, TableWorld

WALK_STATES = 19
"""the non-terminal states of Example 7.1's walk"""
MOVES = (-1, 1)
"""per action: the step along the walk (left, right)"""


class RandomWalkEnv(TableWorld):
    """A walk of ``states`` states between a ``left_reward`` end and a +1 end, started in the middle.

    Args:
        states: the non-terminal states (an odd number, so that there is a middle).
        left_reward: the reward of stepping into the left end.
    """

    def __init__(self, states: int = WALK_STATES, left_reward: float = -1.0) -> None:
        if states < 1 or states % 2 == 0:
            raise ValueError(f"a random walk needs an odd number of states, got {states}")
        super().__init__(n_states=states + 2, n_actions=len(MOVES), start=(states + 1) // 2)
        self.states = states
        self.left_reward = float(left_reward)
        self.P = self._table()
        # Example 6.2 names its five states A-E (figures label them so)
        self.labels = {state: "ABCDE"[state - 1] for state in range(1, 6)} if states == 5 else {}

    def _table(self) -> Table:
        """``P``: a step moves one state; the ends are absorbing."""
        left_end, right_end = 0, self.states + 1
        rewards = {left_end: self.left_reward, right_end: 1.0}
        table: Table = {}
        for state in range(self.states + 2):
            table[state] = {}
            for action, move in enumerate(MOVES):
                if state in (left_end, right_end):
                    table[state][action] = [(1.0, state, 0.0, True)]
                    continue
                following = state + move
                ended = following in (left_end, right_end)
                table[state][action] = [(1.0, following, rewards.get(following, 0.0), ended)]
        return table


JUMP_STATES = 1000
"""the non-terminal states of Example 9.1's walk"""
JUMP_REACH = 100
"""how far one step of Example 9.1's walk may jump, either way"""


class JumpingWalkEnv(TableWorld):
    """Example 9.1's walk: ``states`` states, each step a jump of 1 to ``reach`` states.

    States ``1 .. states`` lie between a -1 end (``0``) and a +1 end (``states + 1``);
    episodes start in state ``states // 2`` (500 of 1000). The book's step goes "to one of
    the 100 neighboring states to its left, or to one of the 100 neighboring states to its
    right, all with equal probability"; near an end, the probability of the neighbours
    beyond it goes to terminating there. Here the walk has two actions, left (0) and right
    (1), as the other walks (a uniformly random policy is the book's walk), and the action
    draws the distance: ``P[s][a]`` lists the jumps of 1, 2, ..., ``reach`` states that stay
    on the walk, each of probability ``1 / reach``, then, if any would leave it, one outcome
    into that end with their probability together (``count / reach``). Rewards: +1 into the
    right end, -1 into the left one, 0 otherwise; the ends are absorbing.

    **State aggregation.** With ``groups`` the observation is a state's group, not the state:
    ``groups`` groups of ``states / groups`` neighbouring states each, state ``s`` in group
    ``(s - 1) * groups // states`` (the left end observed as group 0, the right end as the
    last; their values are never read). A table then has one row per group, and the
    prediction algorithms on it are Sutton & Barto's gradient Monte Carlo and semi-gradient
    TD with state aggregation (section 9.3): with one active feature per state, the
    semi-gradient update of the group's weight is the tabular update of its row. The model
    (``P``) keeps every state: the true values are per state (:attr:`observation_of_state`).

    **A point for tile coding.** With ``position=True`` the observation is the state's
    number as a point on a line, ``Box(0, states + 1, (1,), float32)`` (state ``s`` observed
    as ``[s]``), so that ``discretization`` with ``tilings: T > 1`` tile-codes it (section
    9.5.4, Figure 9.10: 50 tilings of 5 tiles of 200 states are ``bins: [5], low: [1], high:
    [1001], tilings: 50``). :attr:`point_of_state` declares the mapping, so the true values
    are measured on tiles too.

    Args:
        states: the non-terminal states (even, so that the start is ``states // 2``).
        reach: the longest jump, either way.
        groups: aggregate the states into this many groups (it must divide ``states``), or
            ``None``: the observation is the state.
        position: observe the state as a point (a Box) rather than an integer (not with
            ``groups``).

    >>> walk = JumpingWalkEnv(states=10, reach=3, groups=2)
    >>> walk.P[9][1]  # from 9, right: to 10, or into the +1 end with probability 2/3
    [(0.3333333333333333, 10, 0.0, False), (0.6666666666666666, 11, 1.0, True)]
    >>> walk.observation_of_state.tolist()
    [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]
    """

    def __init__(
        self,
        states: int = JUMP_STATES,
        reach: int = JUMP_REACH,
        groups: int | None = None,
        position: bool = False,
    ) -> None:
        if states < 2 or states % 2:
            raise ValueError(f"the jumping walk needs an even number of states, got {states}")
        if not 1 <= reach <= states:
            raise ValueError(f"reach must be from 1 to the states ({states}), got {reach}")
        if groups is not None and not (1 <= groups <= states and states % groups == 0):
            raise ValueError(f"groups must divide the {states} states, got {groups}")
        super().__init__(n_states=states + 2, n_actions=len(MOVES), start=states // 2)
        self.states = states
        self.reach = reach
        self.groups = groups
        self.P = self._table()
        if groups is not None:
            grouped = (np.arange(1, states + 1) - 1) * groups // states
            self.observation_of_state = np.concatenate([[0], grouped, [groups - 1]]).astype(
                np.int64
            )
            self.observation_space = spaces.Discrete(groups)
        if position:
            if groups is not None:
                raise ValueError("position and groups are two observations: give one")
            self.point_of_state = np.arange(states + 2, dtype=np.float32).reshape(-1, 1)
            self.observation_space = spaces.Box(0.0, float(states + 1), (1,), np.float32)

    def _table(self) -> Table:
        """``P``: the jumps that stay on the walk, then the one into an end; absorbing ends."""
        left_end, right_end = 0, self.states + 1
        table: Table = {}
        for state in range(self.states + 2):
            table[state] = {}
            for action, move in enumerate(MOVES):
                if state in (left_end, right_end):
                    table[state][action] = [(1.0, state, 0.0, True)]
                    continue
                outcomes: list[Outcome] = []
                beyond = 0
                for distance in range(1, self.reach + 1):
                    following = state + move * distance
                    if left_end < following < right_end:
                        outcomes.append((1.0 / self.reach, following, 0.0, False))
                    else:
                        beyond += 1
                if beyond:
                    end = right_end if move > 0 else left_end
                    reward = 1.0 if move > 0 else -1.0
                    outcomes.append((beyond / self.reach, end, reward, True))
                table[state][action] = outcomes
        return table
