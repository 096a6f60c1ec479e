"""An independent re-derivation of the training contract, written from the texts alone.

Sources: ``design.md`` ("Randomness and the training loop", "Algorithms", the binning rule of
"Run-directory contract", "Discrete observations", "CartPole physics") and
``docs/algorithms.md`` (every algorithm beyond design.md's four). It is plain Python on
``gymnasium.make`` (NumPy only for the generators and the returned arrays) and imports
nothing from ``cartpole_q``: the tests check that the package's runs are byte-identical to it.

The Q-table is a list of rows (one per state, ``n_actions`` Python floats each): Python
floats are IEEE float64 and every formula below is written exactly as the texts state it,
parenthesised, left to right.

Tile coding (docs/algorithms.md, "Tile coding"): the table is the weights, one row per tile,
and a state is the tuple of its ``T`` tiles' rows; ``Q(x, b)`` sums the tiles' weights from
0.0 in tiling order, and a change of ``Q(x, b)`` by ``amount`` adds ``amount / T`` to each.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

Schedule = Callable[[int], float]

# design.md, "CartPole physics": the keys env.randomize may list, in the order they are drawn.
RANDOMIZE_ORDER = ("gravity", "masscart", "masspole", "length", "force_mag", "tau")

# docs/algorithms.md, "Monte Carlo": the buffer's length of an environment without a time limit.
NO_TIME_LIMIT_LENGTH = 10_000


@dataclass
class ReferenceRun:
    """What one re-derived training run produced.

    Attributes:
        q_table: The kept table, float64 of shape ``(*state_shape, n_actions)``.
        visits: Visits of every (state, action) over all trained episodes, int64, same shape.
        returns: Every trained episode's return.
        lengths: Every trained episode's number of steps.
        solved_episode: The 1-based solve episode, or None.
        errors: A prediction run's RMS error after each episode (None when not measured).
    """

    q_table: np.ndarray
    visits: np.ndarray
    returns: list[float]
    lengths: list[int]
    solved_episode: int | None
    errors: list[float] | None = None


# Schedules (design.md, "Randomness and the training loop").


def constant(value: float) -> Schedule:
    """A constant schedule.

    Args:
        value: The value of every episode.

    Returns:
        The schedule, a function of the 0-based episode.
    """
    return lambda episode: value


def exponential(start: float, decay: float, end: float) -> Schedule:
    """The exponential schedule ``max(end, start * decay ** float(e))``.

    Args:
        start: The value of episode 0.
        decay: The factor per episode.
        end: The floor.

    Returns:
        The schedule, a function of the 0-based episode.
    """
    return lambda episode: max(end, start * decay ** float(episode))


def log_schedule(k: float, end: float, start: float = 1.0) -> Schedule:
    """The log schedule ``max(end, min(start, 1 - log10((e + 1) / k)))``.

    Args:
        k: The episode scale.
        end: The floor.
        start: The ceiling (1 by default).

    Returns:
        The schedule, a function of the 0-based episode.
    """
    return lambda episode: max(end, min(start, 1 - math.log10((episode + 1) / k)))


def schedule(spec: float | Mapping[str, Any] | Schedule) -> Schedule:
    """A schedule from its config form (a number or a mapping with ``type``).

    Args:
        spec: A number, ``{type: constant, value}``, ``{type: exponential, start, decay,
            end}``, ``{type: log, k, end, start}``, or already a schedule.

    Returns:
        The schedule, a function of the 0-based episode.

    Raises:
        ValueError: An unknown schedule type.
    """
    if callable(spec):
        return spec
    if not isinstance(spec, Mapping):
        return constant(float(spec))
    kind = spec.get("type", "constant")
    if kind == "constant":
        return constant(float(spec["value"]))
    if kind == "exponential":
        return exponential(float(spec["start"]), float(spec["decay"]), float(spec["end"]))
    if kind == "log":
        return log_schedule(float(spec["k"]), float(spec["end"]), float(spec.get("start", 1.0)))
    raise ValueError(f"unknown schedule type {kind!r}")


# Observations to rows (design.md: the binning rule, "Discrete observations").


def make_indexer(
    space: spaces.Space[Any], discretization: Mapping[str, Sequence[float]] | None
) -> tuple[tuple[int, ...], Callable[[Any], Any]]:
    """The state shape of an observation space and the function giving an observation's row.

    Args:
        space: A 1-D ``Box``, a ``Discrete`` or a ``Tuple`` of ``Discrete``.
        discretization: ``bins``, ``low`` and ``high`` for a ``Box``; None otherwise.

    Returns:
        ``(state_shape, row)``: the table's shape without the action axis, and the C-order
        row of an observation.
    """
    if isinstance(space, spaces.Box):
        assert discretization is not None, "a Box observation needs a grid"
        bins = [int(b) for b in discretization["bins"]]
        lows = [float(v) for v in discretization["low"]]
        highs = [float(v) for v in discretization["high"]]

        def box_row(observation: Any) -> int:
            row = 0
            for d, x in enumerate(np.asarray(observation, dtype=np.float32).tolist()):
                # x: the float32 coordinate widened to a float64 (a Python float).
                # clip(floor(v), 0, bins - 1); a NaN falls in bin 0, bins = 1 is ignored.
                index = 0
                if bins[d] > 1:
                    v = (x - lows[d]) / (highs[d] - lows[d]) * bins[d]
                    if v >= bins[d]:
                        index = bins[d] - 1
                    elif v >= 0.0:
                        index = math.floor(v)
                row = row * bins[d] + index
            return row

        tilings = int(discretization.get("tilings", 1))  # type: ignore[call-overload]
        if tilings > 1:
            return tile_indexer(bins, lows, highs, tilings)
        return tuple(bins), box_row

    assert discretization is None, "Discrete and Tuple observations take no grid"
    tuple_obs = isinstance(space, spaces.Tuple)
    components: list[Any] = list(space.spaces) if isinstance(space, spaces.Tuple) else [space]
    assert all(isinstance(c, spaces.Discrete) for c in components)
    sizes = [int(c.n) for c in components]
    starts = [int(c.start) for c in components]

    def discrete_row(observation: Any) -> int:
        values = observation if tuple_obs else (observation,)
        row = 0
        for k, size in enumerate(sizes):
            row = row * size + (int(values[k]) - starts[k])
        return row

    return tuple(sizes), discrete_row


def tile_indexer(
    bins: list[int], lows: list[float], highs: list[float], tilings: int
) -> tuple[tuple[int, ...], Callable[[Any], Any]]:
    """docs/algorithms.md, "Tile coding": the weights' shape and an observation's tile rows.

    Tiling ``t`` shifts the grid by ``(t * (1 + 2k) mod T) / T`` of a bin in the ``k``-th
    dimension with more than one bin; each such dimension has ``bins + 1`` tiles; a tile's
    row is the C-order index of ``(t, coord_0, coord_1, ...)``.
    """
    sizes = [b + 1 if b > 1 else 1 for b in bins]

    def tile_rows(observation: Any) -> tuple[int, ...]:
        xs = np.asarray(observation, dtype=np.float32).tolist()
        rows = []
        for t in range(tilings):
            row, k = t, 0
            for d, x in enumerate(xs):
                if bins[d] == 1:
                    continue
                v = (x - lows[d]) / (highs[d] - lows[d]) * bins[d]
                if not v >= 0.0:
                    v = 0.0
                elif v > bins[d]:
                    v = float(bins[d])
                coord = (math.floor(v * tilings) + (t * (1 + 2 * k)) % tilings) // tilings
                row = row * (bins[d] + 1) + coord
                k += 1
            rows.append(row)
        return tuple(rows)

    return (tilings, *sizes), tile_rows


# CartPole physics (design.md, "CartPole physics").


def set_physics(env: gymnasium.Env[Any, Any], values: Mapping[str, Any]) -> None:
    """Set CartPole attributes on ``env.unwrapped``, then recompute the derived ones.

    Args:
        env: A CartPole made by ``gymnasium.make``.
        values: Attribute names and values.
    """
    cartpole = env.unwrapped
    for key, value in values.items():
        setattr(cartpole, key, value)
    cartpole.total_mass = cartpole.masspole + cartpole.masscart  # type: ignore[attr-defined]
    cartpole.polemass_length = cartpole.masspole * cartpole.length  # type: ignore[attr-defined]


# The agent: one table (two for Double Q), the agent's generator, the episode's rates.


class Agent:
    """The Q-table with design.md's and docs/algorithms.md's helpers.

    Attributes:
        q: The table, ``q[x][b]``.
        n: The number of actions.
        gamma: The discount.
        rng: The agent's generator (every draw of every algorithm).
        epsilon: The current episode's epsilon.
        alpha: The current episode's alpha.
        step_counts: ``agent.alpha: sample_average``'s update counts, ``step_counts[x][b]``
            (None under a schedule).
        params: The algorithm's extra keys (``n``, ``lambda``, ``trace``, ...).
    """

    def __init__(
        self,
        n_states: int,
        n: int,
        q_init: float,
        gamma: float,
        rng: np.random.Generator,
        params: Mapping[str, Any],
    ) -> None:
        self.q = [[q_init] * n for _ in range(n_states)]
        self.n = n
        self.gamma = gamma
        self.rng = rng
        self.epsilon = 0.0
        self.alpha = 0.0
        self.step_counts: list[list[float]] | None = None
        self.params = params

    # -- reading the table

    def value(self, x: Any, b: int, table: list[list[float]] | None = None) -> float:
        """``Q(x, b)``: the entry, or on tiles (``x`` a tuple of rows) the tiles' sum."""
        table = self.q if table is None else table
        if isinstance(x, tuple):
            total = 0.0
            for tile in x:
                total = total + table[tile][b]
            return total
        return table[x][b]

    def add(self, x: Any, b: int, amount: float, table: list[list[float]] | None = None) -> None:
        """``Q(x, b) = Q(x, b) + amount``; on tiles each tile by ``amount / T``."""
        table = self.q if table is None else table
        if isinstance(x, tuple):
            step = amount / len(x)
            for tile in x:
                table[tile][b] = table[tile][b] + step
        else:
            table[x][b] = table[x][b] + amount

    def row(self, x: Any) -> list[float]:
        """``[Q(x, 0), Q(x, 1), ...]``."""
        return [self.value(x, b) for b in range(self.n)]

    def policy_row(self, x: Any) -> list[float]:
        """The values epsilon-greedy chooses from (Double Q overrides it with A + B)."""
        return self.row(x)

    def greedy(self, x: Any) -> int:
        """The lowest action with the largest ``Q(x, b)``."""
        return argmax(self.row(x))

    def max(self, x: Any) -> float:
        """``Q(x, greedy(x))``."""
        return self.value(x, self.greedy(x))

    def expected(self, x: Any) -> float:
        """``E(x) = (1 - epsilon) * Q(x, g) + (epsilon / n) * S``."""
        row = self.row(x)
        g = argmax(row)
        total = row[0]
        for b in range(1, self.n):
            total = total + row[b]
        return (1 - self.epsilon) * row[g] + (self.epsilon / self.n) * total

    def pi(self, b: int, x: int) -> float:
        """Epsilon-greedy's probability of ``b`` in ``x``."""
        if b == self.greedy(x):
            return (1 - self.epsilon) + self.epsilon / self.n
        return self.epsilon / self.n

    def b(self, c: int, x: int) -> float:
        """``b(c | x)``: the probability with which ``draw(x)`` takes ``c``, ties as in force.

        ``lowest``: ``pi(c | x)``. ``random``: ``(1 - epsilon) / k + epsilon / n`` for each
        of the ``k`` tied best actions (``greedy(x)`` alone when none equals it), else
        ``epsilon / n``.
        """
        if self.params.get("tie_break", "lowest") != "random":
            return self.pi(c, x)
        row = self.policy_row(x)
        g = argmax(row)
        tied = [d for d in range(self.n) if row[d] == row[g]] or [g]
        if c in tied:
            return (1 - self.epsilon) / len(tied) + self.epsilon / self.n
        return self.epsilon / self.n

    # -- drawing and updating

    def draw(self, x: int) -> int:
        """design.md's epsilon-greedy action for ``x`` (ties as ``agent.tie_break`` says)."""
        if self.epsilon <= 0.0:
            return self.exploit(x)
        if self.epsilon >= 1.0:
            return int(self.rng.integers(0, self.n))
        if self.rng.random() < self.epsilon:
            return int(self.rng.integers(0, self.n))
        return self.exploit(x)

    def start(self, x: int) -> int:
        """An episode's first action: ``draw(x)`` (design.md), unless the algorithm says else."""
        return self.draw(x)

    def exploit(self, x: int) -> int:
        """The greedy branch: the lowest best action, or with ``tie_break: random`` one of the
        ``k`` tied best, the ``rng.integers(0, k)``-th in action order (no draw when k = 1)."""
        row = self.policy_row(x)
        lowest = argmax(row)
        if self.params.get("tie_break", "lowest") == "random":
            tied = [b for b in range(self.n) if row[b] == row[lowest]]
            if len(tied) > 1:
                return tied[int(self.rng.integers(0, len(tied)))]
        return lowest

    def update(self, x: int, b: int, y: float) -> None:
        """``Q(x, b) = Q(x, b) + alpha * (y - Q(x, b))`` (on tiles: ``add``'s split).

        docs/algorithms.md, "Sample averages": under ``agent.alpha: sample_average``,
        ``N(x, b) = N(x, b) + 1.0`` then ``Q(x, b) = Q(x, b) + (y - Q(x, b)) / N(x, b)``.
        """
        if self.step_counts is not None:
            self.step_counts[x][b] = self.step_counts[x][b] + 1.0
            self.add(x, b, (y - self.value(x, b)) / self.step_counts[x][b])
            return
        self.add(x, b, self.alpha * (y - self.value(x, b)))

    # -- what the algorithms override

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        """One step's work after ``visits[s, a] += 1``.

        Args:
            s: The step's state.
            a: The step's action.
            r: Its reward.
            s2: The next state.
            terminated: Whether the step terminated (also when it truncated too).
            truncated: Whether the step only truncated.

        Returns:
            The next action, or None when the episode ends.
        """
        raise NotImplementedError

    def kept_table(self) -> list[list[float]]:
        """The table ``q_table.npy`` holds."""
        return self.q


def argmax(row: Sequence[float]) -> int:
    """The lowest index among the largest values."""
    best = 0
    for b in range(1, len(row)):
        if row[b] > row[best]:
            best = b
    return best


# design.md's four one-step algorithms.


class QLearning(Agent):
    """``q_learning``: update, then draw the next action from the updated table."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        y = r if terminated else r + self.gamma * self.max(s2)
        self.update(s, a, y)
        if terminated or truncated:
            return None
        return self.draw(s2)


class Sarsa(Agent):
    """``sarsa``: draw ``a'`` from the table as it is (not when terminated), then update."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        if terminated:
            self.update(s, a, r)
            return None
        a2 = self.draw(s2)
        self.update(s, a, r + self.gamma * self.value(s2, a2))
        return None if truncated else a2


class ExpectedSarsa(Agent):
    """``expected_sarsa``: update toward ``r + gamma * E(s')``, then draw."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        y = r if terminated else r + self.gamma * self.expected(s2)
        self.update(s, a, y)
        if terminated or truncated:
            return None
        return self.draw(s2)


class DoubleQLearning(Agent):
    """``double_q_learning``: ``u = rng.random()`` picks the table to update; acts on A + B."""

    def __init__(self, n_states: int, n: int, q_init: float, *args: Any) -> None:
        super().__init__(n_states, n, q_init, *args)
        self.q_b = [[q_init] * n for _ in range(n_states)]
        self.counts_b: list[list[float]] | None = None

    def policy_row(self, x: Any) -> list[float]:
        return [self.value(x, b) + self.value(x, b, self.q_b) for b in range(self.n)]

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        u = self.rng.random()
        first, second = (self.q, self.q_b) if u < 0.5 else (self.q_b, self.q)
        best = argmax([self.value(s2, b, first) for b in range(self.n)])
        y = r if terminated else r + self.gamma * self.value(s2, best, second)
        if self.step_counts is not None:  # "Sample averages": each table by its own counts
            if self.counts_b is None:
                self.counts_b = [[0.0] * self.n for _ in self.q]
            counts = self.step_counts if u < 0.5 else self.counts_b
            counts[s][a] = counts[s][a] + 1.0
            self.add(s, a, (y - self.value(s, a, first)) / counts[s][a], first)
        else:
            self.add(s, a, self.alpha * (y - self.value(s, a, first)), first)
        if terminated or truncated:
            return None
        return self.draw(s2)

    def kept_table(self) -> list[list[float]]:
        return [
            [0.5 * (self.q[x][b] + self.q_b[x][b]) for b in range(self.n)]
            for x in range(len(self.q))
        ]


# docs/algorithms.md: n-step methods.


class NStepSarsa(Agent):
    """``n_step_sarsa``: a queue of pending ``(S, A, R)``, settled ``n`` rewards late."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.pending: deque[tuple[int, int, float]] = deque()

    def settle(self, bootstrap: bool, s2: int, a2: int | None) -> None:
        """Update the oldest pending step toward its n-step return, and remove it."""
        k = len(self.pending)
        rewards = [step[2] for step in self.pending]
        g = rewards[0]
        for i in range(1, k):
            g = g + self.gamma ** float(i) * rewards[i]
        if bootstrap:
            assert a2 is not None
            g = g + self.gamma ** float(k) * self.value(s2, a2)
        x, b, _ = self.pending.popleft()
        self.update(x, b, g)

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.pending.append((s, a, r))
        a2 = None if terminated else self.draw(s2)
        if terminated or truncated:
            while self.pending:
                self.settle(not terminated, s2, a2)
            return None
        if len(self.pending) == int(self.params["n"]):
            self.settle(True, s2, a2)
        return a2


class NStepTreeBackup(Agent):
    """``n_step_tree_backup``: the tree backup under the epsilon-greedy target policy."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.pending: deque[tuple[int, int, float]] = deque()

    def settle(self, terminated: bool, s2: int) -> None:
        """Update the oldest pending step toward its tree-backup return, and remove it."""
        steps = list(self.pending)
        k = len(steps)
        g = steps[k - 1][2] if terminated else steps[k - 1][2] + self.gamma * self.expected(s2)
        for m in range(k - 2, -1, -1):
            x, b, _ = steps[m + 1]
            others = 0.0
            for c in range(self.n):
                if c != b:
                    others = others + self.pi(c, x) * self.value(x, c)
            g = steps[m][2] + self.gamma * (others + self.pi(b, x) * g)
        x, b, _ = self.pending.popleft()
        self.update(x, b, g)

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.pending.append((s, a, r))
        if terminated or truncated:
            while self.pending:
                self.settle(terminated, s2)
            return None
        if len(self.pending) == int(self.params["n"]):
            self.settle(False, s2)
        return self.draw(s2)


# docs/algorithms.md: eligibility traces.


class TraceAgent(Agent):
    """Sparse traces: a dict from flat index to ``z``, in the order pairs got a trace."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.traces: dict[int, float] = {}
        self.lam = float(self.params["lambda"])
        self.tilings = int(self.params.get("tilings", 1))

    def give_trace(self, s: Any, a: int) -> None:
        """Give ``(s, a)`` a trace (appended at 0.0 if it has none), by ``agent.trace``.

        On tiles each of ``s``'s tiles gets its trace; dutch is the book's eq. 12.11 over the
        ``T`` binary features: ``S`` = the tiles' traces summed, then each tile
        ``z = z + (1.0 - (alpha / T) * S)``.
        """
        kind = self.params["trace"]
        if isinstance(s, tuple) and kind == "dutch":
            total = 0.0
            for row in s:
                total = total + self.traces.get(row * self.n + a, 0.0)
            amount = 1.0 - (self.alpha / len(s)) * total
            for row in s:
                flat = row * self.n + a
                self.traces[flat] = self.traces.get(flat, 0.0) + amount
            return
        alpha = self.alpha
        if self.step_counts is not None:  # "Sample averages": the visit counts, 1 / N for dutch
            self.step_counts[s][a] = self.step_counts[s][a] + 1.0
            alpha = 1.0 / self.step_counts[s][a]
        for row in s if isinstance(s, tuple) else (s,):
            flat = row * self.n + a
            if flat not in self.traces:
                self.traces[flat] = 0.0
            z = self.traces[flat]
            if kind == "accumulating":
                z = z + 1.0
            elif kind == "replacing":
                z = 1.0
            elif kind == "dutch":
                z = (1.0 - alpha) * z + 1.0
            elif kind == "clearing":
                z = 1.0
            else:
                raise ValueError(f"unknown trace {kind!r}")
            self.traces[flat] = z
            if kind == "clearing":  # the row's other actions that have a trace: 0.0, kept
                for b in range(self.n):
                    other = row * self.n + b
                    if b != a and other in self.traces:
                        self.traces[other] = 0.0

    def decay(self) -> None:
        """``z = (gamma * lambda) * z`` for every trace; traces now exactly 0.0 are dropped."""
        for flat in list(self.traces):
            z = (self.gamma * self.lam) * self.traces[flat]
            if z == 0.0:
                del self.traces[flat]
            else:
                self.traces[flat] = z

    def apply(self, delta: float) -> None:
        """``Q[x] = Q[x] + alpha * delta * z`` for every trace, in list order.

        On tiles a traced tile ``w = w + ((alpha * delta) / T) * z``. Under sample
        averages each entry ``Q[x] = Q[x] + (delta / N[x]) * z``.
        """
        if self.step_counts is not None:
            for flat, z in self.traces.items():
                x, b = divmod(flat, self.n)
                self.q[x][b] = self.q[x][b] + (delta / self.step_counts[x][b]) * z
            return
        self.apply_scaled(self.alpha * delta)

    def apply_scaled(self, scale: float) -> None:
        """``Q[x] = Q[x] + scale * z`` (on tiles ``(scale / T) * z``) for every trace."""
        if self.tilings > 1:
            scale = scale / self.tilings
        for flat, z in self.traces.items():
            x, b = divmod(flat, self.n)
            self.q[x][b] = self.q[x][b] + scale * z


class SarsaLambda(TraceAgent):
    """``sarsa_lambda``: SARSA's delta applied along the traces."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        a2 = None
        if terminated:
            y = r
        else:
            a2 = self.draw(s2)
            y = r + self.gamma * self.value(s2, a2)
        delta = y - self.value(s, a)
        self.give_trace(s, a)
        self.apply(delta)
        if terminated or truncated:
            self.traces.clear()
            return None
        self.decay()
        return a2


class WatkinsQLambda(TraceAgent):
    """``watkins_q_lambda``: Q-learning's delta along traces cut by exploratory actions."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        y = r if terminated else r + self.gamma * self.max(s2)
        delta = y - self.value(s, a)
        self.give_trace(s, a)
        self.apply(delta)
        if terminated or truncated:
            self.traces.clear()
            return None
        a2 = self.draw(s2)
        if self.value(s2, a2) == self.max(s2):
            self.decay()
        else:
            self.traces.clear()
        return a2


class TrueOnlineSarsaLambda(TraceAgent):
    """``true_online_sarsa_lambda``: dutch traces with the ``q_old`` correction."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.q_old = 0.0

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        a2 = None if terminated else self.draw(s2)
        q_sa = self.value(s, a)
        q_next = 0.0 if a2 is None else self.value(s2, a2)
        delta = r + self.gamma * q_next - q_sa
        # On tiles x(s, a) has a 1 at each of s's tiles, and a tile's step size is alpha / T.
        rows = s if isinstance(s, tuple) else (s,)
        tile_alpha = self.alpha / len(rows) if isinstance(s, tuple) else self.alpha
        z_sa = 0.0 if isinstance(s, tuple) else self.traces.get(s * self.n + a, 0.0)
        if isinstance(s, tuple):
            for row in rows:
                z_sa = z_sa + self.traces.get(row * self.n + a, 0.0)
        self.decay()
        for row in rows:
            flat = row * self.n + a
            if flat not in self.traces:
                self.traces[flat] = 0.0
            self.traces[flat] = self.traces[flat] + (
                1.0 - tile_alpha * self.gamma * self.lam * z_sa
            )
        self.apply_scaled(self.alpha * (delta + q_sa - self.q_old))
        self.add(s, a, -(self.alpha * (q_sa - self.q_old)))
        self.q_old = q_next
        if terminated or truncated:
            self.traces.clear()
            self.q_old = 0.0
            return None
        return a2


# docs/algorithms.md: planning.


class DynaQ(Agent):
    """``dyna_q`` (and, with ``plus``, ``dyna_q_plus``): Q-learning plus model replays."""

    plus = False

    def __init__(self, n_states: int, n: int, *args: Any) -> None:
        super().__init__(n_states, n, *args)
        self.model_next = [-1] * (n_states * n)
        self.model_reward = [0.0] * (n_states * n)
        self.model_terminated = [False] * (n_states * n)
        self.seen: list[int] = []
        self.seen_flag = [False] * n_states
        self.actions_of: list[list[int]] = [[] for _ in range(n_states)]
        self.time = 0
        self.last_tried = [0] * (n_states * n)

    def model(self, x: int, b: int) -> tuple[int, float, bool]:
        """The remembered ``(x', reward, terminated)``; untried: back to ``x``, 0.0, False."""
        flat = x * self.n + b
        if self.model_next[flat] == -1:
            return x, 0.0, False
        return self.model_next[flat], self.model_reward[flat], self.model_terminated[flat]

    def plan(self) -> None:
        """One planning update."""
        x = self.seen[int(self.rng.integers(0, len(self.seen)))]
        if self.plus:
            b = int(self.rng.integers(0, self.n))
        else:
            b = self.actions_of[x][int(self.rng.integers(0, len(self.actions_of[x])))]
        x2, rho, t = self.model(x, b)
        if self.plus:
            tau = float(self.time - self.last_tried[x * self.n + b])
            bonus = rho + float(self.params["kappa"]) * math.sqrt(tau)
            y = bonus if t else bonus + self.gamma * self.max(x2)
        else:
            y = rho if t else rho + self.gamma * self.max(x2)
        self.update(x, b, y)

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        flat = s * self.n + a
        if self.plus:
            self.time = self.time + 1
            self.last_tried[flat] = self.time
        y = r if terminated else r + self.gamma * self.max(s2)
        self.update(s, a, y)
        if not self.seen_flag[s]:
            self.seen_flag[s] = True
            self.seen.append(s)
        if self.model_next[flat] == -1:
            self.actions_of[s].append(a)
        self.model_next[flat] = s2
        self.model_reward[flat] = r
        self.model_terminated[flat] = terminated
        for _ in range(int(self.params["planning_steps"])):
            self.plan()
        if terminated or truncated:
            return None
        return self.draw(s2)


class DynaQPlus(DynaQ):
    """``dyna_q_plus``: any action replayed, with the bonus ``kappa * sqrt(tau)``."""

    plus = True


class PrioritizedSweeping(Agent):
    """``prioritized_sweeping``: no direct update; planning from a queue by priority."""

    def __init__(self, n_states: int, n: int, *args: Any) -> None:
        super().__init__(n_states, n, *args)
        self.model_next = [-1] * (n_states * n)
        self.model_reward = [0.0] * (n_states * n)
        self.model_terminated = [False] * (n_states * n)
        self.priority: dict[int, float] = {}  # queued pairs (flat index) -> priority

    def enqueue(self, flat: int, p: float) -> None:
        theta = float(self.params["theta"])
        if p > theta and p > self.priority.get(flat, -1.0):
            self.priority[flat] = p

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        flat = s * self.n + a
        self.model_next[flat] = s2
        self.model_reward[flat] = r
        self.model_terminated[flat] = terminated
        y = r if terminated else r + self.gamma * self.max(s2)
        self.enqueue(flat, abs(y - self.value(s, a)))
        for _ in range(int(self.params["planning_steps"])):
            if not self.priority:
                break
            top = max(self.priority.values())
            pair = min(f for f, p in self.priority.items() if p == top)
            del self.priority[pair]
            x, b = divmod(pair, self.n)
            rho = self.model_reward[pair]
            y = (
                rho
                if self.model_terminated[pair]
                else rho + self.gamma * self.max(self.model_next[pair])
            )
            self.update(x, b, y)
            best = self.max(x)
            for before in range(len(self.model_next)):
                if self.model_next[before] == x and not self.model_terminated[before]:
                    lead = self.model_reward[before] + self.gamma * best
                    self.enqueue(before, abs(lead - self.value(*divmod(before, self.n))))
        if terminated or truncated:
            return None
        return self.draw(s2)


# docs/algorithms.md: Monte Carlo.


class MonteCarlo(Agent):
    """``monte_carlo`` (first visit, epsilon-soft) and, with ``off_policy``, its off-policy twin."""

    off_policy = False

    def __init__(self, n_states: int, n: int, *args: Any) -> None:
        super().__init__(n_states, n, *args)
        self.buffer_length = NO_TIME_LIMIT_LENGTH
        self.states: list[int] = []
        self.actions: list[int] = []
        self.rewards: list[float] = []
        self.behaviour: list[float] = []
        self.first_visit: dict[int, int] = {}
        self.counts = [0.0] * (n_states * n)  # N (on-policy) or C (off-policy)

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        t = len(self.states)
        if self.off_policy:
            self.behaviour.append(self.b(a, s))
        elif s * self.n + a not in self.first_visit:
            self.first_visit[s * self.n + a] = t
        self.states.append(s)
        self.actions.append(a)
        self.rewards.append(r)
        if not terminated and not truncated and len(self.states) < self.buffer_length:
            return self.draw(s2)
        if self.off_policy:
            self.backward_off_policy(terminated, s2)
        else:
            self.backward_on_policy(terminated, s2)
        self.states, self.actions, self.rewards, self.behaviour = [], [], [], []
        self.first_visit = {}
        return None

    def backward_on_policy(self, terminated: bool, s2: int) -> None:
        """First-visit returns, by sample average or constant alpha."""
        g = 0.0 if terminated else self.expected(s2)
        for t in range(len(self.states) - 1, -1, -1):
            g = self.gamma * g + self.rewards[t]
            x, b = self.states[t], self.actions[t]
            flat = x * self.n + b
            if self.first_visit[flat] == t:
                if self.params["update"] == "sample_average":
                    self.counts[flat] = self.counts[flat] + 1.0
                    self.q[x][b] = self.q[x][b] + (g - self.q[x][b]) / self.counts[flat]
                else:
                    self.update(x, b, g)

    def backward_off_policy(self, terminated: bool, s2: int) -> None:
        """Weighted importance sampling toward the greedy policy."""
        g = 0.0 if terminated else self.max(s2)
        w = 1.0
        for t in range(len(self.states) - 1, -1, -1):
            g = self.gamma * g + self.rewards[t]
            x, b = self.states[t], self.actions[t]
            flat = x * self.n + b
            if self.params["update"] == "sample_average":
                self.counts[flat] = self.counts[flat] + w
            else:
                self.counts[flat] = (1.0 - self.alpha) * self.counts[flat] + w
            self.q[x][b] = self.q[x][b] + (w / self.counts[flat]) * (g - self.q[x][b])
            if b != self.greedy(x):
                break
            w = w / self.behaviour[t]


class MonteCarloES(MonteCarlo):
    """``monte_carlo_es``: ``monte_carlo`` whose first action is one ``rng.integers(0, n)``."""

    def start(self, x: int) -> int:
        return int(self.rng.integers(0, self.n))


class OffPolicyMonteCarlo(MonteCarlo):
    """``off_policy_monte_carlo``: behaviour epsilon-greedy, target greedy."""

    off_policy = True


# docs/algorithms.md: prediction. V is a table of one column; pi chooses every action.


class Prediction(Agent):
    """A prediction algorithm: ``V`` as ``q[x][0]``, actions drawn by the uniform ``pi``."""

    def __init__(self, n_states: int, n: int, q_init: float, *args: Any) -> None:
        super().__init__(n_states, n, q_init, *args)
        self.q = [[q_init] for _ in range(n_states)]
        self.greedy: list[int] = []
        if self.params["policy"] in ("greedy", "epsilon_greedy"):
            # agent.policy_run's q_table.npy, its rows in C order: the lowest best action.
            table = np.load(Path(self.params["policy_run"]) / "q_table.npy").reshape(-1, n)
            for values in table.tolist():
                self.greedy.append(values.index(max(values)))

    def pi_of(self, b: int, x: int) -> float:
        """``pi(b | x)``: ``1 / n``; a rule's or the greedy policy's 1.0 or 0.0; epsilon-greedy's
        ``(1 - epsilon) + epsilon / n`` for the greedy action, ``epsilon / n`` for another."""
        policy = self.params["policy"]
        if policy == "random":
            return 1.0 / self.n
        if policy == "epsilon_greedy":
            epsilon = float(self.params["policy_epsilon"])
            return (1.0 - epsilon) + epsilon / self.n if b == self.greedy[x] else epsilon / self.n
        return 1.0 if b == self.rule(x) else 0.0

    def rule(self, x: int) -> int:
        """A deterministic policy's action: ``stick_20`` (Blackjack, rows in C order over (32,
        11, 2)): stick (0) on a player sum of 20 or 21, else hit (1); ``left``: 0; ``greedy``:
        the run's."""
        if self.params["policy"] == "stick_20":
            return 0 if x // (11 * 2) >= 20 else 1
        if self.params["policy"] == "left":
            return 0
        return self.greedy[x]

    def draw(self, x: int) -> int:
        """``pi``'s action: ``random``, one ``rng.integers(0, n)``; ``epsilon_greedy``, one
        ``u = rng.random()`` and the lowest action whose running sum of ``pi`` passes it; a
        rule or ``greedy``, its action, no draw."""
        policy = self.params["policy"]
        if policy == "random":
            return int(self.rng.integers(0, self.n))
        if policy == "epsilon_greedy":
            u = self.rng.random()
            total, last = 0.0, 0
            for b in range(self.n):
                total = total + self.pi_of(b, x)
                if u < total:
                    return b
                if self.pi_of(b, x) > 0.0:
                    last = b
            return last
        return self.rule(x)

    def v(self, x: Any) -> float:
        """``V(x)``: ``x``'s entry, or on tiles its tiles' weights summed (``value``)."""
        return self.value(x, 0)


class TD(Prediction):
    """``td``: TD(0)."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        y = r if terminated else r + self.gamma * self.v(s2)
        self.update(s, 0, y)
        if terminated or truncated:
            return None
        return self.draw(s2)


class NStepTD(Prediction):
    """``n_step_td``: n-step returns of V, settled as n_step_sarsa settles Q."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.pending: deque[tuple[int, float]] = deque()

    def settle(self, bootstrap: bool, s2: int) -> None:
        k = len(self.pending)
        g = self.pending[0][1]
        for i in range(1, k):
            g = g + self.gamma ** float(i) * self.pending[i][1]
        if bootstrap:
            g = g + self.gamma ** float(k) * self.v(s2)
        self.update(self.pending[0][0], 0, g)
        self.pending.popleft()

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.pending.append((s, r))
        if terminated or truncated:
            while self.pending:
                self.settle(not terminated, s2)
            return None
        if len(self.pending) == int(self.params["n"]):
            self.settle(True, s2)
        return self.draw(s2)


class MCPrediction(Prediction):
    """``mc_prediction``: constant-alpha or sample-average, every- or first-visit returns."""

    def __init__(self, n_states: int, *args: Any) -> None:
        super().__init__(n_states, *args)
        self.buffer_length = NO_TIME_LIMIT_LENGTH
        self.episode: list[tuple[int, float]] = []
        self.counts = [0.0] * n_states

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.episode.append((s, r))
        if not terminated and not truncated and len(self.episode) < self.buffer_length:
            return self.draw(s2)
        first: dict[int, int] = {}
        for t, (x, _) in enumerate(self.episode):
            first.setdefault(x, t)
        g = 0.0 if terminated else self.v(s2)
        for t in range(len(self.episode) - 1, -1, -1):
            x, reward = self.episode[t]
            g = self.gamma * g + reward
            if self.params["visits"] == "every" or first[x] == t:
                if self.params["update"] == "sample_average":
                    self.counts[x] = self.counts[x] + 1.0
                    self.q[x][0] = self.q[x][0] + (g - self.q[x][0]) / self.counts[x]
                else:
                    self.update(x, 0, g)
        self.episode = []
        return None


class TDLambda(Prediction, TraceAgent):
    """``td_lambda``: TD(0)'s error along SARSA(lambda)'s traces, with the action 0."""

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        y = r if terminated else r + self.gamma * self.v(s2)
        delta = y - self.v(s)
        self.give_trace(s, 0)
        self.apply(delta)
        if terminated or truncated:
            self.traces.clear()
            return None
        self.decay()
        return self.draw(s2)


class TrueOnlineTDLambda(Prediction, TraceAgent):
    """``true_online_td_lambda``: true online SARSA(lambda) with V."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.v_old = 0.0

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        v_next = 0.0 if terminated else self.v(s2)
        v_s = self.v(s)
        delta = r + self.gamma * v_next - v_s
        # The pairs (s, 0) as the traces key them; on tiles (docs/algorithms.md, "Tile
        # coding", true online) each of s's tiles, with a tile's step size alpha / T.
        rows = s if isinstance(s, tuple) else (s,)
        tile_alpha = self.alpha / len(rows) if isinstance(s, tuple) else self.alpha
        z_s = 0.0 if isinstance(s, tuple) else self.traces.get(s * self.n, 0.0)
        if isinstance(s, tuple):
            for row in rows:
                z_s = z_s + self.traces.get(row * self.n, 0.0)
        self.decay()
        for row in rows:
            flat = row * self.n
            if flat not in self.traces:
                self.traces[flat] = 0.0
            self.traces[flat] = self.traces[flat] + (1.0 - tile_alpha * self.gamma * self.lam * z_s)
        self.apply_scaled(self.alpha * (delta + v_s - self.v_old))
        self.add(s, 0, -(self.alpha * (v_s - self.v_old)))
        self.v_old = v_next
        if terminated or truncated:
            self.traces.clear()
            self.v_old = 0.0
            return None
        return self.draw(s2)


class BatchPrediction(Prediction):
    """``batch_prediction``: every transition kept as ``(s, g, w, b)``, ``y = g + w * V(b)``;
    after each episode, passes over all of them until a pass moves V by less than the
    tolerance in total (or is not finite), or max_passes passes."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.batch: list[list[Any]] = []  # [s, g, w, b] per transition, in order
        self.buffer_length = NO_TIME_LIMIT_LENGTH
        self.episode_start = 0

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.batch.append([s, r, 0.0 if terminated else self.gamma, s2])
        cut = len(self.batch) - self.episode_start == self.buffer_length
        if not terminated and not truncated and not cut:
            return self.draw(s2)
        if self.params["target"] == "mc":
            g, w = 0.0, 0.0 if terminated else 1.0
            for i in range(len(self.batch) - 1, self.episode_start - 1, -1):
                g = self.gamma * g + self.batch[i][1]
                w = self.gamma * w
                self.batch[i][1:] = [g, w, s2]
        self.episode_start = len(self.batch)
        for _ in range(int(self.params["max_passes"])):
            sums = [0.0] * len(self.q)
            for x, g, w, b in self.batch:
                sums[x] = sums[x] + (g + w * self.v(b) - self.v(x))
            moved = 0.0
            for x in range(len(self.q)):
                moved += abs(self.alpha * sums[x])
            if moved < float(self.params["tolerance"]) or not math.isfinite(moved):
                break
            for x in range(len(self.q)):
                self.q[x][0] = self.q[x][0] + self.alpha * sums[x]
        return None


class OfflineLambdaReturn(Prediction):
    """``offline_lambda_return``: every step's lambda-return from V as the episode ended,
    computed backwards, then the updates in step order."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.buffer_length = NO_TIME_LIMIT_LENGTH
        self.episode: list[tuple[int, float]] = []

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.episode.append((s, r))
        if not terminated and not truncated and len(self.episode) < self.buffer_length:
            return self.draw(s2)
        lam = float(self.params["lambda"])
        returns = [0.0] * len(self.episode)
        g = self.episode[-1][1] + self.gamma * (0.0 if terminated else self.v(s2))
        returns[-1] = g
        for t in range(len(self.episode) - 2, -1, -1):
            later = self.v(self.episode[t + 1][0])
            g = self.episode[t][1] + self.gamma * ((1.0 - lam) * later + lam * g)
            returns[t] = g
        for (x, _), g in zip(self.episode, returns, strict=True):
            self.update(x, 0, g)
        self.episode = []
        return None


class OffPolicyMCPrediction(Prediction):
    """``off_policy_mc_prediction``: a uniform behaviour draws every action; returns weighted
    backwards by pi / b over the steps after each visit, ordinary or weighted sampling."""

    def __init__(self, n_states: int, *args: Any) -> None:
        super().__init__(n_states, *args)
        self.buffer_length = NO_TIME_LIMIT_LENGTH
        self.episode: list[tuple[int, int, float]] = []
        self.sums = [0.0] * n_states

    def draw(self, x: int) -> int:
        return int(self.rng.integers(0, self.n))  # b: uniform, whatever the target

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        self.episode.append((s, a, r))
        if not terminated and not truncated and len(self.episode) < self.buffer_length:
            return self.draw(s2)
        first: dict[int, int] = {}
        for t, (x, _, _) in enumerate(self.episode):
            first.setdefault(x, t)
        g = 0.0 if terminated else self.v(s2)
        w = 1.0
        for t in range(len(self.episode) - 1, -1, -1):
            x, b, reward = self.episode[t]
            g = self.gamma * g + reward
            w = w * (self.pi_of(b, x) / (1.0 / self.n))
            if self.params["visits"] == "every" or first[x] == t:
                if self.params["sampling"] == "ordinary":
                    self.sums[x] = self.sums[x] + 1.0
                    self.q[x][0] = self.q[x][0] + (w * g - self.q[x][0]) / self.sums[x]
                else:
                    self.sums[x] = self.sums[x] + w
                    if self.sums[x] > 0.0:
                        self.q[x][0] = self.q[x][0] + (w / self.sums[x]) * (g - self.q[x][0])
        self.episode = []
        return None


def true_values(
    env: gymnasium.Env[Any, Any],
    n: int,
    gamma: float,
    pi: Callable[[int, int], float] | None = None,
    tile_rows: Callable[[Any], Any] | None = None,
) -> tuple[list[Any], list[float]]:
    """docs/algorithms.md, "The error": the policy's values on the measured states.

    ``pi(b, x)`` is the policy's probability of ``b`` in ``x`` (uniform if None); a world
    observed as points (``point_of_state``, on tiles) measures each state on the tiles
    ``tile_rows`` gives its point.

    ``(I - gamma * P_pi) v = r_pi`` from the world's table ``P``, solved by numpy; measured
    are the states reachable from the start distribution along outcomes that do not
    terminate, but the terminal ones (every outcome stays in the state, pays 0, terminates).

    Returns:
        The row each measured state is observed as (the state itself, or, where the world
        aggregates states, ``observation_of_state[x]``: several states share a row), in
        state order, and each state's value.
    """
    table = env.unwrapped.P  # type: ignore[attr-defined]
    states = len(table)
    matrix = np.zeros((states, states))
    expected = np.zeros(states)
    terminal = []
    following: dict[int, set[int]] = {x: set() for x in range(states)}
    for x in range(states):
        ends = True
        for b in range(n):
            for probability, to, reward, done in table[x][b]:
                weight = (1.0 / n if pi is None else pi(b, x)) * probability
                expected[x] += weight * reward
                if not done:
                    matrix[x, to] += weight
                    if weight > 0.0:
                        following[x].add(to)
                ends = ends and done and reward == 0.0 and to == x
        terminal.append(ends)
    start = env.unwrapped.initial_state_distrib  # type: ignore[attr-defined]
    reached = {x for x in range(states) if start[x] > 0.0}
    frontier = list(reached)
    while frontier:
        for to in following[frontier.pop()]:
            if to not in reached:
                reached.add(to)
                frontier.append(to)
    order = sorted(reached)  # the system restricted to the reachable states, in order
    system = np.eye(len(order)) - gamma * matrix[np.ix_(order, order)]
    values = dict(zip(order, np.linalg.solve(system, expected[order]), strict=True))
    measured = [x for x in order if not terminal[x]]
    observed = getattr(env.unwrapped, "observation_of_state", None)
    points = getattr(env.unwrapped, "point_of_state", None)
    if points is not None:  # a world observed as points, on tiles: each state's tiles
        assert tile_rows is not None
        return [tile_rows(points[x]) for x in measured], [float(values[x]) for x in measured]
    rows = [x if observed is None else int(observed[x]) for x in measured]
    return rows, [float(values[x]) for x in measured]


def rms_error(agent: Prediction, measured: list[Any], truth: list[float]) -> float:
    """``math.sqrt(S / k)``, ``S`` the squared differences summed in state order from 0.0.

    ``measured`` holds each measured state's row (a row once per state observed as it).
    """
    total = 0.0
    for x, value in zip(measured, truth, strict=True):
        difference = agent.v(x) - value
        total = total + difference * difference
    return math.sqrt(total / len(measured))


class ActorCritic(Agent):
    """``actor_critic``: a softmax actor on the table's preferences, a critic ``v``, traces.

    docs/algorithms.md, ``actor_critic``: dicts of traces (the critic's by state, the actor's
    by flat index), each decayed by ``(gamma * lambda)`` after its update.
    """

    def __init__(self, n_states: int, n: int, *args: Any) -> None:
        super().__init__(n_states, n, *args)
        self.v = [float(self.params["v_init"])] * n_states
        self.discount = 1.0
        self.z_w: dict[int, float] = {}
        self.z_theta: dict[int, float] = {}

    def policy(self, x: int) -> list[float]:
        """``π(· | x)``: the softmax of the preferences, from the largest."""
        row = self.q[x]
        largest = row[0]
        for b in range(1, self.n):
            if row[b] > largest:
                largest = row[b]
        e = [math.exp(row[b] - largest) for b in range(self.n)]
        total = 0.0
        for b in range(self.n):
            total = total + e[b]
        return [e[b] / total for b in range(self.n)]

    def draw(self, x: int) -> int:
        """One ``rng.random()``: the lowest action whose running sum exceeds it."""
        pi = self.policy(x)
        u = self.rng.random()
        running = 0.0
        for b in range(self.n):
            running = running + pi[b]
            if u < running:
                return b
        return max(b for b in range(self.n) if pi[b] > 0.0)

    def start(self, x: int) -> int:
        self.discount = 1.0
        return self.draw(x)

    def step(
        self, s: int, a: int, r: float, s2: int, terminated: bool, truncated: bool
    ) -> int | None:
        later = 0.0 if terminated else self.v[s2]
        delta = (r + self.gamma * later) - self.v[s]
        self.z_w[s] = self.z_w.get(s, 0.0) + 1.0
        pi = self.policy(s)
        for b in range(self.n):
            g = (1.0 if b == a else 0.0) - pi[b]
            flat = s * self.n + b
            self.z_theta[flat] = self.z_theta.get(flat, 0.0) + self.discount * g
        alpha_w = float(self.params["alpha_w"])
        for x, z in self.z_w.items():
            self.v[x] = self.v[x] + (alpha_w * delta) * z
        for flat, z in self.z_theta.items():
            x, b = divmod(flat, self.n)
            self.q[x][b] = self.q[x][b] + (self.alpha * delta) * z
        if terminated or truncated:
            self.z_w.clear()
            self.z_theta.clear()
            return None
        decay_w = self.gamma * float(self.params["lambda_w"])
        decay_theta = self.gamma * float(self.params["lambda_theta"])
        self.z_w = {x: decay_w * z for x, z in self.z_w.items()}
        self.z_theta = {flat: decay_theta * z for flat, z in self.z_theta.items()}
        self.discount = self.gamma * self.discount
        return self.draw(s2)


ALGORITHMS: dict[str, type[Agent]] = {
    "q_learning": QLearning,
    "sarsa": Sarsa,
    "expected_sarsa": ExpectedSarsa,
    "double_q_learning": DoubleQLearning,
    "n_step_sarsa": NStepSarsa,
    "n_step_tree_backup": NStepTreeBackup,
    "sarsa_lambda": SarsaLambda,
    "watkins_q_lambda": WatkinsQLambda,
    "true_online_sarsa_lambda": TrueOnlineSarsaLambda,
    "dyna_q": DynaQ,
    "dyna_q_plus": DynaQPlus,
    "prioritized_sweeping": PrioritizedSweeping,
    "monte_carlo": MonteCarlo,
    "monte_carlo_es": MonteCarloES,
    "off_policy_monte_carlo": OffPolicyMonteCarlo,
    "actor_critic": ActorCritic,
    "td": TD,
    "n_step_td": NStepTD,
    "mc_prediction": MCPrediction,
    "batch_prediction": BatchPrediction,
    "offline_lambda_return": OfflineLambdaReturn,
    "off_policy_mc_prediction": OffPolicyMCPrediction,
    "td_lambda": TDLambda,
    "true_online_td_lambda": TrueOnlineTDLambda,
}

# docs/algorithms.md, "Config keys the algorithms add": the defaults.
PARAMETER_DEFAULTS: dict[str, Any] = {
    "n": 4,
    "lambda": 0.9,
    "trace": "replacing",
    "planning_steps": 10,
    "kappa": 0.001,
    "theta": 0.0001,
    "update": "sample_average",
    "tie_break": "lowest",  # agent.tie_break, a key of every algorithm
    "policy": "random",
    "visits": "every",
    "target": "td",
    "tolerance": 1e-6,
    "max_passes": 100_000,
    "sampling": "weighted",
    "policy_run": "",
    "policy_epsilon": 0.1,
    "alpha_w": 0.1,
    "lambda_theta": 0.9,
    "lambda_w": 0.9,
    "v_init": 0.0,
}
PREDICTION_DEFAULTS: dict[str, Any] = {"update": "constant_alpha"}
"""mc_prediction's own default of a key another algorithm defaults otherwise"""


def env_threshold(env: gymnasium.Env[Any, Any], env_id: str) -> float | None:
    """``train.reward_threshold: null``: the environment's, scaled for CartPole's time limit.

    Args:
        env: The environment as made.
        env_id: Its id.

    Returns:
        The threshold, or None when the environment has none.
    """
    assert env.spec is not None
    threshold = env.spec.reward_threshold
    if threshold is None:
        return None
    registered = gymnasium.spec(env_id).max_episode_steps
    steps = env.spec.max_episode_steps
    if env_id.startswith("CartPole") and steps is not None and registered and steps != registered:
        return threshold * steps / registered
    return float(threshold)


def reference_train(
    env_id: str,
    *,
    algorithm: str,
    gamma: float,
    alpha: float | str | Mapping[str, Any] | Schedule,
    epsilon: float | Mapping[str, Any] | Schedule,
    q_init: float,
    episodes: int,
    seed: int,
    threshold: float | str | None = "env",
    kwargs: Mapping[str, Any] | None = None,
    discretization: Mapping[str, Sequence[float]] | None = None,
    physics: Mapping[str, Any] | None = None,
    randomize: Mapping[str, Sequence[float]] | None = None,
    stop_when_solved: bool = True,
    params: Mapping[str, Any] | None = None,
    initial_values: Sequence[float] | None = None,
    max_env_steps: int | None = None,
) -> ReferenceRun:
    """Train as the contract says, in plain Python on ``gymnasium.make``.

    Args:
        env_id: The Gymnasium id.
        algorithm: ``agent.algorithm``.
        gamma: ``agent.gamma``.
        alpha: ``agent.alpha``: a number, a schedule mapping, a schedule function, or
            ``"sample_average"``.
        epsilon: ``agent.epsilon``, as ``alpha``.
        q_init: ``agent.q_init``.
        episodes: ``train.episodes``.
        seed: The run's seed.
        threshold: The solve threshold; ``"env"`` for the environment's own (as
            ``train.reward_threshold: null``); None for never solved.
        kwargs: ``env.kwargs``, forwarded to ``gymnasium.make``.
        discretization: ``bins``, ``low`` and ``high`` for a Box observation.
        physics: ``env.physics`` (CartPole).
        randomize: ``env.randomize`` (CartPole): ``{key: [low, high]}``.
        stop_when_solved: ``train.stop_when_solved``.
        params: The algorithm's keys (``n``, ``lambda``, ``trace``, ``planning_steps``,
            ``kappa``, ``update``); missing ones take docs/algorithms.md's defaults.
        initial_values: ``agent.initial_values`` (a prediction algorithm's ``V`` before
            the first episode, one value per row); ``None``: every row at ``q_init``.
        max_env_steps: ``train.max_env_steps``: the episode whose step reaches it is
            truncated there and is the last; ``None``: no limit.

    Returns:
        The kept table, the visits, the returns and lengths, the solve episode.
    """
    averaged = alpha == "sample_average"
    alpha_of = constant(math.nan) if averaged else schedule(alpha)  # type: ignore[arg-type]
    epsilon_of = schedule(epsilon)
    env = gymnasium.make(env_id, **dict(kwargs or {}))
    state_shape, row = make_indexer(env.observation_space, discretization)
    assert isinstance(env.action_space, spaces.Discrete)
    n = int(env.action_space.n)
    n_states = math.prod(state_shape)
    if threshold == "env":
        threshold = env_threshold(env, env_id)
    assert threshold is None or isinstance(threshold, (int, float))

    agent_seq, env_seq, physics_seq = np.random.SeedSequence(seed).spawn(3)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    physics_rng = np.random.Generator(np.random.PCG64(physics_seq))
    env_seed = int(env_seq.generate_state(1, dtype=np.uint32)[0])

    tilings = int((discretization or {}).get("tilings", 1))  # type: ignore[call-overload]
    # docs/algorithms.md, "Tile coding": every weight starts at q_init / T.
    weight_init = float(q_init) / tilings if tilings > 1 else float(q_init)
    defaults = {
        **PARAMETER_DEFAULTS,
        **(PREDICTION_DEFAULTS if algorithm == "mc_prediction" else {}),
    }
    agent = ALGORITHMS[algorithm](
        n_states, n, weight_init, float(gamma), rng,
        {**defaults, **(params or {}), "tilings": tilings},
    )  # fmt: skip
    if initial_values is not None:  # docs/algorithms.md, "Prediction": row x starts at entry x
        agent.q = [
            [float(value)] * len(row) for value, row in zip(initial_values, agent.q, strict=True)
        ]
    if averaged:  # docs/algorithms.md, "Sample averages": one count per table entry
        agent.step_counts = [[0.0] * len(row) for row in agent.q]
    measured: list[Any] = []
    truth: list[float] = []
    errors: list[float] | None = None
    if isinstance(agent, Prediction):
        threshold = None  # a prediction run never solves
        # "State aggregation" and "Tile coding": a world observed as points is measured on
        # tiles only (with one tiling nothing is measured).
        points = getattr(env.unwrapped, "point_of_state", None)
        if hasattr(env.unwrapped, "P") and (points is None or tilings > 1):
            measured, truth = true_values(env, n, float(gamma), agent.pi_of, row)
            errors = []
    if isinstance(
        agent,
        (MonteCarlo, MCPrediction, BatchPrediction, OfflineLambdaReturn, OffPolicyMCPrediction),
    ):
        assert env.spec is not None
        limit = env.spec.max_episode_steps
        agent.buffer_length = int(limit) if limit is not None else NO_TIME_LIMIT_LENGTH
    if physics:
        set_physics(env, physics)
    visits = [[0] * n for _ in range(n_states)]
    returns: list[float] = []
    lengths: list[int] = []
    solved = None
    kept: list[list[float]] | None = None
    steps = 0
    for episode in range(episodes):
        agent.epsilon, agent.alpha = epsilon_of(episode), alpha_of(episode)
        if randomize:
            drawn = {
                key: physics_rng.uniform(randomize[key][0], randomize[key][1])
                for key in RANDOMIZE_ORDER
                if key in randomize
            }
            set_physics(env, drawn)
        observation, _ = env.reset(seed=env_seed if episode == 0 else None)
        s = row(observation)
        a: int | None = agent.start(s)
        episode_return, length = 0.0, 0
        while a is not None:
            observation, reward, terminated, truncated, _ = env.step(a)
            s2 = row(observation)
            r = float(reward)
            for tile in s if isinstance(s, tuple) else (s,):
                visits[tile][a] += 1
            episode_return += r
            length += 1
            if max_env_steps is not None and steps + length >= max_env_steps:
                truncated = True  # docs/algorithms.md, "A budget of steps"
            a2 = agent.step(s, a, r, s2, bool(terminated), bool(truncated) and not terminated)
            s, a = s2, a2
        returns.append(episode_return)
        lengths.append(length)
        steps += length
        if errors is not None:
            errors.append(rms_error(agent, measured, truth))
        if solved is None and threshold is not None and episode >= 99:
            total = 0.0
            for value in returns[episode - 99 : episode + 1]:
                total += value
            if total / 100 >= threshold:
                solved = episode + 1
                kept = [list(values) for values in agent.kept_table()]
                if stop_when_solved:
                    break
        if max_env_steps is not None and steps >= max_env_steps:
            break
    env.close()
    if kept is None:
        kept = agent.kept_table()
    q_table = np.array(kept, dtype=np.float64).reshape(*state_shape, len(kept[0]))  # V: 1
    visit_table = np.array(visits, dtype=np.int64).reshape(*state_shape, n)
    return ReferenceRun(q_table, visit_table, returns, lengths, solved, errors)
