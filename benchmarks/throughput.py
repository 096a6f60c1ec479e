"""Training throughput, measured side by side in one run (env steps per second).

    python benchmarks/throughput.py [--repeats 3] [--quick] [--only SECTION]

Rows:
  blog loop         the tutorial's per-step loop (Python lists for binning,
                    env.action_space.sample(), NumPy Q updates) on gymnasium.make: the baseline
  gymnasium engine  cartpole-q's Python loop on gymnasium.make, same grid
  numba engine      the compiled twin and agent, same grid (one thread, compile excluded)
  + progress bar    the gymnasium engine with the live rich progress bar drawing
  algorithms        every registered agent.algorithm on the numba engine, against Q-learning:
                    env steps/s and Q-entry updates/s (env steps/s times the mean number of
                    Q entries written per env step, counted on the tests' plain-Python
                    re-derivation of the same config: a trace method writes every traced
                    pair, Dyna 1 + planning_steps, Monte Carlo one per first visit)
  environments      MountainCar-v0 and Acrobot-v1: their twins against the gymnasium engine
  tabular worlds    FrozenLake8x8-v1 and Taxi-v4 (the shipped configs frozenlake8x8 and taxi):
                    the numba engine's twin against the gymnasium engine on the same training
                    (the twins are bit-identical, so both engines play the same env steps)
  prediction        every prediction algorithm on the 19-state random walk (Figure 7.2's),
                    the random policy, its error measured per episode: the numba engine
                    against the gymnasium engine on the same training
  linear            every sampled linear method (a linear study's curve): on the 1000-state
                    walk (Fourier order 5; the on-policy ones) and Baird's counterexample
                    (its declared features; the off-policy ones), the numba engine against
                    the gymnasium engine on the same run (√VE recorded every 100 episodes or
                    1,000 steps), env steps per second; the expected methods' sweeps per
                    second on Baird's
  policy_gradient   REINFORCE, REINFORCE with baseline, one-step actor-critic and actor-critic
                    with traces on the short corridor (Figure 13.2's settings, 1,000
                    episodes; the gymnasium engine 100): the numba engine
                    against the gymnasium engine on the same run, env steps per second
  average_reward    differential semi-gradient SARSA on access control (Figure 10.5's
                    settings; 2 million steps, the gymnasium engine 50,000): the numba
                    engine against the gymnasium engine, env steps per second

Every figure is the median of --repeats runs; ratios are against baselines measured in this
same run, so they hold across machines even when absolute rates do not. --only SECTION runs
one section (cartpole, algorithms, environments, tabular, prediction, tiles, linear,
policy_gradient, average_reward, progress); the algorithms section
then measures its own Q-learning baseline.
"""

from __future__ import annotations

import argparse
import io
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from rich.console import Console

from cartpole_q.config import load_config
from cartpole_q.envs.gym import inspect_env
from cartpole_q.progress import RichReporter
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.rl.algorithms import names as algorithm_names
from cartpole_q.training import train

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import reference_tabular  # the tests' plain-Python re-derivation of the contract

BLOG_BINS = (10, 10, 10, 10)
BLOG_LOW = (-4.8, -1.0, -0.418, -1.0)
BLOG_HIGH = (4.8, 1.0, 0.418, 1.0)


def blog_loop(episodes: int, seed: int) -> tuple[int, float]:
    """The tutorial's Q-learning loop, with its two bugs fixed (clamp index, truncation)."""
    env = gym.make("CartPole-v1")
    env.action_space.seed(seed)
    np.random.seed(seed)  # noqa: NPY002 - the tutorial's own global generator
    q_table = np.zeros((*BLOG_BINS, env.action_space.n))
    alpha, gamma, epsilon = 0.1, 0.99, 1.0

    def discretize(observation: np.ndarray) -> tuple[int, ...]:
        ratios = [
            (observation[i] + abs(BLOG_LOW[i])) / (BLOG_HIGH[i] - BLOG_LOW[i])
            for i in range(len(observation))
        ]
        new_obs = [round((BLOG_BINS[i] - 1) * ratios[i]) for i in range(len(observation))]
        new_obs = [min(BLOG_BINS[i] - 1, max(0, new_obs[i])) for i in range(len(observation))]
        return tuple(new_obs)

    steps = 0
    started = time.perf_counter()
    for episode in range(episodes):
        observation, _ = env.reset(seed=seed if episode == 0 else None)
        state = discretize(observation)
        done = False
        while not done:
            if np.random.random() < epsilon:  # noqa: NPY002 - as the tutorial writes it
                action = env.action_space.sample()
            else:
                action = int(np.argmax(q_table[state]))
            observation, reward, terminated, truncated, _ = env.step(action)
            new_state = discretize(observation)
            q_table[state][action] += alpha * (
                reward + gamma * np.max(q_table[new_state]) - q_table[state][action]
            )
            state = new_state
            done = terminated or truncated
            steps += 1
        epsilon = max(0.01, epsilon * 0.995)
    return steps, time.perf_counter() - started


def engine_rate(
    config_path: str | dict | None, engine: str, episodes: int, seed: int, progress: bool = False,
    algorithm: str | None = None,
) -> tuple[int, float]:  # fmt: skip
    """Training env steps and seconds of ``train`` (periodic evaluation off, compile excluded)."""
    overrides = {
        "engine": engine, "seed": seed, "train.episodes": episodes, "train.stop_when_solved": False,
        "train.eval_every": 0, "train.checkpoint_every": 0,
    }  # fmt: skip
    if algorithm is not None:
        overrides["agent.algorithm"] = algorithm
    config = load_config(config_path, overrides)
    info = inspect_env(config)
    callback = None
    reporter = None
    if progress:
        reporter = RichReporter(Console(file=io.StringIO(), force_terminal=True, width=150))
        reporter.start("run", "benchmark", episodes)
        callback = lambda update: reporter.update("run", update)  # noqa: E731
    try:
        result = train(config, env_info=info, on_progress=callback, final_eval=False)
    finally:
        if reporter is not None:
            reporter.close()
    return result.env_steps, result.train_seconds


class CountingRow(list):  # type: ignore[type-arg]
    """A Q-table row that counts the writes made to it."""

    writes = 0

    def __setitem__(self, index: Any, value: Any) -> None:
        CountingRow.writes += 1
        super().__setitem__(index, value)


def updates_per_step(algorithm: str, episodes: int = 40, seed: int = 0) -> float:
    """Q entries written per env step by ``algorithm`` on the default config (plain Python).

    The writes to every Q-table the algorithm keeps (Double Q's two) are counted on the
    re-derivation in ``tests/reference_tabular.py``, which follows the same contract.
    """
    config = load_config(None, {"agent.algorithm": algorithm}).to_dict()
    agent, disc = config["agent"], config["discretization"]
    base = reference_tabular.ALGORITHMS[algorithm]

    class Counting(base):  # type: ignore[valid-type, misc]
        def __init__(self, *args: Any) -> None:
            super().__init__(*args)
            for name in ("q", "q_b"):
                if hasattr(self, name):
                    setattr(self, name, [CountingRow(row) for row in getattr(self, name)])

    reference_tabular.ALGORITHMS[algorithm] = Counting
    CountingRow.writes = 0
    try:
        params = {key: agent[key] for key in reference_tabular.PARAMETER_DEFAULTS if key in agent}
        run = reference_tabular.reference_train(
            config["env"]["id"], algorithm=algorithm, gamma=agent["gamma"], alpha=agent["alpha"],
            epsilon=agent["epsilon"], q_init=agent["q_init"], episodes=episodes, seed=seed,
            stop_when_solved=False, discretization=disc, params=params,
        )  # fmt: skip
    finally:
        reference_tabular.ALGORITHMS[algorithm] = base
    return CountingRow.writes / sum(run.lengths)


def median_rate(measure, repeats: int) -> float:  # type: ignore[no-untyped-def]
    """The median env steps per second of ``repeats`` measurements (a noisy 2-core machine)."""
    rates = []
    for _ in range(repeats):
        steps, seconds = measure()
        rates.append(steps / seconds)
    return statistics.median(rates)


def env_config(env_id: str, bins: tuple[int, ...], low: tuple[float, ...], high: tuple[float, ...],
               algorithm: str = "q_learning") -> dict:  # fmt: skip
    """A config mapping for another environment (a grid over its observation)."""
    return {
        "env": {"id": env_id},
        "discretization": {"bins": list(bins), "low": list(low), "high": list(high)},
        "agent": {"algorithm": algorithm, "epsilon": 0.1, "q_init": 0.0},
    }


MOUNTAINCAR = env_config("MountainCar-v0", (20, 20), (-1.2, -0.07), (0.6, 0.07))
ACROBOT = env_config(
    "Acrobot-v1", (6, 6, 6, 6, 8, 8), (-1, -1, -1, -1, -12.6, -28.3), (1, 1, 1, 1, 12.6, 28.3)
)


TABULAR = (("FrozenLake8x8-v1 (frozenlake8x8)", "frozenlake8x8", 22_000),
           ("Taxi-v4 (taxi)", "taxi", 5_000))  # fmt: skip
"""the tabular worlds' rows: label, shipped config, its episodes (the whole training)"""

SECTIONS = (
    "cartpole", "algorithms", "environments", "tabular", "prediction", "tiles", "linear",
    "policy_gradient", "average_reward", "progress",
)  # fmt: skip
"""what --only can pick; by default every section runs, in this order"""


def cartpole_rows(repeats: int, python_episodes: int, numba_episodes: int) -> float:
    """The training loops on CartPole against the blog loop; returns numba's default rate."""
    blog = "configs/blog.yaml"
    # warm up numba (compile or load the cache) so that no row pays for it
    engine_rate(blog, "numba", 5, 0)
    engine_rate(blog, "gymnasium", 2, 0)
    engine_rate(None, "numba", 5, 0)

    rows = [
        ("blog loop (baseline)", median_rate(lambda: blog_loop(python_episodes, 0), repeats)),
        (
            "gymnasium engine, blog grid",
            median_rate(lambda: engine_rate(blog, "gymnasium", python_episodes, 0), repeats),
        ),
        (
            "numba engine, blog grid",
            median_rate(lambda: engine_rate(blog, "numba", numba_episodes, 0), repeats),
        ),
        (
            "gymnasium engine, default config",
            median_rate(lambda: engine_rate(None, "gymnasium", python_episodes, 0), repeats),
        ),
        (
            "numba engine, default config",
            median_rate(lambda: engine_rate(None, "numba", numba_episodes // 10, 0), repeats),
        ),
    ]
    baseline = rows[0][1]
    print(
        f"{'training loop (median of ' + str(repeats) + ')':40s} {'env steps/s':>14s} {'vs blog loop':>13s}"
    )
    for name, rate in rows:
        print(f"{name:40s} {rate:14,.0f} {rate / baseline:12.1f}x")
    gym_default = rows[3][1]
    print(f"numba / gymnasium engine, default config: {rows[4][1] / gym_default:,.0f}x")
    print(f"numba / gymnasium engine, blog grid:      {rows[2][1] / rows[1][1]:,.0f}x")
    return rows[4][1]


def algorithm_rows(repeats: int, numba_episodes: int, q_learning: float | None) -> None:
    """Each algorithm on the numba engine, default config, against Q-learning."""
    if q_learning is None:  # run alone: measure the baseline here, in this same run
        engine_rate(None, "numba", 5, 0)
        q_learning = median_rate(
            lambda: engine_rate(None, "numba", numba_episodes // 10, 0), repeats
        )
    print(
        f"{'algorithm, numba engine, default config':40s} {'env steps/s':>14s} "
        f"{'vs q_learning':>13s} {'updates/step':>13s} {'updates/s':>14s}"
    )
    for algorithm in algorithm_names():
        if get_algorithm(algorithm).predicts:
            continue  # (the prediction section: they evaluate a policy of the random walk)
        engine_rate(None, "numba", 5, 0, algorithm=algorithm)  # compile or load the cache
        rate = median_rate(
            lambda a=algorithm: engine_rate(None, "numba", numba_episodes // 10, 0, algorithm=a),
            repeats,
        )
        per_step = updates_per_step(algorithm)
        print(
            f"{algorithm:40s} {rate:14,.0f} {rate / q_learning:12.0%} {per_step:13.2f} "
            f"{rate * per_step:14,.0f}"
        )


def environment_rows(repeats: int, scale: float) -> None:
    """The other classic-control twins: numba against the gymnasium engine, same config."""
    print(
        f"{'environment (Q-learning, epsilon 0.1)':40s} {'gymnasium':>14s} {'numba':>13s} {'ratio':>7s}"
    )
    for name, config in (
        ("MountainCar-v0, 20x20 grid", MOUNTAINCAR),
        ("Acrobot-v1, 6^4x8^2 grid", ACROBOT),
    ):
        engine_rate(config, "numba", 2, 0)
        engine_rate(config, "gymnasium", 1, 0)
        gym_rate = median_rate(
            lambda c=config: engine_rate(c, "gymnasium", max(2, int(20 * scale)), 0), repeats
        )
        numba_rate = median_rate(
            lambda c=config: engine_rate(c, "numba", max(200, int(5000 * scale)), 0), repeats
        )
        print(f"{name:40s} {gym_rate:14,.0f} {numba_rate:13,.0f} {numba_rate / gym_rate:6,.0f}x")


def tabular_rows(repeats: int, scale: float) -> None:
    """FrozenLake 8x8 and Taxi: the twin against the gymnasium engine on the same training.

    Both engines train the shipped config from the same seed for the same episodes; the twin
    is bit-identical to ``gymnasium.make``, so they play the same env steps (checked), and
    the ratio is the ratio of training times. The numba runs are short (tens of
    milliseconds), so their median is over at least five.
    """
    print(
        f"{'tabular world (config), whole training':40s} {'gymnasium':>14s} {'numba':>13s} "
        f"{'ratio':>7s} {'episodes':>9s} {'env steps':>10s}"
    )
    for name, config, full in TABULAR:
        episodes = max(100, int(full * scale))
        engine_rate(config, "numba", 5, 0)  # compile or load the cache
        engine_rate(config, "gymnasium", 5, 0)
        steps, _ = engine_rate(config, "numba", episodes, 0)
        gym_steps, _ = engine_rate(config, "gymnasium", episodes, 0)
        if steps != gym_steps:
            raise SystemExit(f"{name}: the engines played {gym_steps} and {steps} env steps")
        gym_rate = median_rate(
            lambda c=config, e=episodes: engine_rate(c, "gymnasium", e, 0), repeats
        )
        numba_rate = median_rate(
            lambda c=config, e=episodes: engine_rate(c, "numba", e, 0), max(5, repeats)
        )
        print(
            f"{name:40s} {gym_rate:14,.0f} {numba_rate:13,.0f} {numba_rate / gym_rate:6,.0f}x "
            f"{episodes:9,d} {steps:10,d}"
        )


PREDICTION_WALK = {
    "env": {"id": "cartpole_q/RandomWalk-v0"}, "discretization": None,
    "agent": {"policy": "random", "gamma": 1.0, "alpha": 0.1, "q_init": 0.0},
}  # fmt: skip
"""the prediction section's world: Figure 7.2's 19-state walk, the random policy"""
PREDICTION_PARAMS = {"batch_prediction": {"alpha": 0.001}}
"""a small enough alpha for the batch to converge (its sums grow with the episodes)"""


def prediction_rows(repeats: int, scale: float) -> None:
    """Each prediction algorithm on the 19-state walk: numba against the gymnasium engine.

    Both engines train the same config from the same seed (the twin is bit-identical, so
    they play the same env steps, checked), with the per-episode RMS error measured as in
    every prediction run. The batch method's cost grows with the episodes seen (each
    episode passes over all earlier ones), so it plays fewer.
    """
    print(
        f"{'prediction, 19-state walk':40s} {'gymnasium':>14s} {'numba':>13s} {'ratio':>7s} "
        f"{'episodes':>9s} {'env steps':>10s}"
    )
    for algorithm in algorithm_names():
        if not get_algorithm(algorithm).predicts:
            continue
        batch = algorithm == "batch_prediction"
        episodes = max(20, int((50 if batch else 2000) * scale))
        config = {
            **PREDICTION_WALK,
            "agent": {**PREDICTION_WALK["agent"], "algorithm": algorithm,
                      **PREDICTION_PARAMS.get(algorithm, {})},
        }  # fmt: skip
        engine_rate(config, "numba", 5, 0)  # compile or load the cache
        engine_rate(config, "gymnasium", 5, 0)
        steps, _ = engine_rate(config, "numba", episodes, 0)
        gym_steps, _ = engine_rate(config, "gymnasium", episodes, 0)
        if steps != gym_steps:
            raise SystemExit(f"{algorithm}: the engines played {gym_steps} and {steps} env steps")
        gym_rate = median_rate(
            lambda c=config, e=episodes: engine_rate(c, "gymnasium", e, 0), repeats
        )
        numba_rate = median_rate(
            lambda c=config, e=episodes: engine_rate(c, "numba", e, 0), max(5, repeats)
        )
        print(
            f"{algorithm:40s} {gym_rate:14,.0f} {numba_rate:13,.0f} {numba_rate / gym_rate:6,.0f}x "
            f"{episodes:9,d} {steps:10,d}"
        )


LINEAR_WALK = {
    "kind": "linear", "world": {"id": "cartpole_q/RandomWalk1000-v0", "kwargs": {"position": True}},
    "gamma": 1.0,
}  # fmt: skip
LINEAR_BAIRD = {
    "kind": "linear", "world": {"id": "cartpole_q/Baird-v0"}, "gamma": 0.99, "target": [0, 1],
    "behaviour": ["6/7", "1/7"],
}  # fmt: skip
LINEAR_CURVES = (
    ("gradient_mc", LINEAR_WALK, {"alpha": 5e-5, "features": {"kind": "fourier", "order": 5}}),
    ("semi_gradient_td", LINEAR_WALK, {"alpha": 5e-5, "features": {"kind": "fourier", "order": 5}}),
    ("lstd", LINEAR_WALK, {"features": {"kind": "fourier", "order": 5}}),
    ("off_policy_td", LINEAR_BAIRD, {"alpha": 0.001, "features": {"kind": "declared"}}),
    ("tdc", LINEAR_BAIRD, {"alpha": 0.005, "beta": 0.05, "features": {"kind": "declared"}}),
    ("gtd2", LINEAR_BAIRD, {"alpha": 0.005, "beta": 0.05, "features": {"kind": "declared"}}),
    ("emphatic_td", LINEAR_BAIRD, {"alpha": 0.001, "features": {"kind": "declared"}}),
    ("semi_gradient_dp", LINEAR_BAIRD, {"alpha": 0.01, "features": {"kind": "declared"}}),
    (
        "expected_tdc",
        LINEAR_BAIRD,
        {"alpha": 0.005, "beta": 0.05, "features": {"kind": "declared"}},
    ),
    ("expected_emphatic_td", LINEAR_BAIRD, {"alpha": 0.03, "features": {"kind": "declared"}}),
)
"""the linear section's rows: each method on its world, with its settings"""


def linear_rate(raw: dict, engine: str, count: int) -> tuple[int, float]:
    """One run of a linear study's curve: ``(env steps or sweeps, seconds)``."""
    from cartpole_q.experiments import linear
    from cartpole_q.experiments.study import RunHandle, study_of

    unit = "episodes" if raw["world"]["id"].endswith("RandomWalk1000-v0") else "steps"
    study = linear.read_study(study_of(
        {**raw, unit: count, "record_every": 100 if unit == "episodes" else 1000, "engine": engine},
        "benchmark", "b", Path("."),
    ))  # fmt: skip
    steps = [0]

    def count_steps(done: int) -> None:
        steps[0] = done

    linear.curve_setup(study, 0)  # the model's solves and the layer: set-up, not stepping
    linear.world_table(study.world_id, study.world_kwargs, study.where)
    start = time.perf_counter()
    record = linear.run_one(study, {"curve": 0, "seed": 0}, RunHandle(lambda: False, count_steps))
    seconds = time.perf_counter() - start
    assert record is not None
    if unit == "episodes":  # the walk's env steps: replay the episode lengths' sum from the record
        steps[0] = walk_steps(count)
    return steps[0], seconds


def walk_steps(episodes: int, seed: int = 0) -> int:
    """The env steps of ``episodes`` episodes of the random policy on the walk (seed 0's draws)."""
    env = gym.make("cartpole_q/RandomWalk1000-v0")
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    env.reset(seed=int(env_seq.generate_state(1, dtype=np.uint32)[0]))
    steps = 0
    for episode in range(episodes):
        if episode:
            env.reset()
        done = False
        while not done:
            _, _, terminated, truncated, _ = env.step(int(rng.integers(0, 2)))
            steps += 1
            done = terminated or truncated
    return steps


def linear_rows(repeats: int, scale: float) -> None:
    """Each linear method: the numba engine against the gymnasium engine, the same run."""
    print(
        f"{'linear method, world':40s} {'gymnasium':>14s} {'numba':>13s} {'ratio':>7s} "
        f"{'per run':>9s} {'unit':>10s}"
    )
    for algorithm, world, curve in LINEAR_CURVES:
        raw = {**world, "curves": [{"algorithm": algorithm, **curve}]}
        expected = algorithm in ("semi_gradient_dp", "expected_tdc", "expected_emphatic_td")
        on_walk = world is LINEAR_WALK
        count = max(20, int((200 if algorithm == "lstd" else 2000) * scale)) if on_walk else (
            max(1000, int(200_000 * scale)) if not expected else max(1000, int(50_000 * scale))
        )  # fmt: skip
        linear_rate(raw, "numba", 2 if on_walk else 10)  # compile or load the cache
        label = f"{algorithm}, {'walk' if on_walk else 'Baird'}"
        unit = "sweeps" if expected else "env steps"
        numba_rate = median_rate(lambda r=raw, c=count: linear_rate(r, "numba", c), max(3, repeats))
        if expected:
            print(f"{label:40s} {'-':>14s} {numba_rate:13,.0f} {'-':>7s} {count:9,d} {unit:>10s}")
            continue
        gym_count = max(10, count // 20)
        gym_rate = median_rate(lambda r=raw, c=gym_count: linear_rate(r, "gymnasium", c), repeats)
        print(
            f"{label:40s} {gym_rate:14,.0f} {numba_rate:13,.0f} {numba_rate / gym_rate:6,.0f}x "
            f"{count:9,d} {unit:>10s}"
        )


POLICY_GRADIENT_CURVES = (
    {"algorithm": "reinforce", "alpha": 2**-13, "theta0": [-1.47, 1.47], "min_probability": 0.05},
    {"algorithm": "reinforce_baseline", "alpha": 2**-9, "alpha_w": 2**-6,
     "theta0": [-1.47, 1.47], "min_probability": 0.05},
    {"algorithm": "actor_critic", "alpha": 2**-9, "alpha_w": 2**-6, "theta0": [-1.47, 1.47],
     "min_probability": 0.05},
    {"algorithm": "actor_critic_lambda", "alpha": 2**-9, "alpha_w": 2**-6, "lambda_theta": 0.9,
     "lambda_w": 0.9, "theta0": [-1.47, 1.47], "min_probability": 0.05},
)  # fmt: skip
"""the policy-gradient section's rows: each method on the short corridor"""


def policy_gradient_rate(curve: dict, engine: str, episodes: int) -> tuple[int, float]:
    """One run of a policy-gradient curve on the short corridor: ``(env steps, seconds)``."""
    from cartpole_q.experiments import linear, policy_gradient
    from cartpole_q.experiments.study import RunHandle, study_of

    study = policy_gradient.read_study(study_of(
        {"kind": "policy_gradient", "world": {"id": "cartpole_q/ShortCorridor-v0"},
         "episodes": episodes, "engine": engine, "curves": [curve]},
        "benchmark", "b", Path("."),
    ))  # fmt: skip
    linear.world_table(study.world_id, study.world_kwargs, study.where)
    start = time.perf_counter()
    record = policy_gradient.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: False, lambda n: None)
    )
    seconds = time.perf_counter() - start
    assert record is not None
    return int(np.sum(record.arrays["lengths"])), seconds


def policy_gradient_rows(repeats: int, scale: float) -> None:
    """Each policy-gradient method: the numba engine against the gymnasium engine, the same run."""
    print(
        f"{'policy-gradient method':40s} {'gymnasium':>14s} {'numba':>13s} {'ratio':>7s} "
        f"{'episodes':>9s}"
    )
    episodes = max(50, int(1000 * scale))
    for curve in POLICY_GRADIENT_CURVES:
        policy_gradient_rate(curve, "numba", 2)  # compile or load the cache
        numba_rate = median_rate(
            lambda c=curve: policy_gradient_rate(c, "numba", episodes), max(3, repeats)
        )
        gym_rate = median_rate(
            lambda c=curve: policy_gradient_rate(c, "gymnasium", max(20, episodes // 10)), repeats
        )
        print(
            f"{curve['algorithm'] + ', short corridor':40s} {gym_rate:14,.0f} {numba_rate:13,.0f} "
            f"{numba_rate / gym_rate:6,.0f}x {episodes:9,d}"
        )


def average_reward_rate(engine: str, steps: int) -> tuple[int, float]:
    """One run of Figure 10.5's curve on access control: ``(env steps, seconds)``."""
    from cartpole_q.experiments import average_reward, linear
    from cartpole_q.experiments.study import RunHandle, study_of

    study = average_reward.read_study(study_of(
        {"kind": "average_reward", "world": {"id": "cartpole_q/AccessControl-v0"},
         "steps": steps, "engine": engine,
         "curves": [{"algorithm": "differential_sarsa", "alpha": 0.01, "beta": 0.01}]},
        "benchmark", "b", Path("."),
    ))  # fmt: skip
    linear.world_table(study.world_id, study.world_kwargs, study.where)
    start = time.perf_counter()
    record = average_reward.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: False, lambda n: None)
    )
    seconds = time.perf_counter() - start
    assert record is not None
    return steps, seconds


def average_reward_rows(repeats: int, scale: float) -> None:
    """Differential SARSA: the numba engine against the gymnasium engine."""
    print(
        f"{'average-reward method':40s} {'gymnasium':>14s} {'numba':>13s} {'ratio':>7s} {'steps':>11s}"
    )
    steps = max(100_000, int(2_000_000 * scale))
    average_reward_rate("numba", 10)  # compile or load the cache
    numba_rate = median_rate(lambda: average_reward_rate("numba", steps), max(3, repeats))
    gym_rate = median_rate(
        lambda: average_reward_rate("gymnasium", max(10_000, steps // 40)), repeats
    )
    print(
        f"{'differential_sarsa, access control':40s} {gym_rate:14,.0f} {numba_rate:13,.0f} "
        f"{numba_rate / gym_rate:6,.0f}x {steps:11,d}"
    )


TILINGS = (1, 2, 4, 8, 16)
"""the tiles section's tiling counts (1: the plain grid, the baseline)"""


def tile_rows(repeats: int, scale: float) -> None:
    """MountainCar with the shipped mountaincar_tiles (SARSA(lambda)) at each tiling count.

    Each step sums and updates ``T`` weights per action and traces ``T`` tiles, so a step
    costs more with more tilings; the rates are against one tiling in the same run, and
    the gymnasium engine's rate at 8 tilings gives the twin's ratio.
    """
    print(f"{'mountaincar_tiles, tilings (numba)':40s} {'env steps/s':>14s} {'vs 1 tiling':>12s}")
    episodes = max(50, int(300 * scale))
    baseline = None
    for tilings in TILINGS:
        mapping = load_config("mountaincar_tiles", {"discretization.tilings": tilings}).to_dict()
        engine_rate(mapping, "numba", 2, 0)  # compile or load the cache
        rate = median_rate(lambda c=mapping: engine_rate(c, "numba", episodes, 0), max(5, repeats))
        baseline = baseline or rate
        print(f"{f'T = {tilings}':40s} {rate:14,.0f} {rate / baseline:11.0%}")
    config = load_config("mountaincar_tiles", {"discretization.tilings": 8}).to_dict()
    engine_rate(config, "gymnasium", 1, 0)
    gym_rate = median_rate(
        lambda: engine_rate(config, "gymnasium", max(5, episodes // 20), 0), repeats
    )
    numba_rate = median_rate(lambda: engine_rate(config, "numba", episodes, 0), max(5, repeats))
    print(
        f"{'T = 8: gymnasium engine / numba':40s} {gym_rate:14,.0f} / {numba_rate:,.0f} "
        f"= {numba_rate / gym_rate:,.0f}x"
    )


def progress_row(repeats: int, python_episodes: int) -> None:
    """The progress bar's cost, measured as interleaved pairs so machine drift cancels out."""
    engine_rate(None, "gymnasium", 2, 0)
    plain, with_bar = [], []
    for _ in range(max(3, repeats)):
        plain.append(median_rate(lambda: engine_rate(None, "gymnasium", python_episodes, 0), 1))
        with_bar.append(
            median_rate(
                lambda: engine_rate(None, "gymnasium", python_episodes, 0, progress=True), 1
            )
        )
    cost = 1.0 - statistics.median(with_bar) / statistics.median(plain)
    print(
        f"progress bar on the gymnasium engine: {statistics.median(with_bar):,.0f} vs "
        f"{statistics.median(plain):,.0f} env steps/s without, a cost of {100 * cost:.1f}% "
        f"(medians of {len(plain)} interleaved runs each)"
    )
    assert math.isfinite(cost)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="fewer episodes (a rough check)")
    parser.add_argument("--only", choices=SECTIONS, help="run one section of rows")
    args = parser.parse_args()
    scale = 0.2 if args.quick else 1.0
    python_episodes = max(20, int(400 * scale))
    numba_episodes = max(1000, int(100_000 * scale))
    sections = (args.only,) if args.only else SECTIONS

    q_learning = None
    for number, section in enumerate(sections):
        if number:
            print()
        if section == "cartpole":
            q_learning = cartpole_rows(args.repeats, python_episodes, numba_episodes)
        elif section == "algorithms":
            algorithm_rows(args.repeats, numba_episodes, q_learning)
        elif section == "environments":
            environment_rows(args.repeats, scale)
        elif section == "tabular":
            tabular_rows(args.repeats, scale)
        elif section == "prediction":
            prediction_rows(args.repeats, scale)
        elif section == "tiles":
            tile_rows(args.repeats, scale)
        elif section == "linear":
            linear_rows(args.repeats, scale)
        elif section == "policy_gradient":
            policy_gradient_rows(args.repeats, scale)
        elif section == "average_reward":
            average_reward_rows(args.repeats, scale)
        else:
            progress_row(args.repeats, python_episodes)


if __name__ == "__main__":
    main()
