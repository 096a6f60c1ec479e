"""Training: a config in, a :class:`TrainResult` out. No file I/O here.

The driver runs the engine in chunks of episodes. Between chunks (always at an episode
boundary) it keeps the solve-point table, runs periodic greedy evaluations, hands
checkpoints and progress to the caller's callbacks, and honours a stop request. Chunk
sizes never change results: an engine's state lives entirely in the Q-table, the metrics
arrays and two random generators.

Randomness: the run seed feeds a ``numpy.random.SeedSequence`` whose three children give the
agent's Generator, the integer seed of the environment's first reset, and the Generator of
``env.randomize``'s physics draws.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import Config
from cartpole_q.engines import make_engine
from cartpole_q.engines.base import NO_STEP_LIMIT, Engine, EpisodeMetrics, Tables, TrainingState
from cartpole_q.engines.plan import Plan, plan_run
from cartpole_q.envs.gym import EnvInfo
from cartpole_q.errors import RunError
from cartpole_q.evaluation import EvalReport
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.rl.solve import SOLVE_WINDOW


def derive_generators(seed: int) -> tuple[np.random.Generator, int, np.random.Generator]:
    """The agent's Generator, the environment's first-reset seed and the physics Generator.

    ``SeedSequence(seed).spawn(3)``: its first two children are ``spawn(2)``'s, so the
    physics generator (``env.randomize``'s draws) changes no run that existed before it.

    >>> _, env_seed, _ = derive_generators(0)
    >>> env_seed
    673228719
    """
    agent_sequence, env_sequence, physics_sequence = np.random.SeedSequence(seed).spawn(3)
    env_seed = int(env_sequence.generate_state(1, dtype=np.uint32)[0])
    return (
        np.random.Generator(np.random.PCG64(agent_sequence)),
        env_seed,
        np.random.Generator(np.random.PCG64(physics_sequence)),
    )


@dataclass(frozen=True)
class Progress:
    """A progress report, given after every chunk of episodes."""

    episode: int
    """episodes finished"""
    episodes: int
    """episodes configured"""
    last_return: float
    moving_average: float
    """mean return of the last (up to) 100 episodes"""
    epsilon: float
    env_steps: int
    elapsed: float
    """seconds since training (re)started"""
    solved_episode: int | None
    train_seconds: float = 0.0
    """seconds spent in training episodes, periodic evaluations excluded, resumed runs' included"""

    @property
    def train_steps_per_second(self) -> float:
        """Env steps per second of training time, as ``summary.json``'s ``steps_per_second``."""
        return self.env_steps / self.train_seconds if self.train_seconds > 0 else 0.0


@dataclass(frozen=True)
class Checkpoint:
    """Everything needed to continue a run exactly where it stopped (an episode boundary).

    The arrays are the live training arrays: a callback must save them before returning.
    """

    engine: str
    episode: int
    env_steps: int
    tables: Tables
    """the live tables and the algorithm's memory"""
    metrics: EpisodeMetrics
    """the metrics of the finished episodes (views of the live arrays)"""
    agent_rng_state: dict[str, Any]
    env_rng_state: dict[str, Any]
    physics_rng_state: dict[str, Any] | None
    solved_episode: int | None
    solved_q: np.ndarray | None
    evaluations: list[dict[str, Any]]
    train_seconds: float
    wall_seconds: float
    config: Config | None = None
    """the config the run was trained with (``None`` in checkpoints older than this field)"""
    info: np.ndarray | None = None
    """the finished episodes' sums of ``info[train.info_metric]`` (``None`` without it)"""
    errors: np.ndarray | None = None
    """a prediction run's finished episodes' RMS errors (``None`` when none are measured)"""


@dataclass(frozen=True)
class TrainResult:
    """The outcome of training: the kept Q-table, per-episode metrics and figures."""

    config: Config
    engine: str
    """the engine that ran"""
    q_table: np.ndarray
    """the kept table, shape ``(*bins, n_actions)`` (``(n, n_actions)`` for ``Discrete(n)``,
    ``(a, b, ..., n_actions)`` for a Tuple of Discrete): from the solve point if it solved.
    A prediction run's is ``V`` with one column, ``(*bins, 1)`` (:attr:`v_table`)"""
    kept_episode: int
    """the episode after which the kept table was taken"""
    visits: np.ndarray
    """how often each (state, action) was taken in training, same shape as ``q_table``"""
    metrics: EpisodeMetrics
    """one value per training episode: returns, lengths, epsilons, alphas"""
    env_steps: int
    solved_episode: int | None
    """first episode whose 100-episode average return reached the threshold"""
    reward_threshold: float | None
    evaluations: list[dict[str, Any]]
    """periodic greedy evaluations: episode, env_steps, mean, std, min, max"""
    eval: EvalReport | None
    """the final greedy evaluation of the kept table (the engine's environment)"""
    train_seconds: float
    """seconds spent in training episodes"""
    wall_seconds: float
    """seconds of the whole training loop, periodic evaluations included"""
    interrupted: bool = False
    """a stop request cut the run short: training stopped before its end, or an evaluation
    was cut (``train --resume`` finishes it)"""
    info: np.ndarray | None = None
    """each training episode's sum of ``info[config.train.info_metric]`` over its steps
    (``None`` without ``train.info_metric``)"""
    eval_interrupted: bool = False
    """the final evaluation was cut short by a stop request: ``eval`` holds the episodes it
    played (``None`` if none)"""
    errors: np.ndarray | None = None
    """a prediction run's RMS error of ``V`` against the true values after each episode
    (``None`` for control, or when the world has no model to know them by)"""

    @property
    def predicts(self) -> bool:
        """Whether the run learnt state values ``V`` (a prediction algorithm)."""
        return get_algorithm(self.config.agent.algorithm).predicts

    @property
    def v_table(self) -> np.ndarray:
        """A prediction run's ``V``, shape ``(*bins,)`` (``v_table.npy``)."""
        if not self.predicts:
            raise ValueError(f"{self.config.agent.algorithm} learns action values, not V")
        values: np.ndarray = self.q_table[..., 0]
        return values

    @property
    def episodes(self) -> int:
        """Episodes trained."""
        return len(self.metrics.returns)

    @property
    def returns(self) -> np.ndarray:
        """The return of each training episode."""
        return self.metrics.returns

    @property
    def lengths(self) -> np.ndarray:
        """The length (env steps) of each training episode."""
        return self.metrics.lengths

    @property
    def extendable(self) -> bool:
        """Whether more episodes would continue this run exactly as a longer run would go on.

        True when the run ended by reaching ``train.episodes``: not interrupted, not
        stopped at its solve point (a longer run would have stopped there too), and not at
        ``train.max_env_steps`` (its last episode was cut there).
        """
        settings = self.config.train
        stopped_when_solved = self.solved_episode is not None and settings.stop_when_solved
        budget = settings.max_env_steps
        return (
            not self.interrupted
            and self.episodes >= settings.episodes
            and not stopped_when_solved
            and not (budget is not None and self.env_steps >= budget)
        )

    @property
    def steps_per_second(self) -> float:
        """Training env steps per second of training time."""
        return self.env_steps / self.train_seconds if self.train_seconds > 0 else 0.0

    def first_greedy_success(self) -> dict[str, int] | None:
        """The first periodic evaluation whose mean reached the threshold, if any."""
        if self.reward_threshold is None:
            return None
        for record in self.evaluations:
            if record["mean"] >= self.reward_threshold:
                return {"episode": record["episode"], "env_steps": record["env_steps"]}
        return None


def train(
    config: Config | Plan,
    *,
    env_info: EnvInfo | None = None,
    resume: Checkpoint | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_progress: Callable[[Progress], None] | None = None,
    on_checkpoint: Callable[[Checkpoint], None] | None = None,
    final_eval: bool = True,
    snapshot_every: int = 0,
    on_snapshot: Callable[[int, np.ndarray], None] | None = None,
) -> TrainResult:
    """Train a Q-table as the config says.

    Args:
        config: a validated config (its ``train.seeds`` is ignored: one run, ``config.seed``),
            or its :class:`~cartpole_q.engines.plan.Plan` (then nothing is checked again).
        env_info: the checked environment, if the caller already inspected it (with a
            config; a plan has its own).
        resume: a checkpoint to continue from; the result is then byte-identical to an
            uninterrupted run.
        should_stop: polled between chunks of episodes, and between chunks of greedy
            episodes in evaluations; when it returns true, training ends at the last
            finished episode, a periodic evaluation being played is dropped (a resumed run
            plays it again), the final evaluation ends after its first chunk (of
            :data:`~cartpole_q.engines.base.EVAL_CHUNK_EPISODES` episodes) or where it is,
            and the result is marked ``interrupted``.
        on_progress: called after every chunk.
        on_checkpoint: called every ``train.checkpoint_every`` episodes, and on interruption.
        final_eval: run the final greedy evaluation of the kept table.
        snapshot_every: call ``on_snapshot`` every this many episodes (0: never), e.g. to
            watch or record the greedy policy while it learns (``train --watch``,
            ``--video-every``). Results do not depend on it.
        on_snapshot: called with the episodes finished and a copy of the current table,
            shape ``(*bins, n_actions)``.

    Raises:
        ConfigError: the config does not fit its environment.
    """
    if isinstance(config, Plan):
        if env_info is not None:
            raise TypeError("train: give env_info with a config, not with a plan (it has one)")
        plan = config
    elif resume is not None:  # the checkpoint's engine runs: no other is chosen
        plan = plan_run(config, env_info=env_info, engine=resume.engine)
    else:
        plan = plan_run(config, env_info=env_info)
    config, env_info = plan.config, plan.env_info
    engine_name = resume.engine if resume is not None else plan.engine
    twin = plan.twin if engine_name == plan.engine else None  # (a resumed run's own engine)
    agent_rng, env_seed, physics_rng = derive_generators(config.seed)
    state = TrainingState.fresh(config, env_info, agent_rng, physics_rng)
    if resume is not None:
        _restore(state, resume)
    engine = make_engine(
        engine_name, config, env_info, env_seed,
        None if resume is None else resume.env_rng_state, twin,
    )  # fmt: skip
    hooks = _Hooks(should_stop, on_progress, on_checkpoint, snapshot_every, on_snapshot)
    try:
        engine.warm_up(state)
        return _run(config, env_info, engine, state, resume, hooks, final_eval)
    finally:
        engine.close()


@dataclass(frozen=True)
class _Hooks:
    """The caller's callbacks (see :func:`train`)."""

    should_stop: Callable[[], bool] | None
    on_progress: Callable[[Progress], None] | None
    on_checkpoint: Callable[[Checkpoint], None] | None
    snapshot_every: int
    on_snapshot: Callable[[int, np.ndarray], None] | None


def _run(
    config: Config,
    env_info: EnvInfo,
    engine: Engine,
    state: TrainingState,
    resume: Checkpoint | None,
    hooks: _Hooks,
    final_eval: bool,
) -> TrainResult:
    settings = config.train
    should_stop, on_progress, on_checkpoint = (
        hooks.should_stop,
        hooks.on_progress,
        hooks.on_checkpoint,
    )
    snapshot_every, on_snapshot = hooks.snapshot_every, hooks.on_snapshot
    table_shape = (*env_info.state_shape, state.tables.q.shape[1])  # V: one column
    visits_shape = (*env_info.state_shape, env_info.n_actions)
    # A prediction run follows a given policy: no greedy policy to evaluate, nothing solved.
    predicts = state.algorithm.predicts
    evaluate_every = 0 if predicts else settings.eval_every
    total = settings.episodes
    train_seconds = 0.0 if resume is None else resume.train_seconds
    wall_before = 0.0 if resume is None else resume.wall_seconds
    started = time.perf_counter()
    interrupted = False

    def snapshot() -> Checkpoint:
        episode = state.episode
        return Checkpoint(
            engine=engine.name,
            episode=episode,
            env_steps=state.env_steps,
            tables=state.tables,
            metrics=EpisodeMetrics(*(column[:episode] for column in state.metrics)),
            agent_rng_state=dict(state.agent_rng.bit_generator.state),
            physics_rng_state=dict(state.physics_rng.bit_generator.state),
            env_rng_state=engine.env_rng_state(),
            solved_episode=state.solved_episode,
            solved_q=state.solved_q,
            evaluations=list(state.evaluations),
            train_seconds=train_seconds,
            wall_seconds=wall_before + time.perf_counter() - started,
            config=config,
            info=None if state.info is None else state.info[:episode],
            errors=None if state.errors is None else state.errors[:episode],
        )

    def periodic_evaluation() -> bool:
        """Record the periodic evaluation of this episode; False if a stop cut it short."""
        returns = engine.evaluate(
            state.policy_table(), settings.eval_episodes, config.eval.seed, should_stop
        )
        if len(returns) < settings.eval_episodes:
            return False  # not recorded: a resumed run plays it again, whole
        periodic = EvalReport.from_returns(returns, config.eval.seed)
        state.evaluations.append(
            {"episode": state.episode, "env_steps": state.env_steps, **periodic.to_dict()}
        )
        return True

    step_limit = settings.max_env_steps or NO_STEP_LIMIT
    finished = (
        state.episode >= total
        or (state.solved_episode is not None and settings.stop_when_solved)
        or state.steps_spent(step_limit)
    )
    if resume is not None and _evaluation_missing(state, evaluate_every):
        interrupted = not periodic_evaluation()  # the one a stop cut short
    while not finished and not interrupted:
        stop = min(
            total,
            state.episode + engine.chunk_episodes,
            _next_multiple(state.episode, evaluate_every),
            _next_multiple(state.episode, settings.checkpoint_every),
            _next_multiple(state.episode, snapshot_every if on_snapshot else 0),
        )
        chunk_started = time.perf_counter()
        solved = engine.run(state, stop, check_solved=state.solved_episode is None and not predicts)
        train_seconds += time.perf_counter() - chunk_started
        if solved is not None:
            state.solved_episode = solved + 1
            if not settings.stop_when_solved:
                state.solved_q = state.policy_table().copy()
        evaluated = True
        if evaluate_every and state.episode % evaluate_every == 0:
            evaluated = periodic_evaluation()
        finished = (
            state.episode >= total
            or (solved is not None and settings.stop_when_solved)
            or state.steps_spent(step_limit)
        )
        if on_snapshot is not None and snapshot_every and state.episode % snapshot_every == 0:
            on_snapshot(state.episode, state.policy_table().reshape(table_shape).copy())
        if (
            on_checkpoint is not None
            and settings.checkpoint_every
            and state.episode % settings.checkpoint_every == 0
            and not finished
            and evaluated
        ):
            on_checkpoint(snapshot())
        if on_progress is not None:
            on_progress(_progress(state, total, time.perf_counter() - started, train_seconds))
        if not evaluated or (not finished and should_stop is not None and should_stop()):
            interrupted = True
            break

    stopped_when_solved = state.solved_episode is not None and settings.stop_when_solved
    # A run cut at train.max_env_steps is not extended: its last episode was cut.
    stopped_early = stopped_when_solved or state.steps_spent(step_limit)
    checkpointed = on_checkpoint is not None and (interrupted or not stopped_early)
    if checkpointed and on_checkpoint is not None:  # (checkpointed says so; mypy cannot see it)
        # Interrupted: for --resume. Reached train.episodes: to extend the run later.
        on_checkpoint(snapshot())
    wall_seconds = wall_before + time.perf_counter() - started

    if state.solved_episode is not None:
        kept = state.policy_table() if state.solved_q is None else state.solved_q
        kept_episode = state.solved_episode
    else:
        kept, kept_episode = state.policy_table(), state.episode
    report: EvalReport | None = None
    eval_interrupted = False
    if final_eval and not predicts:
        returns = engine.evaluate(kept, config.eval.episodes, config.eval.seed, should_stop)
        eval_interrupted = len(returns) < config.eval.episodes
        report = EvalReport.from_returns(returns, config.eval.seed) if len(returns) else None
    if eval_interrupted and not checkpointed and on_checkpoint is not None:
        # Trained to its end, its evaluation cut short: --resume only evaluates again.
        on_checkpoint(snapshot())
    episode = state.episode
    return TrainResult(
        config=config,
        engine=engine.name,
        q_table=kept.reshape(table_shape).copy(),
        kept_episode=kept_episode,
        visits=state.tables.visits.reshape(visits_shape).copy(),
        metrics=state.metrics.head(episode),
        env_steps=state.env_steps,
        solved_episode=state.solved_episode,
        reward_threshold=env_info.reward_threshold,
        evaluations=list(state.evaluations),
        eval=report,
        train_seconds=train_seconds,
        wall_seconds=wall_seconds,
        interrupted=interrupted or eval_interrupted,
        info=None if state.info is None else state.info[:episode].copy(),
        errors=None if state.errors is None else state.errors[:episode].copy(),
        eval_interrupted=eval_interrupted,
    )


def _fits(live: tuple[int, ...], saved: tuple[int, ...], growing: bool) -> bool:
    """Whether a saved memory array restores into the live one.

    The same shape; or, for an array that grows with ``train.episodes`` (a run extended), a
    first axis no longer than the live one's and the same other axes.
    """
    if not growing:
        return live == saved
    return live[1:] == saved[1:] and len(live) == len(saved) > 0 and saved[0] <= live[0]


def _restore(state: TrainingState, checkpoint: Checkpoint) -> None:
    episode = checkpoint.episode
    live, saved = state.tables, checkpoint.tables
    growing = state.algorithm.growing_memory
    older = state.algorithm.older_memory
    if older is not None and len(live.memory) != len(saved.memory):
        try:  # a checkpoint written before the algorithm kept its present arrays
            saved = saved._replace(memory=older(saved.memory))
        except ValueError as error:
            raise RunError(f"the checkpoint's memory cannot be continued: {error}.") from None
    if len(live.memory) != len(saved.memory) or any(
        not _fits(a.shape, b.shape, index in growing)
        for index, (a, b) in enumerate(zip(live.memory, saved.memory, strict=False))
    ):
        raise RunError(
            f"the checkpoint holds {len(saved.memory)} memory arrays of "
            f"{state.algorithm.name} shaped {[array.shape for array in saved.memory]}, the "
            f"config asks for {[array.shape for array in live.memory]}; it was written by "
            "another algorithm or grid."
        )
    # A damaged file must be a RunError, not numpy's ValueError from a slice of another length.
    expected = [
        ("q", live.q.shape, saved.q.shape),
        ("visits", live.visits.shape, saved.visits.shape),
        *(
            (name, (episode,), column.shape)
            for name, column in zip(EpisodeMetrics._fields, checkpoint.metrics, strict=True)
        ),
        *(
            (name, (episode,), None if array is None else array.shape)
            for name, array in (("info", checkpoint.info), ("rms_errors", checkpoint.errors))
            if array is not None
        ),
    ]
    for name, wanted, found in expected:
        if found != wanted or episode > len(state.metrics.returns):
            raise RunError(
                f"the checkpoint's {name} has shape {found}, the run needs {wanted} (episode "
                f"{episode} of {len(state.metrics.returns)}); the checkpoint is damaged or was "
                "written with another config."
            )
    live.q[...] = saved.q
    live.visits[...] = saved.visits
    for array, kept in zip(live.memory, saved.memory, strict=True):
        if array.shape == kept.shape:
            array[...] = kept
        else:  # an array that grows with train.episodes: the start of a longer one
            array[: kept.shape[0]] = kept
    for column, values in zip(state.metrics, checkpoint.metrics, strict=True):
        column[:episode] = values
    for what, live_column, kept_column in (
        ("train.info_metric (per-episode info sums)", state.info, checkpoint.info),
        ("a prediction run's per-episode errors", state.errors, checkpoint.errors),
    ):
        if (live_column is None) != (kept_column is None):
            raise RunError(
                f"the checkpoint and the config disagree on {what}: one keeps them, the other "
                "none; it was written with another config."
            )
        if live_column is not None and kept_column is not None:
            live_column[:episode] = kept_column
    state.agent_rng.bit_generator.state = checkpoint.agent_rng_state
    if checkpoint.physics_rng_state is not None:
        state.physics_rng.bit_generator.state = checkpoint.physics_rng_state
    state.episode = episode
    state.env_steps = checkpoint.env_steps
    state.solved_episode = checkpoint.solved_episode
    state.solved_q = None if checkpoint.solved_q is None else checkpoint.solved_q.copy()
    state.evaluations = list(checkpoint.evaluations)


def _evaluation_missing(state: TrainingState, eval_every: int) -> bool:
    """Whether the periodic evaluation due at ``state.episode`` has no record.

    Only a stop can leave it out (it cuts the evaluation short, and the checkpoint is
    written after it): a resumed run plays it first, so its evaluations are those of an
    uninterrupted run.
    """
    if not eval_every or state.episode == 0 or state.episode % eval_every:
        return False
    return not state.evaluations or state.evaluations[-1]["episode"] != state.episode


def _next_multiple(episode: int, every: int) -> int:
    """The next episode count after ``episode`` that is a multiple of ``every`` (0: never)."""
    if every <= 0:
        return np.iinfo(np.int64).max
    return (episode // every + 1) * every


def _progress(state: TrainingState, total: int, elapsed: float, train_seconds: float) -> Progress:
    episode = state.episode
    returns, epsilons = state.metrics.returns, state.metrics.epsilons
    window = returns[max(0, episode - SOLVE_WINDOW) : episode]
    return Progress(
        episode=episode,
        episodes=total,
        last_return=float(returns[episode - 1]) if episode else 0.0,
        moving_average=float(window.mean()) if episode else 0.0,
        epsilon=float(epsilons[episode - 1]) if episode else 0.0,
        env_steps=state.env_steps,
        elapsed=elapsed,
        solved_episode=state.solved_episode,
        train_seconds=train_seconds,
    )
