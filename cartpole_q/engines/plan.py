"""A run planned once: the config, its environment's facts, its engine and its twin.

Checking a config against its environment makes and resets a real Gymnasium environment
(:func:`~cartpole_q.envs.gym.inspect_env`), and choosing the engine reads the twin's
settings (:func:`~cartpole_q.envs.registry.twin_settings`). :func:`plan_run` does both once;
every consumer downstream (training, the engines, multi-seed runs, the command line's
compile notice) takes the :class:`Plan` instead of deriving its parts again. Inside a
:func:`planning` scope (a command), plans and environment facts are kept and shared.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cartpole_q.config import Config, Provenance
from cartpole_q.envs.gym import EnvInfo, inspect_env, inspected_fields

if TYPE_CHECKING:  # the registry loads when an engine is made
    from cartpole_q.envs.registry import TwinSettings


@dataclass(frozen=True)
class Plan:
    """A checked config with its environment's facts, its engine and its twin, ready to train."""

    config: Config
    env_info: EnvInfo
    """the environment's facts, checked against the config"""
    engine: str
    """the engine that runs it: ``numba`` or ``gymnasium`` (``auto`` resolved)"""
    source: str
    """the config's file (or another label), for messages"""
    twin: TwinSettings | None = None
    """the twin's settings, for the numba engine (``None`` on the gymnasium engine)"""

    def for_seed(self, seed: int) -> Plan:
        """The same plan for one seed of a multi-seed run (the facts do not depend on it)."""
        return dataclasses.replace(self, config=self.config.for_seed(seed))

    def parts(self) -> tuple[dict[str, Any], EnvInfo, str, str, TwinSettings | None]:
        """The plan as it travels to a worker process: a config does not pickle, its mapping does."""
        return self.config.to_dict(), self.env_info, self.engine, self.source, self.twin

    @classmethod
    def from_parts(
        cls, parts: tuple[dict[str, Any], EnvInfo, str, str, TwinSettings | None]
    ) -> Plan:
        """The plan :meth:`parts` sent, in a worker: its config read again, nothing inspected."""
        from cartpole_q.config import load_config

        mapping, env_info, engine, source, twin = parts
        return cls(load_config(mapping), env_info, engine, source, twin)

    def precompile(self, greedy_loop: bool | None = None) -> None:
        """Compile (or load from the cache) what training this plan runs.

        Nothing is trained: the loops are compiled on a fresh state, as a run's warm-up
        does; ``greedy_loop`` as :func:`~cartpole_q.engines.make_engine` takes it
        (``True``: the greedy loop as well, wherever the run's epsilon reaches 0).
        """
        import numpy as np

        from cartpole_q.engines import make_engine
        from cartpole_q.engines.base import TrainingState

        state = TrainingState.fresh(self.config, self.env_info, np.random.default_rng(0))
        made = make_engine(
            self.engine, self.config, self.env_info, env_seed=0, twin=self.twin,
            greedy_loop=greedy_loop,
        )  # fmt: skip
        try:
            made.warm_up(state)
        finally:
            made.close()

    def loop_names(self) -> tuple[str, ...]:
        """The compiled loops the run calls, as numba's cache names them."""
        from cartpole_q.engines import loop_names

        return loop_names(self.config, self.env_info, self.engine, self.twin)


def plan_run(
    config: Config,
    source: str | Provenance = "config",
    env_info: EnvInfo | None = None,
    engine: str | None = None,
) -> Plan:
    """Check a config against its environment and pick its engine (no files touched).

    Args:
        config: a validated config.
        source: the config's file (or another label), for error messages.
        env_info: the environment's facts, when the caller has already checked them
            (otherwise :func:`env_facts`: inspected, or the planning scope's).
        engine: the engine that runs it when it is not to be chosen: a resumed run's, its
            checkpoint's (the plan then has no twin settings: the engine finds them).

    Raises:
        ConfigError: the config does not fit its environment or engine.
    """
    from cartpole_q.engines import check_prediction, engine_and_twin

    if env_info is None:
        env_info = env_facts(config, source)
    if engine is not None:
        return Plan(config, env_info, engine, str(source))
    engine, twin = engine_and_twin(config, env_info, source)
    check_prediction(config, env_info)
    return Plan(config, env_info, engine, str(source), twin)


MOST_KEPT = 64
"""plans kept at most (a study of many trials keeps its latest)"""

_KEPT: dict[str, Plan] = {}
"""the plans of the planning scope, by their config but its seed (see :func:`planned`)"""
_FACTS: dict[str, EnvInfo] = {}
"""the environment facts of the planning scope, by what :func:`inspect_env` reads"""
_SCOPES = [0]
"""how many :func:`planning` scopes are open in this process (a forked worker inherits
its parent's, and the plans and facts kept in them)"""


@contextlib.contextmanager
def planning() -> Iterator[None]:
    """A scope (a command, a study) inside which plans and facts are kept and shared.

    Inside it, :func:`planned` and :func:`env_facts` plan a config and inspect its
    environment once, however many runs ask; when the outermost scope closes, everything
    is forgotten. Outside any scope nothing is kept (an environment may be registered anew
    between two calls of a long-lived program), and they plan and inspect each time. The
    command line opens one per command; forked workers inherit it.
    """
    _SCOPES[0] += 1
    try:
        yield
    finally:
        _SCOPES[0] -= 1
        if _SCOPES[0] == 0:
            _KEPT.clear()
            _FACTS.clear()


def _plan_key(config: Config) -> str:
    """What the configs that share a plan share: everything but the seed."""
    return repr(config.for_seed(0).to_dict())


def planned(config: Config, source: str | Provenance = "config") -> Plan:
    """The plan of ``config``, made once per planning scope for the configs that share it.

    A study runs one config on many seeds, often in the same process (or in workers it
    forks, which inherit its plans): inside a :func:`planning` scope they share a plan,
    made by :func:`plan_run` the first time and kept, so that the environment is inspected
    once per study, not once per run. Configs that differ in more than their seed have
    plans of their own, but share the environment's facts (:func:`env_facts`).

    Raises:
        ConfigError: the config does not fit its environment or engine (nothing is kept).
    """
    if not _SCOPES[0]:
        return plan_run(config, source)
    key = _plan_key(config)
    plan = _KEPT.get(key)
    if plan is None:
        plan = plan_run(config, source)
        _keep(key, plan)
    return dataclasses.replace(plan, config=config)


def env_facts(config: Config, source: str | Provenance = "config") -> EnvInfo:
    """The environment's facts for ``config``, inspected once per planning scope.

    Configs that agree in what :func:`~cartpole_q.envs.gym.inspect_env` reads (the
    environment, the grid, the table's size limit, the info metric and the threshold:
    :func:`~cartpole_q.envs.gym.inspected_fields`) share them inside a :func:`planning`
    scope; outside one, this inspects the environment each time.

    Raises:
        ConfigError: the config does not fit its environment (nothing is kept).
    """
    key = inspected_fields(config) if _SCOPES[0] else None
    facts = None if key is None else _FACTS.get(key)
    if facts is None:
        facts = inspect_env(config, source)
        if key is not None:
            _FACTS[key] = facts
    return facts


def keep_plan(plan: Plan) -> None:
    """Keep ``plan`` for the scope's runs of its config on any seed (see :func:`planned`).

    Outside a :func:`planning` scope nothing is kept.
    """
    if _SCOPES[0]:
        _keep(_plan_key(plan.config), plan)
        _FACTS[inspected_fields(plan.config)] = plan.env_info


def _keep(key: str, plan: Plan) -> None:
    """Keep a plan, forgetting the oldest beyond :data:`MOST_KEPT`."""
    _KEPT[key] = plan
    while len(_KEPT) > MOST_KEPT:
        del _KEPT[next(iter(_KEPT))]
