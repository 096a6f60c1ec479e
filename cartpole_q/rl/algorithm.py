"""What an algorithm is to the rest of the package, and the registry of algorithms.

An algorithm is one module that builds an :class:`Algorithm`: its name and a line on it,
the config keys it adds (``agent.n``, ``agent.lambda``: :class:`Param`), the memory it keeps
across steps and episodes (Double Q-learning's second table, traces, an n-step buffer, a
learned model), and its hooks, plain functions the engines compile with numba:

- ``start(q, memory, params, state, epsilon, rng) -> action``: an episode begins in
  ``state``; return its first action (default: epsilon-greedy on ``Q``);
- ``step(q, memory, params, transition, rates, rng) -> next action or ENDED``: learn from
  one transition (a :class:`~cartpole_q.rl.tabular.Transition`: ``state``, ``action``,
  ``reward``, ``next_state``, ``terminated``, ``truncated``) at the episode's
  :class:`~cartpole_q.rl.tabular.Rates` (``alpha``, ``gamma``, ``epsilon``); return the next
  action, or :data:`~cartpole_q.rl.tabular.ENDED` when the episode ended;
- ``end(q, memory, params, rates, rng)``: the episode has ended (default: nothing).

``q`` is the learned table as 2-D ``(n_states, n_actions)``; ``memory`` the tuple of arrays
:attr:`Algorithm.memory` allocated (under ``agent.alpha: sample_average`` followed by the
table of update counts, which is also what ``rates.alpha`` then is: see
:func:`~cartpole_q.rl.tabular.averaged_update`); ``params`` the algorithm's parameters as a tuple of
floats in :attr:`Algorithm.params` order. The training loop counts ``visits[s, a] += 1``
before every step, for every algorithm. :attr:`Algorithm.policy` says which table
``q_table.npy`` holds (``Q`` itself by default). Checkpoints store ``q`` and every memory
array, so resuming any algorithm is byte-identical.

A new algorithm is one module and one :func:`cartpole_q.rl.algorithms.register` call;
configs, validation, the README's table and the benchmarks read the registry there.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from cartpole_q.rl.tabular import TIE_BREAKS, first_action, no_episode_end

ParamValue = float | int | str


@dataclass(frozen=True)
class Param:
    """A config key an algorithm adds under ``agent`` (``agent.n``, ``agent.trace``)."""

    key: str
    """the key under ``agent``"""
    default: ParamValue
    """the value a config that leaves it out gets"""
    doc: str
    """what it means, one line"""
    kind: str = "float"
    """``float``, ``int``, ``choice`` or ``str`` (text the hooks never read: a path)"""
    low: float | None = None
    """the smallest value (``None``: no bound)"""
    high: float | None = None
    """the largest value (``None``: no bound)"""
    low_open: bool = False
    """``low`` itself is excluded"""
    choices: tuple[str, ...] = ()
    """the values of a ``choice`` (passed to the hooks as their index, a float)"""

    @property
    def interval(self) -> str:
        """The accepted values as text: ``[0, 1]``, ``an integer >= 1``, ``a, b or c``.

        >>> Param("n", 1, "", kind="int", low=1).interval
        'an integer >= 1'
        >>> Param("lambda", 0.9, "", low=0.0, high=1.0).interval
        '[0, 1]'
        """
        if self.kind == "str":
            return "text"
        if self.kind == "choice":
            if len(self.choices) == 1:
                return self.choices[0]
            return ", ".join(self.choices[:-1]) + f" or {self.choices[-1]}"
        if self.kind == "int":
            parts = [f">= {self.low:g}" if self.low is not None else ""]
            parts += [f"<= {self.high:g}" if self.high is not None else ""]
            return "an integer " + " and ".join(part for part in parts if part)
        low = "-inf" if self.low is None else f"{self.low:g}"
        high = "inf" if self.high is None else f"{self.high:g}"
        return f"{'(' if self.low_open or self.low is None else '['}{low}, {high}{']' if self.high is not None else ')'}"

    def as_float(self, value: ParamValue) -> float:
        """The value as the hooks take it (a choice as its index).

        >>> Param("trace", "replacing", "", kind="choice", choices=("a", "replacing")).as_float("replacing")
        1.0
        """
        if self.kind == "choice":
            return float(self.choices.index(str(value)))
        if self.kind == "str":
            return 0.0  # text (a path) is read when memory is made, never by the hooks
        return float(value)


@dataclass(frozen=True)
class MemoryContext:
    """What an algorithm's memory is sized by."""

    n_states: int
    n_actions: int
    q_init: float
    params: Mapping[str, ParamValue]
    """the algorithm's parameters by key (defaults filled)"""
    max_steps: int
    """the longest an episode can be (its time limit, or the greedy cap without one)"""
    episodes: int = 0
    """the run's training episodes (``train.episodes``; 0 where no run is sized)"""
    policy: Sequence[int] | None = None
    """a prediction run's named policy (``agent.policy`` other than ``random``): the action
    of each state, from the world's profile"""
    averaged: bool = False
    """``agent.alpha: sample_average``: the engine keeps the update counts of ``q`` (its last
    memory array); an algorithm with a second table keeps that table's counts itself"""


def no_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The memory of an algorithm that keeps none."""
    return ()


def same_table(q: np.ndarray, memory: tuple[np.ndarray, ...]) -> np.ndarray:
    """The policy of most algorithms: the table ``Q`` itself."""
    return q


def param_index(params: Sequence[Param], param: Param) -> int:
    """Where ``param`` stands in the ``params`` tuple the hooks get, by its key.

    A hook reads its parameters by name through module constants made with it,
    ``LAMBDA_AT = param_index(PARAMS, LAMBDA)`` then ``params[LAMBDA_AT]``: numba reads the
    constant at compile time, and the declaration order can change without a hook reading
    another parameter.

    >>> param_index((Param("n", 1, ""), Param("lambda", 0.9, "")), Param("lambda", 0.5, ""))
    1
    """
    keys = [declared.key for declared in params]
    if param.key not in keys:
        raise ValueError(f"{param.key!r} is not among the parameters {keys}")
    return keys.index(param.key)


UNDECLARED_SAMPLE_AVERAGE = (
    "its module does not declare that its step size reaches nothing but update and the trace "
    'functions (an algorithm that does says so with Algorithm(..., no_sample_average=""))'
)
"""the refusal of ``agent.alpha: sample_average`` for an algorithm that does not declare it"""


@dataclass(frozen=True)
class Algorithm:
    """An algorithm: its name, its config keys, its memory and its compiled hooks."""

    name: str
    """the ``agent.algorithm`` value"""
    description: str
    """one line: what it is and where the book has it"""
    step: Callable[..., int]
    """learn from one transition and return the next action (see the module docstring)"""
    start: Callable[..., int] = first_action
    """choose an episode's first action"""
    end: Callable[..., None] = no_episode_end
    """finish an episode"""
    params: tuple[Param, ...] = ()
    """the config keys it adds under ``agent``, in the order the hooks get them"""
    memory: Callable[[MemoryContext], tuple[np.ndarray, ...]] = no_memory
    """allocate the arrays it keeps across steps and episodes"""
    policy: Callable[[np.ndarray, tuple[np.ndarray, ...]], np.ndarray] = same_table
    """the table whose greedy actions are its policy (``q_table.npy``), from ``Q`` and memory"""
    memory_names: tuple[str, ...] = ()
    """a name for each memory array, in order, for readers (checkpoints store them as
    ``memory_0``, ``memory_1``, ...); one that only a variant allocates comes last (Double
    Q-learning's ``q_b_update_counts``, under sample averages)"""
    book: str = ""
    """where Sutton & Barto (2nd ed.) state it"""
    task: str = "control"
    """``control`` (learns ``Q`` and acts epsilon-greedily on it) or ``prediction`` (learns
    the state values ``V`` of the policy ``agent.policy``, which chooses the actions; its
    table has one column: :mod:`cartpole_q.rl.prediction`)"""
    not_on_tiles: str = ""
    """why it does not run on tile coding (empty: it does). On tiles a hook's state is a
    handle of one episode's observations (:mod:`cartpole_q.rl.tiles`), so memory that keys
    states across episodes (a model, per-state counts) has no meaning there"""
    no_sample_average: str = UNDECLARED_SAMPLE_AVERAGE
    """why ``agent.alpha: sample_average`` does not apply to it; empty: it does. Under a
    sample average the hooks' ``alpha`` is the table of update counts and
    :func:`~cartpole_q.rl.tabular.update` (and the trace functions) move an entry by its own
    ``1 / N``, so an algorithm declares ``no_sample_average=""`` when its step size reaches
    nothing but those; one whose step size reaches anything else (true online traces, a
    batch iterated to convergence) says why not. The default refuses it for an algorithm
    that says neither"""
    epsilon_floor: float = 0.0
    """the smallest positive epsilon it is defined for (0.0: any): off-policy Monte Carlo
    divides by the probability ``epsilon / n`` of an exploratory action, which a smaller
    positive epsilon could round to 0. Configs whose epsilon takes a positive value below
    it in any episode are refused"""
    growing_memory: tuple[int, ...] = ()
    """the memory arrays (by index) whose first axis grows with ``train.episodes`` (a batch
    of every transition seen): a run extended past its episodes resumes from a checkpoint
    whose arrays are shorter, copied into the start of the longer ones"""
    older_memory: Callable[[tuple[np.ndarray, ...]], tuple[np.ndarray, ...]] | None = None
    """rebuild a memory an earlier version wrote with fewer arrays (a checkpoint from before
    the algorithm kept more), so that ``train --resume`` continues it; ``None``: a memory of
    another layout is refused. Raises ``ValueError`` for a memory it cannot rebuild"""
    key: str = field(default="", compare=False)
    """the name and a digest of the module's source: compiled code is cached under it, so
    an edited algorithm is compiled again (set when registered)"""

    @property
    def predicts(self) -> bool:
        """Whether it learns state values ``V`` (``task: prediction``) instead of ``Q``."""
        return self.task == "prediction"

    def table_columns(self, n_actions: int) -> int:
        """The columns of its table: the actions (``Q``), or 1 (``V``)."""
        return 1 if self.predicts else n_actions

    def param(self, key: str) -> Param:
        """The parameter ``key`` (raises ``KeyError`` for another)."""
        for param in self.params:
            if param.key == key:
                return param
        raise KeyError(key)

    def hook_params(
        self, values: Mapping[str, ParamValue], tie_break: str = "lowest"
    ) -> tuple[float, ...]:
        """The parameters as the hooks take them: floats, in declaration order, then the tie rule.

        The last is ``agent.tie_break`` as its index in ``TIE_BREAKS`` (``random``: 1.0),
        which every algorithm's epsilon-greedy reads (``behaviour_action``).
        """
        own = tuple(param.as_float(values[param.key]) for param in self.params)
        return (*own, float(TIE_BREAKS.index(tie_break)))
