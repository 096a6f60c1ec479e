"""``cartpole-q compile``: fill numba's cache ahead of time, for CI images and classrooms.

A first run compiles its training loop for several seconds, once per machine and version.
This compiles the loops of a config (the embedded default's, or any), or with ``every`` the
loops of every registered algorithm on every environment with a compiled twin and on the
gymnasium engine, spread over worker processes; later runs load
them from the cache in a fraction of a second.

Studies use :func:`compile_ahead`: before their runs start, each distinct loop they will run
and the cache lacks is compiled once, the loops side by side on the workers. Without it every
worker compiles each loop it meets: on a cold cache two workers starting the same point
both compile it, and a study of several algorithms compiles each of them once per worker.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cartpole_q.config import Config, load_config
from cartpole_q.experiments.workers import JobHandle, default_workers, execute
from cartpole_q.rl.algorithms import names as algorithm_names

if TYPE_CHECKING:
    from cartpole_q.engines.plan import Plan

ENGINE_CONFIGS = {
    "numba": ("default", "mountaincar", "acrobot", "frozenlake", "taxi", "blackjack"),
    "gymnasium": ("default",),
}
"""shipped configs that cover every twin (numba: CartPole, MountainCar, Acrobot, the
transition-table twin of FrozenLake and CliffWalking, Taxi, Blackjack) and the gymnasium
engine (whose step functions take every observation but tiles' as float64 values: one
world covers them all)"""


STUDY = "study"
"""the ``engine`` of a job that compiles a study's loop (:data:`STUDY_LOOPS`)"""
SKIPPED = "skipped"
"""how the line of a job that could not run its config starts"""


@dataclass(frozen=True)
class CompileJob:
    """One config on one engine."""

    config: str
    """a shipped config's name (empty: the config given)"""
    algorithm: str
    engine: str
    label: str
    """what it trains on, for messages"""

    def describe(self) -> str:
        """``q_learning on CartPole-v1 (numba engine)``."""
        return f"{self.algorithm} on {self.label} ({self.engine} engine)"


STUDY_LOOPS: dict[str, tuple[str, Callable[[], None]]] = {
    "bandit_numba": ("the bandit testbed", lambda: _bandit("numba")),
    "bandit_gymnasium": ("the bandit testbed", lambda: _bandit("gymnasium")),
    "linear": ("the linear methods (both engines)", lambda: _linear()),
    "policy_gradient": ("the policy-gradient methods (both engines)", lambda: _policy_gradient()),
    "average_reward": ("the average-reward methods (both engines)", lambda: _average_reward()),
}
"""the compiled loops the studies run outside training (by a name, with what they play
and how to compile them): ``compile --all`` fills the cache with them too"""


def _bandit(engine: str) -> None:
    from cartpole_q.engines.bandit import warm_up

    warm_up(engine)


def _linear() -> None:
    from cartpole_q.engines.linear import warm_up

    warm_up()


def _policy_gradient() -> None:
    from cartpole_q.engines.policy_gradient import warm_up

    warm_up()


def _average_reward() -> None:
    from cartpole_q.engines.average_reward import warm_up

    warm_up()


def jobs_for(config: Config | None, every: bool) -> list[CompileJob]:
    """What to compile: one config's loops on both engines, or every algorithm's everywhere.

    ``every`` adds the studies' own loops (:data:`STUDY_LOOPS`).
    """
    if not every:
        chosen = config or load_config()
        return [
            CompileJob("", chosen.agent.algorithm, engine, chosen.env.id)
            for engine in ("numba", "gymnasium")
        ]
    training = [
        CompileJob(name, algorithm, engine, load_config(name).env.id)
        for engine, configs in ENGINE_CONFIGS.items()
        for name in configs
        for algorithm in algorithm_names()
    ]
    studies = [CompileJob("", loop, STUDY, label) for loop, (label, _) in STUDY_LOOPS.items()]
    return training + studies


def _compile(handle: JobHandle, job: CompileJob, mapping: dict[str, Any] | None) -> str:
    """Job: compile one config's loops (a config mapping, or a shipped config's name).

    Returns:
        What it did, a line to print: ``compiled q_learning on CartPole-v1 (numba
        engine)``, ``skipped ...: why``, or ``""`` when stopped before it started.
    """
    from cartpole_q.config import ConfigError
    from cartpole_q.engines.plan import plan_run

    if handle.should_stop():
        return ""
    if job.engine == STUDY:
        STUDY_LOOPS[job.algorithm][1]()
        return f"compiled {job.algorithm} ({job.label}, a study's loop)"
    config = load_config(mapping if mapping is not None else (job.config or None))
    config = load_config(config.to_dict(), {"agent.algorithm": job.algorithm, "engine": job.engine})
    try:
        # (the greedy loop too: a run that finds it cached plays its greedy episodes on it)
        plan_run(config).precompile(greedy_loop=True)
    except ConfigError as error:  # e.g. an algorithm's parameters a config cannot give
        return f"{SKIPPED} {job.describe()}: {error}"
    return f"compiled {job.describe()}"


def compile_all(
    config: Config | None,
    every: bool,
    *,
    workers: int | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_done: Callable[[str], None] | None = None,
) -> tuple[int, int, float]:
    """Compile the loops of each job (a config on an engine), telling ``on_done`` each line.

    Returns:
        How many jobs compiled (or loaded) their loops, how many were skipped (an algorithm
        a config cannot give its parameters), and the seconds it took.
    """
    jobs = jobs_for(config, every)
    mapping = None if config is None or every else config.to_dict()
    started = time.perf_counter()
    compiled = skipped = 0

    def on_item(index: int, line: str) -> None:
        nonlocal compiled, skipped
        if line.startswith(SKIPPED):
            skipped += 1
        elif line:
            compiled += 1
        if on_done is not None and line:
            on_done(line)

    # A stop abandons the loops being compiled (compiled in part, they are worth nothing);
    # the finished ones are in the cache.
    execute(
        _compile, [(job, mapping) for job in jobs], on_item,
        workers=workers or default_workers(len(jobs)), should_stop=should_stop, abandon=True,
    )  # fmt: skip
    return compiled, skipped, time.perf_counter() - started


def compile_ahead(
    plans: Sequence[Plan],
    workers: int,
    should_stop: Callable[[], bool] | None = None,
    on_start: Callable[[int], None] | None = None,
) -> int:
    """Compile the distinct loops ``configs`` will run that numba's cache lacks, once each.

    The loops are compiled side by side on up to ``workers`` worker processes (also a single
    loop: this process stays free to answer a stop); the runs' workers then load them from
    the cache.

    Args:
        plans: the plans of the runs about to start (their environments are not
            inspected again, here or in the workers).
        workers: the worker processes the runs will use.
        should_stop: polled about ten times a second; once true, the loops being compiled
            are abandoned (their processes killed) and this returns at once.
        on_start: told how many loops are about to be compiled (not called for none).

    Returns:
        How many loops were compiled.
    """
    from cartpole_q.numba_cache import is_cached

    # A config's loops are compiled by one job (the numba engine's two side by side); a
    # loop another config's job compiles already is not counted again.
    jobs: list[tuple[Any, ...]] = []
    counted: set[str] = set()
    seen: set[tuple[Any, ...]] = set()
    for plan in plans:
        signature = _loop_signature(plan.config)
        if signature in seen:
            continue
        seen.add(signature)
        missing = [
            name for name in plan.loop_names() if name not in counted and not is_cached(name)
        ]
        if missing:
            counted.update(missing)
            jobs.append((plan.parts(),))
    if not jobs:
        return 0
    if on_start is not None:
        on_start(len(counted))
    execute(
        _compile_loop, jobs, lambda index, item: None,
        workers=min(workers, len(jobs)), should_stop=should_stop, abandon=True,
    )  # fmt: skip
    return len(counted)


def _loop_signature(config: Config) -> tuple[Any, ...]:
    """What decides which loops a config compiles (physics values and seeds do not)."""
    grid = config.discretization
    return (
        config.engine,
        config.agent.algorithm,
        config.env.id,
        repr(config.env.kwargs),
        None if grid is None else grid.tilings,
        bool(config.env.randomize),
        config.train.info_metric,
        repr(config.agent.epsilon),  # which of the numba engine's two loops it plays
        config.train.episodes,
        config.agent.alpha.averages,  # sample averages compile their own loops
    )


def _compile_loop(handle: JobHandle, parts: tuple[Any, ...]) -> str:
    """Job: compile (or load) the loops of one plan (as :meth:`Plan.parts` sent it)."""
    from cartpole_q.engines.plan import Plan

    plan = Plan.from_parts(parts)
    if not handle.should_stop():
        plan.precompile()
    return plan.engine
