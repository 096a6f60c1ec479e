"""What every engine shares: parameters as compiled code takes them, state, interface.

The compiled code takes a few typed records (named tuples of numbers and arrays) rather
than long lists of positional arguments: :class:`Grid`, :class:`AgentRecord`,
:class:`Tables` and :class:`EpisodeMetrics`. Which algorithm runs is not a record field: the
compiled loops are built per algorithm (see :mod:`cartpole_q.engines.kernel`).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple, Protocol

import numpy as np
import yaml

from cartpole_q.config import Config, ConfigError, EnvConfig, Schedule
from cartpole_q.envs.gym import EnvInfo
from cartpole_q.envs.models import GREEDY_STEP_CAP
from cartpole_q.families import profile_for
from cartpole_q.numba_cache import is_cached
from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.rl.prediction import (
    POLICY,
    POLICY_EPSILON,
    POLICY_RUN,
    RUN_POLICIES,
    policy_table,
)
from cartpole_q.rl.schedules import SAMPLE_AVERAGE, SCHEDULE_KINDS, schedule_value
from cartpole_q.rl.solvers import (
    evaluate_policy,
    on_policy_distribution,
    reachable_states,
)


def pair_name(algorithm_key: str, twin_key: str, tiled: bool, averaged: bool = False) -> str:
    """An (algorithm, twin) pair as the names of its compiled loops say it.

    >>> pair_name("sarsa", "cartpole_0123", tiled=False, averaged=True)
    'sarsa__cartpole_0123__averaged'
    """
    return (
        f"{algorithm_key}__{twin_key}"
        + ("__tiles" if tiled else "")
        + ("__averaged" if averaged else "")
    )


def kernel_name(
    algorithm_key: str,
    twin_key: str,
    randomized: bool,
    tiled: bool,
    greedy: bool,
    averaged: bool = False,
) -> str:
    """One of the numba engine's two training loops of a pair, as numba's cache names it.

    ``averaged``: compiled for ``agent.alpha: sample_average``.

    >>> kernel_name("sarsa", "cartpole_0123", randomized=True, tiled=False, greedy=False)
    'train_exploring__sarsa__cartpole_0123__randomized'
    """
    pair = pair_name(algorithm_key, twin_key, tiled, averaged)
    kind = "greedy" if greedy else "exploring"
    return f"train_{kind}__{pair}" + ("__randomized" if randomized else "")


def step_function_name(step: str, algorithm_key: str, kind: str, averaged: bool = False) -> str:
    """One of the gymnasium engine's compiled step functions, as numba's cache names it.

    ``averaged``: compiled for ``agent.alpha: sample_average``.

    >>> step_function_name("next_step", "sarsa_0123", "tiles")
    'next_step__sarsa_0123__tiles'
    """
    return f"{step}__{algorithm_key}__{kind}" + ("__averaged" if averaged else "")


class ScheduleRecord(NamedTuple):
    """A schedule as the compiled code takes it (see :mod:`cartpole_q.rl.schedules`)."""

    kind: int
    start: float
    end: float
    rate: float

    @classmethod
    def of(cls, schedule: Schedule) -> ScheduleRecord:
        """The record of a config's schedule."""
        return cls(schedule.code, schedule.start, schedule.end, schedule.rate)


def epsilon_record(config: Config) -> ScheduleRecord:
    """The epsilon schedule the compiled code runs: the config's, or a prediction run's 0.

    A prediction algorithm's actions are its policy's, so epsilon plays no part: it is the
    constant 0 (``metrics.csv``'s epsilon column), and the numba engine runs its greedy
    loop alone.
    """
    if get_algorithm(config.agent.algorithm).predicts:
        return ScheduleRecord(SCHEDULE_KINDS.index("constant"), 0.0, 0.0, 1.0)
    return ScheduleRecord.of(config.agent.epsilon)


def loops_played(epsilon: ScheduleRecord, start: int, stop: int) -> tuple[bool, ...]:
    """Which training loops episodes ``start .. stop - 1`` play, as ``greedy`` flags, sorted.

    The numba engine has an exploring loop (epsilon > 0) and a greedy one (epsilon 0; see
    :mod:`~cartpole_q.engines.kernel`). Epsilon schedules never rise: the first episode says
    whether any explores, the last whether any is greedy. Computed by the plain schedule,
    it decides only what to compile ahead (the loops decide for themselves).

    >>> loops_played(ScheduleRecord(2, 1.0, 0.0, 9.0), 0, 1000)  # the default's log schedule
    (False, True)
    >>> constant = ScheduleRecord(0, 0.1, 0.1, 1.0)
    >>> loops_played(constant, 0, 1000), loops_played(constant, 5, 5)
    ((False,), ())
    """
    if start >= stop:
        return ()
    first, last = (
        not schedule_value(epsilon.kind, epsilon.start, epsilon.end, epsilon.rate, episode) > 0.0
        for episode in (start, stop - 1)
    )
    return tuple(sorted({first, last}))


GREEDY_LOOP_STEPS = 1_000_000
"""the greedy env steps a run may play from which it compiles the greedy loop as well"""


def greedy_loop_pays(
    epsilon: ScheduleRecord, start: int, stop: int, time_limit: int | None
) -> bool:
    """Whether episodes ``start .. stop - 1`` may play enough greedy steps to compile for.

    A run that explores first and then plays greedy episodes needs only the exploring loop:
    it plays a greedy episode as well, with epsilon 0 (the same draws: none), where the
    greedy loop takes about a third less time per step but seconds to compile. So the greedy loop is
    compiled for such a run only when its greedy episodes may take at least
    :data:`GREEDY_LOOP_STEPS` env steps (their number times the time limit; no limit:
    always), where being faster may pay; under that bound it would save a few hundredths
    of a second. (A cached greedy loop is used anyway: see the numba engine.)

    >>> default = ScheduleRecord(2, 1.0, 0.0, 9.0)  # 0 from episode 89 (0-based) on
    >>> greedy_loop_pays(default, 0, 1000, 500), greedy_loop_pays(default, 0, 3000, 500)
    (False, True)
    >>> greedy_loop_pays(default, 0, 1000, None), greedy_loop_pays(default, 0, 89, None)
    (True, False)
    """
    first_greedy = bisect.bisect_left(
        range(start, stop),
        True,
        key=lambda episode: (
            not schedule_value(epsilon.kind, epsilon.start, epsilon.end, epsilon.rate, episode)
            > 0.0
        ),
    )
    greedy_episodes = stop - start - first_greedy
    if greedy_episodes <= 0:
        return False
    return time_limit is None or greedy_episodes * time_limit >= GREEDY_LOOP_STEPS


def plays_greedy_loop(
    greedy_name: str, epsilon: ScheduleRecord, start: int, stop: int, time_limit: int | None
) -> bool:
    """Whether a run that explores, then plays greedy episodes, plays those on the greedy loop.

    Where the loop (``greedy_name``) is in numba's cache, loading it costs nothing; else
    where compiling it pays (:func:`greedy_loop_pays`).
    """
    return is_cached(greedy_name) or greedy_loop_pays(epsilon, start, stop, time_limit)


def exploring_plays_greedy(
    greedy_loop: bool | None,
    greedy_name: str,
    epsilon: ScheduleRecord,
    episodes: int,
    time_limit: int | None,
) -> bool:
    """Whether a run's exploring loop plays its greedy episodes too, leaving the greedy loop.

    Only a run that explores and then plays greedy episodes (over its ``episodes``, from
    0: a resumed run decides as its first part did) has the choice: ``greedy_loop`` makes
    it (``None``: :func:`plays_greedy_loop`). The numba engine and
    :func:`~cartpole_q.engines.loop_names` both ask here.
    """
    if loops_played(epsilon, 0, episodes) != (False, True):
        return False
    if greedy_loop is None:
        greedy_loop = plays_greedy_loop(greedy_name, epsilon, 0, episodes, time_limit)
    return not greedy_loop


class Truth(NamedTuple):
    """The true values a prediction run's ``V`` is measured against after every episode.

    Empty arrays for a control run, or where the values cannot be known (no model of the
    world, tile coding): nothing is measured then. One entry per measured state of the
    world's model; where the world aggregates states (state aggregation), several states
    are observed as one row and each is measured against ``V`` of its row.
    """

    rows: np.ndarray
    """int64 ``(k, T)``: the table rows each measured state is observed as, the states in
    order: one row (``T = 1``) on a table, its ``T`` tiles on tiles (``V`` is their sum)"""
    values: np.ndarray
    """float64: the evaluated policy's exact value of each"""
    states: np.ndarray
    """int64: the measured states of the world's model (its reachable non-terminal states),
    in order: the x axis of a values figure"""

    @classmethod
    def none(cls) -> Truth:
        """Nothing to measure."""
        nothing = np.zeros(0, dtype=np.int64)
        return cls(nothing.reshape(0, 1), np.zeros(0, dtype=np.float64), nothing.copy())

    @property
    def measured(self) -> bool:
        """Whether there is anything to measure."""
        return bool(self.rows.shape[0])


NO_STEP_LIMIT = 2**63 - 1
"""a limit of steps never reached (the largest int64): no time limit, no ``train.max_env_steps``"""


class AgentRecord(NamedTuple):
    """The hyperparameters every algorithm has, as the compiled code takes them."""

    gamma: float
    alpha: ScheduleRecord
    epsilon: ScheduleRecord
    threshold: float
    """the solve threshold; ``inf`` when the environment has none (never solved)"""
    max_env_steps: int
    """``train.max_env_steps``: the run's training steps in all, the episode reaching it
    cut there (:data:`NO_STEP_LIMIT` when there is none)"""


class Grid(NamedTuple):
    """How an observation becomes a Q-table row, as compiled code takes it.

    Binned (Box) observations: float64 edges and int64 bins per dimension, ``starts``
    empty. Indexed (Discrete, Tuple of Discrete) observations: ``bins`` holds each
    component's size and ``starts`` its ``start`` (int64), ``low`` and ``high`` empty; the
    row is ``obs - start`` (components in C order). ``starts.size > 0`` is the index mode.
    """

    low: np.ndarray
    high: np.ndarray
    bins: np.ndarray
    starts: np.ndarray

    @property
    def indexed(self) -> bool:
        """Whether observations are the row index (Discrete) rather than binned (Box)."""
        return bool(self.starts.size)

    @classmethod
    def of(cls, config: Config, env_info: EnvInfo) -> Grid:
        """The grid of a validated config on its (inspected) environment."""
        if env_info.index_starts is not None:
            return cls(
                np.zeros(0, dtype=np.float64),
                np.zeros(0, dtype=np.float64),
                np.array(env_info.state_shape, dtype=np.int64),
                np.array(env_info.index_starts, dtype=np.int64),
            )
        d = config.discretization
        assert d is not None  # inspect_env refuses a Box observation without a grid
        return cls(
            np.array(d.low, dtype=np.float64),
            np.array(d.high, dtype=np.float64),
            np.array(d.bins, dtype=np.int64),
            np.zeros(0, dtype=np.int64),
        )


class Tables(NamedTuple):
    """The learned tables, as 2-D ``(n_states, n_actions)`` views, and the algorithm's memory."""

    q: np.ndarray
    """float64: the table the algorithm learns (Double Q-learning's ``A``)"""
    visits: np.ndarray
    """int64: how often training took each (state, action)"""
    memory: tuple[np.ndarray, ...]
    """the algorithm's own arrays (Double Q-learning's ``B``, traces, buffers, a model),
    then, under ``agent.alpha: sample_average``, the table of update counts (float64, ``q``'s
    shape)"""


class EpisodeMetrics(NamedTuple):
    """One value per training episode: the columns of ``metrics.csv`` after ``episode``."""

    returns: np.ndarray
    """float64"""
    lengths: np.ndarray
    """int64"""
    epsilons: np.ndarray
    """float64"""
    alphas: np.ndarray
    """float64"""

    @classmethod
    def empty(cls, episodes: int) -> EpisodeMetrics:
        """Zeroed arrays for ``episodes`` episodes."""
        return cls(
            np.zeros(episodes, dtype=np.float64),
            np.zeros(episodes, dtype=np.int64),
            np.zeros(episodes, dtype=np.float64),
            np.zeros(episodes, dtype=np.float64),
        )

    def head(self, episodes: int) -> EpisodeMetrics:
        """Copies of the first ``episodes`` values."""
        return EpisodeMetrics(*(column[:episodes].copy() for column in self))


@dataclass(frozen=True)
class AgentParams:
    """A config's algorithm, grid and agent settings, ready for the compiled code."""

    algorithm: Algorithm
    grid: Grid
    agent: AgentRecord
    params: tuple[float, ...]
    """the algorithm's own parameters, as its hooks take them"""
    tilings: int = 1
    """tile coding's tilings (1: plain rows; see :mod:`cartpole_q.rl.tiles`)"""
    max_steps: int = 0
    """the longest episode (its time limit, or the greedy cap): on tiles, the handles"""
    truth: Truth = field(default_factory=Truth.none)
    """a prediction run's true values (:func:`prediction_truth`; empty: none measured)"""

    @property
    def tiled(self) -> bool:
        """Whether observations are tile-coded (the hooks get ``(weights, features)``)."""
        return self.tilings > 1

    @property
    def averaged(self) -> bool:
        """Whether ``agent.alpha`` is ``sample_average`` (the hooks' ``alpha`` is the counts)."""
        return self.agent.alpha.kind == SAMPLE_AVERAGE

    def hook_table(self, q: np.ndarray) -> Any:
        """The table as the hooks take it: ``q``, or on tiles ``(q, features)``.

        The features are a fresh ``(max_steps + 1, T)`` array of the handles' tile rows
        (scratch: an episode writes them before it reads them).
        """
        if not self.tiled:
            return q
        return (q, np.zeros((self.max_steps + 1, self.tilings), dtype=np.int64))

    @classmethod
    def from_config(cls, config: Config, env_info: EnvInfo) -> AgentParams:
        """Build the parameters of a validated config on its environment."""
        threshold = env_info.reward_threshold
        algorithm = get_algorithm(config.agent.algorithm)
        tilings = config.discretization.tilings if config.discretization is not None else 1
        return cls(
            algorithm=algorithm,
            grid=Grid.of(config, env_info),
            agent=AgentRecord(
                gamma=config.agent.gamma,
                alpha=ScheduleRecord.of(config.agent.alpha),
                epsilon=epsilon_record(config),
                threshold=math.inf if threshold is None else float(threshold),
                max_env_steps=config.train.max_env_steps or NO_STEP_LIMIT,
            ),
            params=algorithm.hook_params(config.agent.params, config.agent.tie_break),
            tilings=tilings,
            max_steps=env_info.max_episode_steps or GREEDY_STEP_CAP,
            truth=prediction_truth(config, env_info) if algorithm.predicts else Truth.none(),
        )


def prediction_truth(config: Config, env_info: EnvInfo) -> Truth:
    """The evaluated policy's exact values on the world's non-terminal states.

    From the world's transition table, by
    :func:`~cartpole_q.rl.solvers.evaluate_policy` with the config's
    ``agent.gamma``; each model state is measured on the table row it is observed as
    (several on one row only where the world aggregates states by design: where two share a
    row by accident, as Blackjack's natural 21 and a 21 with a usable ace, nothing is
    measured), or only the states the world names (Blackjack dealt one hand). On tiles, a
    world observed as points (its ``point_of_state``) measures each state on its tiles.
    Nothing is measured for a world without a model.
    """
    # A sweep's runs of one point ask for the same values: solved once per process. A run's
    # policy is keyed by its actions (the file may change between two calls).
    policy = EvaluatedPolicy.of(config)
    key = (
        repr(config.env), env_info.max_episode_steps, env_info.state_shape, env_info.n_actions,
        config.agent.gamma, policy.name, policy.epsilon, repr(config.discretization),
        tuple(run_greedy_actions(config.env, policy, env_info)) if policy.from_run else None,
    )  # fmt: skip
    found = _TRUTHS.get(key)
    if found is None:
        found = _solve_truth(config, env_info)
        if len(_TRUTHS) >= 64:
            _TRUTHS.clear()
        _TRUTHS[key] = found
    return found


_TRUTHS: dict[tuple[Any, ...], Truth] = {}
"""the true values solved in this process, by what decides them"""


@dataclass(frozen=True)
class EvaluatedPolicy:
    """A fixed policy whose values are learnt or solved: ``agent.policy`` and its source.

    A prediction run's (:meth:`of` its config), or ``optimum --policy``'s: the same policy
    on a world needs no algorithm to be evaluated exactly.
    """

    name: str = str(POLICY.default)
    """``agent.policy``: ``random``, a rule the world declares, ``greedy`` or ``epsilon_greedy``"""
    run: str = str(POLICY_RUN.default)
    """``agent.policy_run``: the control run whose table gives a run's policy (absolute)"""
    epsilon: float = float(POLICY_EPSILON.default)
    """``agent.policy_epsilon``: ``epsilon_greedy``'s probability of a uniform action"""

    @classmethod
    def of(cls, config: Config) -> EvaluatedPolicy:
        """The policy a (prediction) config evaluates; a control config's is ``random``."""
        params = config.agent.params
        return cls(
            str(params.get(POLICY.key, cls.name)),
            str(params.get(POLICY_RUN.key, cls.run)),
            float(params.get(POLICY_EPSILON.key, cls.epsilon)),
        )

    @property
    def from_run(self) -> bool:
        """Whether a run's table gives it (``greedy``, ``epsilon_greedy``)."""
        return self.name in RUN_POLICIES

    def params(self) -> dict[str, Any]:
        """Its keys as a prediction algorithm's parameters name them (for its policy table)."""
        return {POLICY.key: self.name, POLICY_RUN.key: self.run, POLICY_EPSILON.key: self.epsilon}

    def table(self, env: EnvConfig, env_info: EnvInfo) -> np.ndarray:
        """``pi`` on the table's rows: each row's probability of each action."""
        return policy_table(
            MemoryContext(
                math.prod(env_info.state_shape), env_info.n_actions, 0.0, self.params(), 0,
                policy=named_policy(env, self, env_info),
            )
        )  # fmt: skip


def named_policy(env: EnvConfig, policy: EvaluatedPolicy, env_info: EnvInfo) -> list[int] | None:
    """A named policy (not ``random``): its action in every row.

    The rule is the world's (its profile's ``policies``); validation has checked it has it.
    """
    if policy.name == "random":
        return None
    if policy.from_run:
        return run_greedy_actions(env, policy, env_info)
    rule = profile_for(env.id).policies[policy.name]
    return rule(tuple(env_info.state_shape))


def run_greedy_actions(env: EnvConfig, policy: EvaluatedPolicy, env_info: EnvInfo) -> list[int]:
    """The greedy action of every row of ``agent.policy_run``'s ``q_table.npy``.

    The lowest action of the largest value (design.md's argmax), in the table's C order.
    The run must be a control run on this config's ``env.id`` whose table has this
    config's shape, ``(*state_shape, n_actions)``. Reading one file is the only I/O of this
    layer: the table is the policy's definition, as a world's rule is (validation has
    checked that the file exists).

    Raises:
        ConfigError: naming ``agent.policy_run``: the table is unreadable, another world's,
            of another shape, or not finite.
    """
    run = Path(policy.run)
    field = f"agent.policy_run: {run}"
    if not run.exists():
        raise ConfigError(
            f"{field} does not exist (moved or removed?). A prediction run reads the policy it "
            "evaluates from that run: give a control run's directory; to resume a run that "
            "evaluated it, put the directory back at that path (its config.yaml names it), or "
            "start a new run with agent.policy_run where it is now."
        )
    if not (run / "q_table.npy").is_file():
        what = (
            "is a prediction run: it has state values (v_table.npy), no policy"
            if (run / "v_table.npy").is_file()
            else "has no q_table.npy: it is not a finished run directory"
        )
        raise ConfigError(f"{field} {what}. Give a control run's directory.")
    try:
        table = np.load(run / "q_table.npy", allow_pickle=False)
        raw = yaml.safe_load((run / "config.yaml").read_text(encoding="utf-8"))
    except (OSError, ValueError, EOFError, UnicodeError, yaml.YAMLError) as error:
        raise ConfigError(
            f"{field}: cannot read its q_table.npy and config.yaml ({type(error).__name__}: "
            f"{error})."
        ) from None
    section = raw.get("env") if isinstance(raw, dict) else None
    env_id = section.get("id") if isinstance(section, dict) else None
    if env_id != env.id:
        raise ConfigError(
            f"{field}: its config.yaml's env.id is {env_id or 'missing'}, not this "
            f"config's {env.id}; evaluate a run's policy on its own world."
        )
    shape = (*env_info.state_shape, env_info.n_actions)
    if table.shape != shape or table.dtype != np.float64 or not np.isfinite(table).all():
        raise ConfigError(
            f"{field}: its q_table.npy is {table.dtype} of shape {table.shape}; this config's "
            f"table is float64 of shape {shape} with finite values (the same discretization)."
        )
    rows = table.reshape(-1, env_info.n_actions)
    return [int(action) for action in np.argmax(rows, axis=1)]


def _solve_truth(config: Config, env_info: EnvInfo) -> Truth:
    """:func:`prediction_truth`, solved (see there)."""
    if config.discretization is not None and config.discretization.tilings > 1:
        return _tiled_truth(config, env_info)
    policy = EvaluatedPolicy.of(config)
    return exact_values(config.env, env_info, policy, config.agent.gamma, measure_shared_rows=False)


def _tiled_truth(config: Config, env_info: EnvInfo) -> Truth:
    """The random policy's exact values, each state measured on the tiles of its point.

    Only the random policy runs on tiles (a rule or a run's policy gives an action per
    table row); a world that does not observe points (``point_of_state``) measures nothing.
    """
    from cartpole_q.envs.models import point_model
    from cartpole_q.rl.tiles import active_tiles

    found = point_model(config.env)
    d = config.discretization
    if found is None or d is None or config.agent.params.get("policy", "random") != "random":
        return Truth.none()
    tabular, points = found
    pi = np.full((tabular.n_states, env_info.n_actions), 1.0 / env_info.n_actions)
    reachable, values = _policy_values(config.env.id, "random", tabular, pi, config.agent.gamma)
    measured = ~tabular.terminal_states()[reachable]
    states = reachable[measured]
    rows = np.zeros((len(states), d.tilings), dtype=np.int64)
    low, high = np.array(d.low, dtype=np.float64), np.array(d.high, dtype=np.float64)
    bins = np.array(d.bins, dtype=np.int64)
    for i, state in enumerate(states):
        active_tiles(points[state], low, high, bins, d.tilings, rows[i])
    return Truth(rows, values[measured].astype(np.float64), states.astype(np.int64))


def _policy_values(
    env_id: str, name: str, tabular: Any, pi: np.ndarray, gamma: float
) -> tuple[np.ndarray, np.ndarray]:
    """The reachable states under ``pi`` (the policy ``name``) and their values (``evaluate_policy``).

    Raises:
        ConfigError: naming ``agent.policy``: the values are not defined (``gamma`` 1 and a
            policy that may never end an episode).
    """
    reachable = np.flatnonzero(reachable_states(tabular, pi))
    try:
        values = evaluate_policy(tabular, pi, gamma, reachable)
    except ValueError as error:
        raise UndefinedValuesError(
            f"agent.policy: the {name} policy's values on {env_id} are not defined at "
            f"agent.gamma {gamma:g} ({error}); give agent.gamma below 1.",
            str(error),
        ) from None
    return reachable, values


class UndefinedValuesError(ConfigError):
    """A policy's values are not defined: at ``gamma`` 1 it may never end an episode."""

    def __init__(self, message: str, reason: str) -> None:
        super().__init__(message)
        self.reason = reason
        """why (the solver's words)"""


def exact_values(
    env: EnvConfig,
    env_info: EnvInfo,
    policy: EvaluatedPolicy,
    gamma: float,
    measure_shared_rows: bool = True,
) -> Truth:
    """``policy``'s exact values (discounted by ``gamma``) on every reachable non-terminal model state.

    As :func:`prediction_truth` (``cartpole-q optimum --policy`` prints them), but Blackjack's
    too: its natural 21s are model states of their own, on the row of a 21 with a usable ace
    (``measure_shared_rows``: keep such states; else nothing is measured where two states
    share a row and the world does not aggregate by design).
    """
    from cartpole_q.envs.models import EnvModel, env_model

    model = env_model(env, env_info.max_episode_steps)
    if not isinstance(model, EnvModel):
        return Truth.none()
    tabular, row_of_state = model.model, model.row_of_state
    pi = policy.table(env, env_info)[row_of_state]
    reachable, values = _policy_values(env.id, policy.name, tabular, pi, gamma)
    measured = ~tabular.terminal_states()[reachable]
    if model.measured is not None:  # the world measures these states only
        measured &= np.isin(reachable, model.measured)
    states = reachable[measured]
    rows = row_of_state[states]
    shared = len(np.unique(rows)) != len(rows)
    if shared and not (model.aggregates or measure_shared_rows):
        return Truth.none()  # states observed alike by accident: no one value per row
    return Truth(
        rows.astype(np.int64).reshape(-1, 1),
        values[measured].astype(np.float64),
        states.astype(np.int64),
    )


def prediction_distribution(config: Config, env_info: EnvInfo) -> np.ndarray:
    """The evaluated policy's on-policy distribution ``mu`` on the measured states.

    The fraction of an episode's time steps spent in each state of :func:`prediction_truth`'s
    ``states``, in their order (Sutton & Barto eq. 9.3, from the world's model by
    :func:`~cartpole_q.rl.solvers.on_policy_distribution`, renormalised over the
    measured states): what Figure 9.1 shades.

    Raises:
        ConfigError: the world has no model, or the policy may never end an episode.
    """
    from cartpole_q.envs.models import EnvModel, env_model

    truth = prediction_truth(config, env_info)
    model = env_model(config.env, env_info.max_episode_steps)
    if not truth.measured or not isinstance(model, EnvModel):
        raise ConfigError(f"{config.env.id}: no model to compute the on-policy distribution from.")
    pi = EvaluatedPolicy.of(config).table(config.env, env_info)[model.row_of_state]
    reachable = np.flatnonzero(reachable_states(model.model, pi))
    try:
        mu = on_policy_distribution(model.model, pi, reachable)
    except ValueError as error:
        raise ConfigError(f"agent.policy: no on-policy distribution ({error}).") from None
    measured = mu[np.searchsorted(reachable, truth.states)]
    distribution: np.ndarray = measured / measured.sum()
    return distribution


def initial_table(config: Config, n_states: int, columns: int, q_init: float) -> np.ndarray:
    """The table before the first update: ``q_init`` everywhere, or ``agent.initial_values``.

    >>> from cartpole_q.config import load_config
    >>> initial_table(load_config(None), 2, 3, 1.5).tolist()
    [[1.5, 1.5, 1.5], [1.5, 1.5, 1.5]]
    """
    starts = config.agent.initial_values
    if starts is None:
        return np.full((n_states, columns), q_init, dtype=np.float64)
    return np.repeat(np.array(starts, dtype=np.float64)[:, None], columns, axis=1)


@dataclass
class TrainingState:
    """Everything that changes while training; an engine advances it episode by episode.

    The tables are the 2-D ``(n_states, n_actions)`` views the compiled code addresses;
    the per-episode metrics are allocated for the configured episodes and filled up to
    ``episode``.
    """

    tables: Tables
    agent_rng: np.random.Generator
    metrics: EpisodeMetrics
    physics_rng: np.random.Generator
    """draws ``env.randomize``'s physics before every episode (nothing else)"""
    algorithm: Algorithm
    """the algorithm that learns the tables (its policy table is ``q_table.npy``)"""
    episode: int = 0
    """episodes finished"""
    env_steps: int = 0
    """environment steps taken in training (evaluations excluded)"""
    solved_episode: int | None = None
    """1-based episode at which the 100-episode average first reached the threshold"""
    solved_q: np.ndarray | None = None
    """the policy table at the solve point, kept when training goes on past it"""
    evaluations: list[dict[str, Any]] = field(default_factory=list)
    """periodic greedy evaluations: episode, env_steps, mean, std, min, max"""
    info: np.ndarray | None = None
    """float64, one value per configured episode: the sum of ``info[train.info_metric]``
    over the episode's steps (``None`` without ``train.info_metric``; the gymnasium engine
    fills it)"""
    errors: np.ndarray | None = None
    """float64, one value per configured episode: a prediction run's RMS error of ``V``
    against the true values after the episode (``None`` when nothing is measured)"""

    def steps_spent(self, max_env_steps: int) -> bool:
        """Whether the run has taken its ``train.max_env_steps`` (never with :data:`NO_STEP_LIMIT`)."""
        return self.env_steps >= max_env_steps

    @classmethod
    def fresh(
        cls,
        config: Config,
        env_info: EnvInfo,
        agent_rng: np.random.Generator,
        physics_rng: np.random.Generator | None = None,
    ) -> TrainingState:
        """Allocate the state of a run that has not started."""
        n_states = math.prod(env_info.state_shape)
        algorithm = get_algorithm(config.agent.algorithm)
        # On tiles every weight starts at q_init / T, so that every Q(s, a) starts near q_init.
        tilings = config.discretization.tilings if config.discretization is not None else 1
        q_init = config.agent.q_init / tilings if tilings > 1 else config.agent.q_init
        context = MemoryContext(
            n_states=n_states,
            n_actions=env_info.n_actions,
            q_init=q_init,
            params=dict(config.agent.params),
            max_steps=env_info.max_episode_steps or GREEDY_STEP_CAP,
            episodes=config.train.episodes,
            policy=(
                named_policy(config.env, EvaluatedPolicy.of(config), env_info)
                if algorithm.predicts
                else None
            ),
            averaged=config.agent.alpha.averages,
        )
        columns = algorithm.table_columns(env_info.n_actions)  # V: one column
        memory = tuple(algorithm.memory(context))
        if config.agent.alpha.averages:  # the update counts come last
            memory += (np.zeros((n_states, columns), dtype=np.float64),)
        return cls(
            tables=Tables(
                q=initial_table(config, n_states, columns, q_init),
                visits=np.zeros((n_states, env_info.n_actions), dtype=np.int64),
                memory=memory,
            ),
            agent_rng=agent_rng,
            metrics=EpisodeMetrics.empty(config.train.episodes),
            physics_rng=physics_rng if physics_rng is not None else np.random.default_rng(0),
            algorithm=algorithm,
            info=(
                None
                if config.train.info_metric is None
                else np.zeros(config.train.episodes, dtype=np.float64)
            ),
            errors=(
                np.zeros(config.train.episodes, dtype=np.float64)
                if algorithm.predicts and prediction_truth(config, env_info).measured
                else None
            ),
        )

    def policy_table(self) -> np.ndarray:
        """The table whose greedy actions are the policy (``q_table.npy``).

        ``Q`` for most algorithms; Double Q-learning's ``0.5 * (A + B)``: halving is exact in
        binary floating point, so it has the greedy actions (and ties) of ``A + B``.
        """
        return self.algorithm.policy(self.tables.q, self.tables.memory)


EVAL_CHUNK_EPISODES = 100
"""greedy episodes an evaluation plays between looks at a stop request (the first chunk is
always played, so that even a stopped run has an evaluation of its table)"""


def played_until_stopped(
    play: Callable[[int], np.ndarray],
    episodes: int,
    should_stop: Callable[[], bool] | None,
    chunk: int = EVAL_CHUNK_EPISODES,
) -> np.ndarray:
    """The returns of ``episodes`` greedy episodes, played ``chunk`` at a time.

    After each chunk, ``should_stop`` is asked; once it says so, the returns of the episodes
    played so far are returned. ``play(n)`` plays the next ``n`` episodes, continuing the
    environment's random stream, so the chunks give exactly the returns of one long call.

    >>> stream = iter(range(1000))
    >>> play = lambda n: np.array([next(stream) for _ in range(n)], dtype=float)
    >>> played_until_stopped(play, 250, lambda: True).size
    100
    >>> played_until_stopped(play, 250, None)[:3].tolist()
    [100.0, 101.0, 102.0]
    """
    parts: list[np.ndarray] = []
    played = 0
    while played < episodes:
        count = min(chunk, episodes - played)
        parts.append(play(count))
        played += count
        if should_stop is not None and played < episodes and should_stop():
            break
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.float64)


class Engine(Protocol):
    """Drives an environment around the shared compiled step functions."""

    name: str
    """``numba`` or ``gymnasium``, as recorded in ``summary.json``"""
    chunk_episodes: int
    """episodes per :meth:`run` call that keep progress and Ctrl-C responsive"""

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes ``state.episode .. stop - 1``, advancing ``state``.

        When ``check_solved``, return right after the first episode whose moving average
        reaches the threshold, giving its 0-based index; else return ``None``.
        """
        ...

    def evaluate(
        self,
        q: np.ndarray,
        episodes: int,
        seed: int,
        should_stop: Callable[[], bool] | None = None,
    ) -> np.ndarray:
        """Return the greedy policy's returns over ``episodes`` episodes from ``seed``.

        With ``should_stop``, fewer when it asks to stop: the episodes played before
        (see :func:`played_until_stopped`).
        """
        ...

    def warm_up(self, state: TrainingState) -> None:
        """Compile (or load from the cache) the compiled code, so that timing excludes it.

        Touches neither the state's arrays nor its generator's stream.
        """
        ...

    def env_rng_state(self) -> dict[str, Any]:
        """Return the training environment's random generator state (for checkpoints)."""
        ...

    def close(self) -> None:
        """Release the environment."""
        ...
