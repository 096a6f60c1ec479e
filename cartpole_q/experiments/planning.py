"""Dynamic programming studies (``cartpole-q dp``): a study file, its sweeps, its figure.

A study file names a world with an exact model, an algorithm of chapter 4 (policy
evaluation, value iteration, policy iteration) and its settings, the figure to draw, and
the book's numbers to print beside ours. :func:`run_study` runs it (pure NumPy, see
:mod:`cartpole_q.rl.solvers`); :func:`write_study` writes the figure with its
data (``<figure>.csv``) and every recorded sweep and policy (``<figure>_sweeps.csv``).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, EnvConfig, load_config, read_yaml_mapping, shown_value
from cartpole_q.config.bounds import check_count, check_memory
from cartpole_q.envs.models import PlanningModel, planning_model
from cartpole_q.experiments.study import Finished, RunHandle, RunsKind, StudyFile, register_kind
from cartpole_q.experiments.sweep_spec import (
    check_top_keys,
    checked_figure_section,
    checked_list,
    checked_study,
)
from cartpole_q.progress import Units
from cartpole_q.rl import solvers as dp
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = (
    "name", "env", "algorithm", "gamma", "policy", "sweeps", "tolerance", "max_sweeps",
    "tie_tolerance", "figure", "book",
)  # fmt: skip
"""the keys a study file may have"""
ALGORITHMS = ("policy_evaluation", "value_iteration", "policy_iteration")
FIGURE_KINDS = ("grid", "gambler", "car_rental")
FIGURE_KEYS = ("kind", "file", "title", "show", "greedy", "decimals")
BOOK_KEYS = ("label", "value", "state", "of", "sweep", "decimals")
BOOK_OF = ("value", "min", "max", "action", "sweeps", "improvements")
"""what a ``book`` entry compares: a state's value or action, the values' extremes, counts"""
SWEEPS_SUFFIX = "_sweeps.csv"
MAX_SWEEPS = 1_000_000
"""the most sweeps a study may make (every sweep's values are recorded)"""


@dataclass(frozen=True)
class FigureSpec:
    """A study's figure."""

    kind: str
    """``grid`` (values in cells, greedy arrows), ``gambler`` (Figure 4.3), ``car_rental``
    (Figure 4.2)"""
    file: str
    """its default file name (``--out`` overrides it)"""
    title: str
    show: tuple[int, ...]
    """the sweeps drawn before the last (``grid``, ``gambler``)"""
    greedy: bool
    """``grid``: draw the greedy policy below each values panel"""
    decimals: int
    """``grid``: the decimals of the values written in the cells"""


@dataclass(frozen=True)
class BookNumber:
    """A number the book prints, compared with ours."""

    label: str
    value: float
    decimals: int
    """ours is rounded to these, halves upwards, as the book prints"""
    of: str
    """one of :data:`BOOK_OF`"""
    state: int | None
    step: int | None
    """the sweep (policy iteration: the policy) compared; ``None``: the last"""


@dataclass(frozen=True)
class Study:
    """A checked study file."""

    name: str
    env: EnvConfig
    algorithm: str
    gamma: float
    policy: str | int
    """``random`` (uniform over the allowed actions) or an action taken everywhere"""
    order: str
    tolerance: float
    max_sweeps: int
    tie_tolerance: float
    figure: FigureSpec
    book: tuple[BookNumber, ...]
    where: str
    """the file, for messages"""


@dataclass(frozen=True)
class Outcome:
    """What a study computed."""

    world: PlanningModel
    values: np.ndarray
    """``(steps + 1, S)``: after each sweep, or (policy iteration) of each policy"""
    policies: np.ndarray
    """``(steps + 1, S)``: the greedy policy of each row of ``values`` (policy iteration:
    each policy)"""
    tied: np.ndarray
    """``(steps + 1, S, A)``: the tied best actions of each row of ``values``"""
    steps: int
    """sweeps made (policy iteration: improvements)"""


@dataclass(frozen=True)
class BookRow:
    """One line of the comparison: the book's number and ours."""

    label: str
    book: float
    ours: float
    exact: float
    decimals: int

    @property
    def agrees(self) -> bool:
        """Ours, rounded as the book prints, is the book's number."""
        return math.isclose(self.ours, self.book, abs_tol=0.5 * 10.0 ** (-self.decimals - 3))

    def text(self) -> str:
        """``v_pi(A): book 8.8, ours 8.8 (8.78930)``."""
        same = "same" if self.agrees else "differs"
        return (
            f"{self.label}: book {self.book:.{self.decimals}f}, ours {self.ours:.{self.decimals}f} "
            f"({self.exact:.6g}; {same})"
        )


def _number(raw: Mapping[str, Any], key: str, default: float, where: str) -> float:
    value = raw.get(key, default)
    if isinstance(value, str):  # YAML reads 1e-10 as a string
        with contextlib.suppress(ValueError):
            value = float(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}: {key}: must be a number, got {shown_value(value)}.")
    return float(value)


def _integer(raw: Mapping[str, Any], key: str, default: int | None, where: str) -> int | None:
    value = raw.get(key, default)
    if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
        raise ConfigError(f"{where}: {key}: must be a whole number >= 0, got {shown_value(value)}.")
    return value


def _decimals_of(value: Any) -> int:
    """The decimals a number is written with in the study file (``8.8``: 1, ``-14``: 0)."""
    if isinstance(value, int):
        return 0
    text = repr(float(value))
    return 0 if "e" in text else len(text.partition(".")[2])


def load_study(path: Path) -> Study:
    """Read and check a dynamic-programming study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw = read_yaml_mapping(path, "study file")
    return read_study(StudyFile(raw, "dp", str(path), path.stem, path.parent))


def read_study(study: StudyFile) -> Study:
    """Check a dynamic-programming study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(
        study,
        STUDY_KEYS,
        "`env`, `algorithm`, `gamma` and `figure`",
        "examples/book/fig4_1_small_gridworld.yaml",
    )
    env_raw = raw.get("env")
    if not isinstance(env_raw, Mapping) or "id" not in env_raw:
        raise ConfigError(
            f"{where}: env: must be a mapping with an id, such as "
            f"{{id: cartpole_q/SmallGridworld-v0}}, got {shown_value(env_raw)}."
        )
    env = load_config({"env": dict(env_raw)}, source=f"{where}").env
    algorithm = raw.get("algorithm")
    if algorithm not in ALGORITHMS:
        raise ConfigError(
            f"{where}: algorithm: must be one of {', '.join(ALGORITHMS)}, got "
            f"{shown_value(algorithm)}."
        )
    if "gamma" not in raw:
        raise ConfigError(f"{where}: gamma: is missing; the discount, in [0, 1].")
    gamma = _number(raw, "gamma", 0.0, where)
    if not 0.0 <= gamma <= 1.0:
        raise ConfigError(f"{where}: gamma: must be a number in [0, 1], got {gamma:g}.")
    policy = raw.get("policy", "random")
    if policy != "random" and (
        isinstance(policy, bool) or not isinstance(policy, int) or policy < 0
    ):
        raise ConfigError(
            f"{where}: policy: must be random or an action (a whole number) taken in every "
            f"state, got {shown_value(policy)}."
        )
    if algorithm == "policy_iteration" and policy == "random":
        raise ConfigError(
            f"{where}: policy: policy iteration starts from a deterministic policy: give the "
            "action it takes in every state (Jack's car rental: 5, no car moved)."
        )
    order = raw.get("sweeps", "synchronous")
    if order not in dp.SWEEP_ORDERS:
        raise ConfigError(
            f"{where}: sweeps: must be one of {', '.join(dp.SWEEP_ORDERS)}, got {shown_value(order)}."
        )
    tolerance = _number(raw, "tolerance", 1e-10, where)
    tie_tolerance = _number(raw, "tie_tolerance", 1e-9, where)
    if tolerance <= 0:
        raise ConfigError(f"{where}: tolerance: must be positive, got {tolerance:g}.")
    if tie_tolerance < 0:
        raise ConfigError(f"{where}: tie_tolerance: must not be negative, got {tie_tolerance:g}.")
    max_sweeps = raw.get("max_sweeps", 100_000)
    if isinstance(max_sweeps, bool) or not isinstance(max_sweeps, int) or max_sweeps < 1:
        raise ConfigError(
            f"{where}: max_sweeps: must be a whole number >= 1, got {shown_value(max_sweeps)}."
        )
    check_count(where, "max_sweeps", max_sweeps, MAX_SWEEPS, "each sweep's values are kept")
    if algorithm == "value_iteration" and "policy" in raw:
        raise ConfigError(
            f"{where}: policy: value iteration starts from v = 0 and follows no policy; leave "
            "policy out (policy evaluation and policy iteration take one)."
        )
    figure = _figure(raw.get("figure"), name, where)
    late = [k for k in figure.show if k > max_sweeps]
    if late:
        raise ConfigError(
            f"{where}: figure.show: sweep {late[0]:,} is beyond max_sweeps ({max_sweeps:,}); "
            "show sweeps the study can make."
        )
    book = tuple(
        _book(entry, index, where) for index, entry in enumerate(checked_list(raw, "book", where))
    )
    checked = Study(
        name, env, str(algorithm), gamma, policy, str(order), tolerance, max_sweeps,
        tie_tolerance, figure, book, where,
    )  # fmt: skip
    world = _model(checked)
    _check_fits(checked, world)
    states, actions = world.model.n_states, world.model.n_actions
    # every sweep's values and greedy policy (8 bytes each) and tied actions (1 byte each)
    check_memory(where, "max_sweeps", (max_sweeps + 1) * states * (16 + actions),
                 f"{max_sweeps:,} recorded sweeps of {states:,} states")  # fmt: skip
    return checked


def _model(study: Study) -> PlanningModel:
    """The world's model.

    Raises:
        ConfigError: it has none, or the policy's action is not one of its actions.
    """
    world = planning_model(study.env, source=study.where)
    if isinstance(world, str):
        raise ConfigError(f"{study.where}: env.id: {world}; dynamic programming needs a model.")
    if isinstance(study.policy, int) and study.policy >= world.model.n_actions:
        raise ConfigError(
            f"{study.where}: policy: action {study.policy} does not exist ({study.env.id} has "
            f"{world.model.n_actions} actions)."
        )
    return world


def _figure(raw: Any, name: str, where: str) -> FigureSpec:
    kind, file, title = checked_figure_section(raw, name, where, FIGURE_KEYS, FIGURE_KINDS)
    show = raw.get("show", [])
    if not isinstance(show, list) or not all(
        isinstance(k, int) and not isinstance(k, bool) and k >= 0 for k in show
    ):
        raise ConfigError(
            f"{where}: figure.show: must be a list of sweep numbers (0, 1, 2, ...), got "
            f"{shown_value(show)}."
        )
    greedy = raw.get("greedy", False)
    if not isinstance(greedy, bool):
        raise ConfigError(
            f"{where}: figure.greedy: must be true or false, got {shown_value(greedy)}."
        )
    decimals = _integer(raw, "decimals", 1, f"{where}: figure") or 0
    return FigureSpec(kind, file, title, tuple(show), greedy, decimals)


def _book(raw: Any, index: int, where: str) -> BookNumber:
    here = f"{where}: book[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, value, ...}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, BOOK_KEYS, here)
    label, value = raw.get("label"), raw.get("value")
    if not isinstance(label, str) or isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{here}: needs a label (text) and the book's value (a number).")
    of = raw.get("of", "value")
    if of not in BOOK_OF:
        raise ConfigError(f"{here}.of: must be one of {', '.join(BOOK_OF)}, got {shown_value(of)}.")
    state = raw.get("state")
    if of in ("value", "action") and (
        isinstance(state, bool) or not isinstance(state, int) or state < 0
    ):
        raise ConfigError(
            f"{here}.state: {of} of a state needs its number, got {shown_value(state)}."
        )
    step = _integer(raw, "sweep", None, here)
    decimals = _integer(raw, "decimals", _decimals_of(value), here)
    return BookNumber(label, float(value), int(decimals or 0), str(of), state, step)


def run_study(study: Study) -> Outcome:
    """Run a study's algorithm on its world's model, recording every sweep.

    Raises:
        ConfigError: the world has no model, the policy's action or a state is out of
            range, or the algorithm does not converge (naming the file and the key).
    """
    world = _model(study)
    model = world.model
    _check_fits(study, world)
    try:
        if study.algorithm == "policy_iteration":
            start = np.full(model.n_states, int(study.policy), dtype=np.int64)
            found = dp.policy_iteration(model, study.gamma, start, study.tie_tolerance)
            values, policies = found.values, found.policies
            steps = found.improvements
        else:
            if study.algorithm == "value_iteration":
                sweeps = dp.value_iteration_sweeps(
                    model, study.gamma, study.tolerance, study.max_sweeps, study.order
                )
            else:
                pi = (
                    dp.uniform_policy(model)
                    if study.policy == "random"
                    else dp.deterministic_policy(
                        np.full(model.n_states, int(study.policy)), model.n_actions
                    )
                )
                sweeps = dp.evaluate_sweeps(
                    model, pi, study.gamma, study.tolerance, study.max_sweeps, study.order
                )
            values, steps = sweeps.values, sweeps.sweeps
            policies = np.array([dp.greedy(model.backup(v, study.gamma), model.allowed,
                                           study.tie_tolerance) for v in values])  # fmt: skip
    except ValueError as error:
        hint = "; raise max_sweeps, or the tolerance" if "converge" in str(error) else ""
        raise ConfigError(f"{study.where}: {error}{hint}.") from None
    tied = np.array(
        [
            dp.tied_best(model.backup(v, study.gamma), model.allowed, study.tie_tolerance)
            for v in values
        ]
    )
    return Outcome(world, values, policies, tied, steps)


def _check_fits(study: Study, world: PlanningModel) -> None:
    """The figure's kind fits the world and the algorithm; the book's states exist."""
    kind, where = study.figure.kind, study.where
    if kind == "grid" and world.shape is None:
        raise ConfigError(
            f"{where}: figure.kind: grid needs a grid world; {study.env.id} is not one."
        )
    if kind == "car_rental" and (
        study.algorithm != "policy_iteration"
        or math.isqrt(world.model.n_states) ** 2 != world.model.n_states
    ):
        raise ConfigError(
            f"{where}: figure.kind: car_rental draws policy iteration on a square of states "
            "(cars at two locations)."
        )
    if kind == "gambler" and study.algorithm == "policy_iteration":
        raise ConfigError(f"{where}: figure.kind: gambler draws sweeps, not policy iteration.")
    if kind == "gambler" and not _is_gambler(world):
        raise ConfigError(
            f"{where}: figure.kind: gambler draws a capital's value and stake (Figure 4.3); "
            f"{study.env.id} is not the gambler's problem (cartpole_q/Gambler-v0)."
        )
    for index, number in enumerate(study.book):
        if number.state is not None and number.state >= world.model.n_states:
            raise ConfigError(
                f"{where}: book[{index}].state: {number.state} is not a state of {study.env.id} "
                f"(0 to {world.model.n_states - 1})."
            )


def _is_gambler(world: PlanningModel) -> bool:
    """A world whose states are capitals 0..goal and whose actions are stakes 0..goal/2."""
    states, stakes = world.model.n_states, world.action_values
    return (
        states >= 3
        and stakes == tuple(float(s) for s in range(len(stakes)))
        and (len(stakes) == (states - 1) // 2 + 1)
    )


def book_rows(study: Study, outcome: Outcome) -> list[BookRow]:
    """The book's numbers beside ours, rounded as the book prints them.

    Raises:
        ConfigError: a ``sweep`` beyond those made.
    """
    from cartpole_q.figures import book_round

    rows = []
    for index, number in enumerate(study.book):
        step = outcome.steps if number.step is None else number.step
        if step > outcome.steps:
            raise ConfigError(
                f"{study.where}: book[{index}].sweep: {step}, but the study made only "
                f"{outcome.steps}."
            )
        values = outcome.values[step]
        if number.of == "value":
            exact = float(values[number.state])
        elif number.of == "action":
            exact = outcome.world.action_values[int(outcome.policies[step][number.state])]
        elif number.of == "min":
            exact = float(values.min())
        elif number.of == "max":
            exact = float(values.max())
        else:  # sweeps or improvements: how many were made
            exact = float(outcome.steps)
        rows.append(BookRow(number.label, number.value, book_round(exact, number.decimals),
                            exact, number.decimals))  # fmt: skip
    return rows


def summary(study: Study, outcome: Outcome) -> str:
    """One line: what ran, on what, and how long it took to converge."""
    if study.policy == "random":
        policy = "the random policy"
    else:
        meaning = _meanings(outcome.world)[int(study.policy)]
        policy = f"action {study.policy} ({meaning}) in every state"
    what = {
        "policy_evaluation": f"policy evaluation of {policy}",
        "value_iteration": "value iteration",
        "policy_iteration": f"policy iteration from {policy}",
    }[study.algorithm]
    if study.algorithm == "policy_iteration":
        done = f"policy stable after {outcome.steps} improvements (each policy evaluated exactly)"
    else:
        done = (
            f"{outcome.steps} {study.order.replace('_', '-')} sweeps (the last changed no value by "
            f"{study.tolerance:g} or more)"
        )
    return f"{study.name}: {what} on {study.env.id}, gamma {study.gamma:g}: {done}"


def study_figure(study: Study, outcome: Outcome) -> Any:
    """The study's figure (a :class:`~cartpole_q.figures.DataFigure`)."""
    from cartpole_q import figures

    world, spec = outcome.world, study.figure
    last = outcome.steps
    if spec.kind == "grid":
        assert world.shape is not None  # checked by run_study
        ends = world.model.terminal_states()
        steps = [k for k in spec.show if k < last] + [last]
        symbol = "pi" if study.algorithm == "policy_evaluation" else "*"
        names = [_move_name(move) for move in world.moves]
        values_panels, policy_panels = [], []
        for k in steps:
            final = k == last
            if study.algorithm == "policy_evaluation":
                name = f"v_pi (k = ∞: {k} sweeps)" if final else f"v_k, k = {k}"
            else:
                name = f"v{symbol}" if final else f"v_k, k = {k}"
            values_panels.append(
                figures.GridPanel(
                    name,
                    world.shape,
                    values=outcome.values[k].reshape(world.shape),
                    ends=ends,
                    labels=world.labels,
                )
            )
            if spec.greedy:
                greedy = f"greedy w.r.t. v_{'pi' if final else f'k, k = {k}'}"
                if study.algorithm == "value_iteration" and final:
                    greedy = "pi*"
                policy_panels.append(
                    figures.GridPanel(greedy, world.shape, tied=outcome.tied[k], ends=ends)
                )
        return figures.dp_grid_figure(
            values_panels + policy_panels, world.moves, names, spec.title, spec.decimals,
            columns=len(values_panels),
        )  # fmt: skip
    if spec.kind == "gambler":
        inner = slice(1, world.model.n_states - 1)
        steps = [k for k in spec.show if k < last] + [last]
        curves = [(f"sweep {k}", outcome.values[k][inner]) for k in steps]
        stakes = _meanings(world)[outcome.policies[last][inner]]
        return figures.gambler_figure(curves, stakes, spec.title)
    size = math.isqrt(world.model.n_states)
    moves = _meanings(world)
    policies = [moves[policy].reshape(size, size) for policy in outcome.policies]
    value = outcome.values[last].reshape(size, size)
    return figures.car_rental_figure(policies, value, spec.title, f"v_pi{last}")


def _meanings(world: PlanningModel) -> np.ndarray:
    """Each action's meaning (a stake, cars moved), as integers when they are whole."""
    meanings = np.array(world.action_values)
    whole = np.all(meanings == np.round(meanings))
    return meanings.astype(np.int64) if whole else meanings


def _move_name(move: tuple[int, int]) -> str:
    return {(-1, 0): "up", (1, 0): "down", (0, -1): "left", (0, 1): "right"}.get(move, str(move))


def sweeps_csv_text(outcome: Outcome) -> str:
    """Every recorded row: ``record,step,state,value`` (``values`` and ``policy`` records).

    A ``values`` row is a state's value after sweep ``step`` (policy iteration: of policy
    ``step``); a ``policy`` row the greedy action's meaning (a stake, cars moved; else its
    number) with those values (policy iteration: policy ``step`` itself).
    """
    lines = ["record,step,state,value"]
    meaning = np.array(outcome.world.action_values)
    for step, (values, policy) in enumerate(zip(outcome.values, outcome.policies, strict=True)):
        lines.extend(f"values,{step},{state},{float(v)!r}" for state, v in enumerate(values))
        lines.extend(f"policy,{step},{state},{_cell(meaning[a])}" for state, a in enumerate(policy))
    return "\n".join(lines) + "\n"


def _cell(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def sweeps_path(figure_path: Path) -> Path:
    """Where the recorded sweeps go: ``<figure>_sweeps.csv`` beside the figure."""
    return figure_path.with_name(figure_path.stem + SWEEPS_SUFFIX)


def write_study(study: Study, outcome: Outcome, out: Path) -> tuple[Path, Path]:
    """Write the figure (with its data) and the recorded sweeps.

    Returns:
        The figure's path and the sweeps' path.
    """
    from cartpole_q.store.atomic import atomic_write_text
    from cartpole_q.store.figure_file import write_figure

    figure = study_figure(study, outcome)
    write_figure(out, figure)
    sweeps = sweeps_path(out)
    atomic_write_text(sweeps, sweeps_csv_text(outcome))
    return out, sweeps


def check_outputs(out: Path, force: bool) -> None:
    """Refuse, before any work, outputs that exist (without ``force``) or cannot be written."""
    from cartpole_q.store.atomic import check_output_file
    from cartpole_q.store.figure_file import check_figure_file

    check_figure_file(out, "--out", force)
    check_output_file(sweeps_path(out), "--out (its _sweeps.csv)", (".csv",), force)


def default_out(study: Study) -> Path:
    """The figure file when ``--out`` is not given: the study's ``figure.file`` here."""
    return Path(study.figure.file)


class PlanningKind(RunsKind):
    """``kind: dp``: one run, the algorithm on the world's model, every sweep recorded."""

    name = "dp"
    figure_kinds = FIGURE_KINDS
    units = Units("dp", "solves", "solves")

    def read(self, study: StudyFile) -> Study:
        """Check the file (:func:`read_study`)."""
        return read_study(study)

    def runs(self, spec: Study) -> list[dict[str, Cell]]:
        """One run: the algorithm."""
        return [{"algorithm": spec.algorithm}]

    def describe(self, spec: Study) -> tuple[int, str]:
        """One solve."""
        what = spec.algorithm.replace("_", " ")
        return 1, f"a dp study: {what} on {spec.env.id}, gamma {spec.gamma:g} (one run)"

    def result_columns(self, spec: Study) -> tuple[str, ...]:
        """Sweeps (policy iteration: improvements) made."""
        return ("steps",)

    def run_one(self, spec: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
        """Solve: every sweep's values, greedy policies and tied actions."""
        outcome = run_study(spec)
        book_rows(spec, outcome)  # a book number at a sweep never made: refused before saving
        return RunRecord(
            {"steps": outcome.steps},
            {"values": outcome.values, "policies": outcome.policies, "tied": outcome.tied},
        )

    def finish(
        self, spec: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
    ) -> Finished:
        """The figure, the recorded sweeps, the summary and the book's numbers beside ours."""
        (record,) = records
        world = planning_model(spec.env, source=spec.where)
        assert not isinstance(world, str)  # run_one solved it
        arrays = record.arrays
        outcome = Outcome(
            world,
            arrays["values"],
            arrays["policies"],
            arrays["tied"],
            int(record.row["steps"] or 0),
        )
        lines = [summary(spec, outcome)]
        beyond = [k for k in spec.figure.show if k > outcome.steps]
        if beyond:
            lines.append(
                f"  figure.show: {', '.join(map(str, beyond))} not drawn: the study made "
                f"{outcome.steps} {'improvements' if spec.algorithm == 'policy_iteration' else 'sweeps'}"
            )
        rows = book_rows(spec, outcome)
        if rows:
            lines.append("the book's numbers and ours (rounded as the book prints them):")
            lines.extend(f"  {row.text()}" for row in rows)
        sweeps = sweeps_path(Path(spec.figure.file)).name
        return Finished(
            [(spec.figure.file, study_figure(spec, outcome))],
            [(sweeps, sweeps_csv_text(outcome))],
            lines,
        )


PLANNING = register_kind(PlanningKind())
"""the dynamic-programming kind (registered)"""
