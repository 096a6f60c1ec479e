"""The finite MDP: the one model every exact computation takes.

A :class:`FiniteMDP` lists every outcome of every (state, action) as flat arrays, as
Gymnasium's toy-text worlds give them (``env.unwrapped.P[s][a] = [(p, s', r, terminated),
...]``; :meth:`FiniteMDP.from_transitions`), or from a world's dense arrays (Jack's car
rental: :meth:`FiniteMDP.from_dense`); with the start distribution and the actions each
state offers. A terminated outcome contributes its reward and nothing after it; one that is
not terminated continues from its next state. Its backup (:meth:`FiniteMDP.backup`) is the
book's ``sum p(s', r | s, a) [r + gamma v(s')]``, summed over the outcomes in their order.

The solvers that take it are in :mod:`cartpole_q.rl.solvers`; ``optimum``, ``optimum
--policy``, the ``dp`` studies, the exact values a prediction run is measured against and
every table world's exact figures use them.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class FiniteMDP:
    """A finite MDP as flat arrays: one entry per possible outcome of a (state, action)."""

    n_states: int
    n_actions: int
    state: np.ndarray
    """int64: the state each outcome starts from"""
    action: np.ndarray
    """int64: the action taken"""
    probability: np.ndarray
    """float64: the outcome's probability (a (state, action)'s outcomes sum to 1)"""
    next_state: np.ndarray
    """int64: where the outcome leads"""
    reward: np.ndarray
    """float64: its reward"""
    terminated: np.ndarray
    """bool: whether the episode ends there (no value after it)"""
    initial: np.ndarray
    """float64, ``(n_states,)``: the distribution of the start state"""
    allowed: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))
    """bool, ``(n_states, n_actions)``: the actions each state offers (the gambler's stakes up
    to ``min(s, 100 - s)``, Jack's moves of the cars there); empty: every action everywhere"""

    def __post_init__(self) -> None:
        shape = (self.n_states, self.n_actions)
        if self.allowed.size == 0:
            object.__setattr__(self, "allowed", np.ones(shape, dtype=bool))
        if self.allowed.shape != shape or not self.allowed.any(axis=1).all():
            raise ValueError("allowed must be (states, actions) with an action in every state")

    @classmethod
    def from_transitions(
        cls,
        transitions: Mapping[int, Mapping[int, Sequence[tuple[float, int, float, bool]]]],
        initial: Sequence[float] | np.ndarray,
        n_actions: int | None = None,
        allowed: np.ndarray | None = None,
    ) -> FiniteMDP:
        """Build a model from Gymnasium's ``P[s][a] = [(p, s', r, terminated), ...]``.

        States are ``0 .. len(transitions) - 1``; a (state, action) missing from the table
        (or with no outcome) is refused. ``allowed``: the actions each state offers (the
        world's ``allowed_actions()``; default every action).

        Raises:
            ValueError: a state or action is missing, a next state out of range, or a
                probability negative or not summing to 1.
        """
        n_states = len(transitions)
        n_actions = n_actions or max(len(actions) for actions in transitions.values())
        rows: list[tuple[int, int, float, int, float, bool]] = []
        for s in range(n_states):
            for a in range(n_actions):
                outcomes = transitions.get(s, {}).get(a)
                if not outcomes:
                    raise ValueError(
                        f"the transition table has no outcome for state {s}, action {a}"
                    )
                total = 0.0
                for probability, next_state, reward, terminated in outcomes:
                    if not 0 <= int(next_state) < n_states or probability < 0:
                        raise ValueError(
                            f"state {s}, action {a}: bad outcome {next_state, probability}"
                        )
                    total += float(probability)
                    rows.append(
                        (s, a, float(probability), int(next_state), float(reward), bool(terminated))
                    )
                if abs(total - 1.0) > 1e-9:
                    raise ValueError(f"state {s}, action {a}: probabilities sum to {total}")
        columns = list(zip(*rows, strict=True))
        start = np.asarray(initial, dtype=np.float64)
        if start.shape != (n_states,) or abs(start.sum() - 1.0) > 1e-9:
            raise ValueError(f"initial must be a distribution over the {n_states} states")
        return cls(
            n_states=n_states,
            n_actions=n_actions,
            state=np.array(columns[0], dtype=np.int64),
            action=np.array(columns[1], dtype=np.int64),
            probability=np.array(columns[2], dtype=np.float64),
            next_state=np.array(columns[3], dtype=np.int64),
            reward=np.array(columns[4], dtype=np.float64),
            terminated=np.array(columns[5], dtype=bool),
            initial=start,
            allowed=np.zeros((0, 0), dtype=bool) if allowed is None else np.asarray(allowed, bool),
        )

    @classmethod
    def from_dense(
        cls,
        transition: np.ndarray,
        reward: np.ndarray,
        allowed: np.ndarray | None = None,
        initial: np.ndarray | None = None,
    ) -> FiniteMDP:
        """Build a model from dense arrays: ``transition[s, a, s']`` and the expected ``reward[s, a]``.

        Each positive ``transition[s, a, s']`` is an outcome that goes on to ``s'``, in the
        order of ``s'``; what a row leaves below 1 is one more outcome that ends the episode
        (in ``s``); every outcome of ``(s, a)`` pays ``reward[s, a]``, its expected reward.
        ``initial`` defaults to every state alike (Jack's car rental starts so).

        Raises:
            ValueError: the arrays' shapes disagree, or a row's probabilities exceed 1.
        """
        states, actions = reward.shape
        if transition.shape != (states, actions, states):
            raise ValueError(
                f"transition has shape {transition.shape}, not {(states, actions, states)}"
            )
        going = transition > 0.0
        source, action, target = np.nonzero(going)
        left = 1.0 - transition.sum(axis=2)
        if (left < -1e-9).any():
            raise ValueError("a row of transition sums to more than 1")
        ends = np.argwhere(left > 1e-12)
        state = np.concatenate([source, ends[:, 0]])
        taken = np.concatenate([action, ends[:, 1]])
        order = np.lexsort((np.arange(state.size), taken, state))  # by (s, a), s' order kept
        probability = np.concatenate([transition[going], left[ends[:, 0], ends[:, 1]]])
        start = np.full(states, 1.0 / states) if initial is None else np.asarray(initial, float)
        return cls(
            n_states=states,
            n_actions=actions,
            state=state[order].astype(np.int64),
            action=taken[order].astype(np.int64),
            probability=probability[order],
            next_state=np.concatenate([target, ends[:, 0]])[order].astype(np.int64),
            reward=np.asarray(reward, dtype=np.float64)[state[order], taken[order]],
            terminated=np.concatenate([np.zeros(target.size, bool), np.ones(len(ends), bool)])[
                order
            ],
            initial=start,
            allowed=np.zeros((0, 0), dtype=bool) if allowed is None else np.asarray(allowed, bool),
        )

    def backup(self, values: np.ndarray, gamma: float) -> np.ndarray:
        """``Q(s, a) = sum p * (r + gamma * values[s'] * (not terminated))``, ``(S, A)``.

        Summed over the outcomes in the model's order (``np.bincount``), every action
        (an action a state does not offer too: :meth:`masked` leaves them out).
        """
        flat = self.state * self.n_actions + self.action
        continued = np.where(self.terminated, 0.0, values[self.next_state])
        weights = self.probability * (self.reward + gamma * continued)
        size = self.n_states * self.n_actions
        return np.bincount(flat, weights=weights, minlength=size).reshape(
            self.n_states, self.n_actions
        )

    def masked(self, q: np.ndarray) -> np.ndarray:
        """``q`` with the actions a state does not offer at minus infinity (for a maximum)."""
        blocked: np.ndarray = np.where(self.allowed, q, -np.inf)
        return blocked

    def state_backup(self, state: int, values: np.ndarray, gamma: float) -> np.ndarray:
        """One state's :meth:`backup`, ``(A,)`` (an in-place sweep's update)."""
        low, high = self._slices[state], self._slices[state + 1]
        continued = np.where(self.terminated[low:high], 0.0, values[self.next_state[low:high]])
        weights = self.probability[low:high] * (self.reward[low:high] + gamma * continued)
        found: np.ndarray = np.bincount(
            self.action[low:high], weights=weights, minlength=self.n_actions
        )
        return found

    @functools.cached_property
    def _slices(self) -> np.ndarray:
        """Where each state's outcomes start (the outcomes are in state order)."""
        found: np.ndarray = np.searchsorted(self.state, np.arange(self.n_states + 1))
        return found

    def policy_matrix(self, policy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The policy's expected reward per state and its continuing transition matrix."""
        chosen = policy[self.state] == self.action
        expected = np.bincount(
            self.state[chosen],
            weights=(self.probability * self.reward)[chosen],
            minlength=self.n_states,
        )
        going_on = chosen & ~self.terminated
        matrix = np.zeros((self.n_states, self.n_states))
        np.add.at(
            matrix,
            (self.state[going_on], self.next_state[going_on]),
            self.probability[going_on],
        )
        return expected, matrix

    def stochastic_policy_matrix(self, pi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`policy_matrix` of a stochastic policy, ``pi[s, a]`` the probability of ``a``."""
        weight = pi[self.state, self.action] * self.probability
        expected = np.bincount(self.state, weights=weight * self.reward, minlength=self.n_states)
        going_on = ~self.terminated
        matrix = np.zeros((self.n_states, self.n_states))
        np.add.at(matrix, (self.state[going_on], self.next_state[going_on]), weight[going_on])
        return expected, matrix

    def terminal_states(self) -> np.ndarray:
        """bool, ``(n_states,)``: the absorbing states where every action ends the episode.

        Every outcome of every action stays in the state, pays 0 and terminates: the
        book's terminal states (the ends of a random walk, FrozenLake's holes and goal),
        whose value is 0 under every policy; prediction errors leave them out.
        """
        ends = np.ones(self.n_states, dtype=bool)
        absorbing = self.terminated & (self.reward == 0.0) & (self.next_state == self.state)
        np.logical_and.at(ends, self.state, absorbing)
        return ends
