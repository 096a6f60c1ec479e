"""A run planned once: the config, its environment's facts, its engine and its twin.

Checking a config against its environment makes and resets a real Gymnasium environment
(:func:`~cartpole_q.envs.gym.inspect_env`), and choosing the engine reads the twin's
settings (:func:`~cartpole_q.envs.registry.twin_settings`). :func:`plan_run` does both once;
every consumer downstream (training, the engines, multi-seed runs, the command line's
compile notice) takes the :class:`Plan` instead of deriving its parts again.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

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

    def with_config(self, config: Config) -> Plan:
        """The plan of ``config``, a config of the same environment, engine and twin.

        For the seeds of a multi-seed run, which differ from each other only by their seed.
        """
        return dataclasses.replace(self, config=config)

    def loop_names(self) -> tuple[str, ...]:
        """The compiled loops the run calls, as numba's cache names them."""
        from cartpole_q.engines import loop_names

        return loop_names(self.config, self.env_info, self.engine, self.twin)


def plan_run(
    config: Config, source: str | Provenance = "config", env_info: EnvInfo | None = None
) -> Plan:
    """Check a config against its environment and pick its engine (no files touched).

    Args:
        config: a validated config.
        source: the config's file (or another label), for error messages.
        env_info: the environment's facts, when the caller has already checked them.

    Raises:
        ConfigError: the config does not fit its environment or engine.
    """
    from cartpole_q.engines import check_prediction, engine_and_twin

    if env_info is None:
        env_info = inspect_env(config, source)
    engine, twin = engine_and_twin(config, env_info, source)
    check_prediction(config, env_info)
    return Plan(config, env_info, engine, str(source), twin)


_KEPT: dict[str, Plan] = {}
"""this process's plans, by their config but its seed (see :func:`planned`)"""
_FACTS: dict[str, EnvInfo] = {}
"""the environment facts of those plans, by what :func:`inspect_env` reads of a config"""


def _plan_key(config: Config) -> str:
    """What the configs that share a plan share: everything but the seed."""
    return repr(config.for_seed(0).to_dict())


def planned(config: Config, source: str | Provenance = "config") -> Plan:
    """The plan of ``config``, made once per process for all the configs that share it.

    A study runs one config on many seeds, often in the same process (or in workers it
    forks, which inherit its plans): they share a plan, made by :func:`plan_run` the first
    time and kept, so that the environment is inspected once per study, not once per run.
    Configs that differ in more than their seed have plans of their own, but share the
    environment's facts where :func:`~cartpole_q.envs.gym.inspect_env` reads the same
    (a sweep over ``agent.alpha``).

    Raises:
        ConfigError: the config does not fit its environment or engine (nothing is kept).
    """
    key = _plan_key(config)
    plan = _KEPT.get(key)
    if plan is None:
        plan = _KEPT[key] = plan_run(config, source, env_facts(config, source))
    return plan.with_config(config)


def env_facts(config: Config, source: str | Provenance = "config") -> EnvInfo:
    """The environment's facts for ``config``, inspected once per process and command.

    Configs that agree in what :func:`~cartpole_q.envs.gym.inspect_env` reads (the
    environment, the grid, the table's size limit, the info metric and the threshold)
    share them; a command forgets them when it starts (:func:`forget_plans`).

    Raises:
        ConfigError: the config does not fit its environment (nothing is kept).
    """
    key = inspected_fields(config)
    facts = _FACTS.get(key)
    if facts is None:
        facts = _FACTS[key] = inspect_env(config, source)
    return facts


def keep_plan(plan: Plan) -> None:
    """Keep ``plan`` for this process's runs of its config on any seed (see :func:`planned`)."""
    _KEPT[_plan_key(plan.config)] = plan
    _FACTS[inspected_fields(plan.config)] = plan.env_info


def forget_plans() -> None:
    """Forget the kept plans and facts: a command starts afresh.

    Between commands of one process an environment may have been registered anew, or a
    world's file changed; the command line's commands call this as they start.
    """
    _KEPT.clear()
    _FACTS.clear()
