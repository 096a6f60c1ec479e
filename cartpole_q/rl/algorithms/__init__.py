"""The registry of algorithms: the package's, and any a user registers.

Each algorithm is one module here building an :class:`~cartpole_q.rl.algorithm.Algorithm`
(its name, config keys, memory and hooks); :data:`PACKAGE` lists them in the order the
documentation shows. A user's algorithm, from a module anywhere, is one :func:`register`
call away from every command: configs accept its name and parameters, both engines train
it, checkpoints keep its memory.
"""

from __future__ import annotations

import hashlib
import inspect
import types
import warnings
from collections.abc import Iterator
from typing import Any

from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.algorithms import (
    actor_critic,
    batch_prediction,
    double_q_learning,
    dyna_q,
    dyna_q_plus,
    expected_sarsa,
    mc_prediction,
    monte_carlo,
    monte_carlo_es,
    n_step_sarsa,
    n_step_td,
    n_step_tree_backup,
    off_policy_mc_prediction,
    off_policy_monte_carlo,
    offline_lambda_return,
    prioritized_sweeping,
    q_learning,
    sarsa,
    sarsa_lambda,
    td,
    td_lambda,
    true_online_sarsa_lambda,
    true_online_td_lambda,
    watkins_q_lambda,
)
from cartpole_q.rl.tabular import Memory, Params, Rates, Rng, Table, Transition, compilable

PACKAGE = (
    q_learning, sarsa, expected_sarsa, double_q_learning, n_step_sarsa, n_step_tree_backup,
    sarsa_lambda, watkins_q_lambda, true_online_sarsa_lambda, dyna_q, dyna_q_plus,
    prioritized_sweeping, monte_carlo, monte_carlo_es, off_policy_monte_carlo, actor_critic, td,
    mc_prediction, batch_prediction, off_policy_mc_prediction, n_step_td, offline_lambda_return,
    td_lambda, true_online_td_lambda,
)  # fmt: skip
"""the package's algorithm modules, in the order the documentation lists them (control,
then prediction)"""

_REGISTRY: dict[str, Algorithm] = {}

RESERVED_KEYS = frozenset(
    {
        "algorithm",
        "params",
        "gamma",
        "alpha",
        "epsilon",
        "q_init",
        "max_q_table_bytes",
        "tie_break",
        "initial_values",
    }
)
"""the keys under ``agent`` every algorithm has (the fields of ``AgentConfig``; a test keeps
the two the same): no algorithm may declare a parameter of one of these names"""


def register(algorithm: Algorithm) -> Algorithm:
    """Add an algorithm to the registry (a new name, or the same module again).

    Returns:
        The registered algorithm, its :attr:`~Algorithm.key` set.

    Raises:
        ValueError: another algorithm has this name, a parameter's name is used by a
            config key every algorithm has, or a prediction algorithm does not declare
            ``agent.policy`` first.
    """
    clash = [param.key for param in algorithm.params if param.key in RESERVED_KEYS]
    if clash:
        raise ValueError(f"algorithm {algorithm.name!r}: parameter {clash[0]!r} is a base key")
    if algorithm.predicts and [param.key for param in algorithm.params[:1]] != ["policy"]:
        # the compiled policy reads it at params[POLICY_AT] (cartpole_q.rl.prediction)
        raise ValueError(
            f"algorithm {algorithm.name!r}: a prediction algorithm declares agent.policy "
            "(cartpole_q.rl.prediction.POLICY) as its first parameter"
        )
    keyed = _named_record_hooks(_with_key(algorithm))
    existing = _REGISTRY.get(algorithm.name)
    if existing is not None and existing.step.__module__ != algorithm.step.__module__:
        raise ValueError(f"an algorithm named {algorithm.name!r} is registered already")
    _REGISTRY[algorithm.name] = keyed
    return keyed


def _with_key(algorithm: Algorithm) -> Algorithm:
    """The algorithm with its cache key: its name and a digest of its module's source."""
    from dataclasses import replace

    module = inspect.getmodule(algorithm.step)
    try:
        source = inspect.getsource(module) if module is not None else algorithm.name
    except (OSError, TypeError):
        source = algorithm.name
    digest = hashlib.sha256(source.encode()).hexdigest()[:12]
    return replace(algorithm, key=f"{algorithm.name}_{digest}")


POSITIONAL_STEP: Any = None
"""bound to a plug-in's ``step`` written for the positional hooks (see :func:`positional_step`)"""
POSITIONAL_END: Any = None
"""bound to a plug-in's ``end`` written for the positional hooks (see :func:`positional_end`)"""


def positional_step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """A ``step`` written for the positional hooks (13 arguments), called as the records' one."""
    t = transition
    return POSITIONAL_STEP(  # type: ignore[no-any-return]
        q, memory, params, t.state, t.action, t.reward, t.next_state, t.terminated,
        t.truncated, rates.alpha, rates.gamma, rates.epsilon, rng,
    )  # fmt: skip


def positional_end(q: Table, memory: Memory, params: Params, rates: Rates, rng: Rng) -> None:
    """An ``end`` written for the positional hooks (7 arguments), called as the records' one."""
    POSITIONAL_END(q, memory, params, rates.alpha, rates.gamma, rates.epsilon, rng)


POSITIONAL_ARGUMENTS = {"step": 13, "end": 7}
"""how many arguments the hooks took before they took named records (version 0.x)"""


def _named_record_hooks(algorithm: Algorithm) -> Algorithm:
    """The algorithm with hooks that take named records, adapting a plug-in's positional ones.

    Hooks take a :class:`~cartpole_q.rl.tabular.Transition` and
    :class:`~cartpole_q.rl.tabular.Rates` since 0.x; a plug-in's ``step`` (or ``end``)
    written for the 13 (7) positional arguments before still runs, through an adapter
    compiled with it (numba inlines both: nothing is lost at run time), with a
    ``FutureWarning``. The CHANGELOG says how to update one.
    """
    from dataclasses import replace

    adapted: dict[str, Any] = {}
    for hook, template, placeholder in (
        ("step", positional_step, "POSITIONAL_STEP"),
        ("end", positional_end, "POSITIONAL_END"),
    ):
        function = getattr(algorithm, hook)
        try:
            arguments = len(inspect.signature(function).parameters)
        except (TypeError, ValueError):  # (a compiled dispatcher: taken as it is)
            continue
        if arguments != POSITIONAL_ARGUMENTS[hook]:
            continue
        warnings.warn(
            f"algorithm {algorithm.name!r}: its {hook} hook takes the {arguments} positional "
            f"arguments of before; hooks now take named records ({hook}(q, memory, params, "
            f"{'transition, ' if hook == 'step' else ''}rates, rng)): see the CHANGELOG",
            FutureWarning,  # (shown by default: a plug-in is imported, never __main__)
            stacklevel=3,
        )
        namespace = {**template.__globals__, placeholder: compilable(function)}
        wrapper = types.FunctionType(template.__code__, namespace, template.__name__)
        wrapper.__module__ = function.__module__
        adapted[hook] = compilable(wrapper)
    return replace(algorithm, **adapted) if adapted else algorithm


def get(name: str) -> Algorithm:
    """The registered algorithm ``name`` (raises ``KeyError`` when there is none)."""
    return _REGISTRY[name]


def names() -> tuple[str, ...]:
    """Every registered algorithm's name: the package's first, in their order, then others."""
    return tuple(_REGISTRY)


def algorithms() -> Iterator[Algorithm]:
    """Every registered algorithm."""
    return iter(tuple(_REGISTRY.values()))


def params_of_others(name: str) -> dict[str, list[str]]:
    """Each parameter key of the other algorithms, and which algorithms have it."""
    found: dict[str, list[str]] = {}
    for algorithm in algorithms():
        if algorithm.name != name:
            for param in algorithm.params:
                found.setdefault(param.key, []).append(algorithm.name)
    return found


for _module in PACKAGE:
    register(_module.ALGORITHM)
