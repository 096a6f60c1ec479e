"""Compiling a study's loops once, before its runs: the names numba caches them under.

The loops here (Q-learning and SARSA on CartPole's twin, with and without ``env.randomize``,
on tiles, and on the gymnasium engine, whose one loop per algorithm takes a Box, a Discrete
and a Tuple alike) are loops the rest of the suite compiles anyway, so on a cold cache they
cost no extra compilation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import cartpole_q.engines.plan
import cartpole_q.numba_cache
from cartpole_q.config import Config, load_config
from cartpole_q.engines import loop_names, resolve_engine
from cartpole_q.engines.plan import plan_run
from cartpole_q.envs.gym import inspect_env
from cartpole_q.experiments.compiling import compile_ahead
from cartpole_q.numba_cache import is_cached
from cartpole_q.training import train
from tests.conftest import invoke, write_yaml

RANDOMIZE = {"env.randomize": {"length": [0.4, 0.6]}}
TILES = {"discretization": {"bins": [1, 1, 3, 5], "tilings": 3}}


def _config(**overrides: Any) -> Config:
    return load_config(overrides={"train.episodes": 2, "eval.episodes": 1, **overrides})


@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        ({}, "train_exploring__q_learning_"),
        (RANDOMIZE, "train_exploring__q_learning_"),
        ({**TILES, "engine": "numba"}, "train_exploring__q_learning_"),
        ({"engine": "gymnasium"}, "next_step__q_learning_"),
        ({"env.id": "FrozenLake-v1", "engine": "gymnasium"}, "next_step__q_learning_"),
        ({"env.id": "Blackjack-v1", "engine": "gymnasium"}, "next_step__q_learning_"),
    ],
    ids=["numba", "randomized", "tiles", "box", "discrete", "tuple"],
)
def test_loop_name_is_what_numba_caches_once_trained(
    overrides: dict[str, Any], expected: str
) -> None:
    config = _config(**overrides)
    info = inspect_env(config)
    (name,) = loop_names(config, info, resolve_engine(config, info))  # two episodes explore
    assert name.startswith(expected)
    kind = {"randomized": "__randomized", "tiles": "__tiles"}
    for key, suffix in (("env.randomize", kind["randomized"]), ("discretization", "__tiles")):
        assert name.endswith(suffix) == (key in overrides)
    train(config, final_eval=False)
    assert is_cached(name)


def test_every_world_but_tiles_shares_the_gymnasium_engines_step_functions() -> None:
    """Observations come as float64 values: one compilation per algorithm for every world."""
    names = set()
    for env_id in ("CartPole-v1", "FrozenLake-v1", "Blackjack-v1", "cartpole_q/RandomWalk-v0"):
        config = _config(**{"env.id": env_id, "engine": "gymnasium"})
        (name,) = loop_names(config, inspect_env(config), "gymnasium")
        names.add(name)
    assert names == {next(iter(names))} and next(iter(names)).endswith("__values")
    tiled = _config(engine="gymnasium", **TILES)
    assert loop_names(tiled, inspect_env(tiled), "gymnasium")[0].endswith("__tiles")


def test_compile_ahead_asks_once_per_distinct_loop_and_fills_the_cache(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    configs = [
        _config(),
        _config(**{"seed": 7, "agent.alpha": 0.3, "env.physics": {"length": 0.6}}),
        _config(**{"agent.algorithm": "sarsa"}),
        _config(**RANDOMIZE),
    ]
    plans = [plan_run(config) for config in configs]  # the workers inspect nothing again
    asked: list[str] = []

    def never_cached(name: str) -> bool:
        asked.append(name)
        return False

    def inspected(*args: Any) -> None:
        raise AssertionError("a compile worker inspected an environment its plan carries")

    monkeypatch.setattr(cartpole_q.numba_cache, "is_cached", never_cached)
    monkeypatch.setattr(cartpole_q.engines.plan, "inspect_env", inspected)  # (workers fork)
    assert compile_ahead(plans, workers=2) == 3  # seed, alpha and physics are no new loop
    assert len(asked) == len(set(asked)) == 3
    monkeypatch.undo()
    assert all(is_cached(name) for name in asked)
    assert compile_ahead(plans, workers=2) == 0


def test_a_sweep_says_how_many_loops_it_compiles_first(
    in_tmp: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(cartpole_q.numba_cache, "is_cached", lambda name: False)
    sweep = write_yaml(
        in_tmp / "s.yaml",
        {
            "base": {"train": {"episodes": 3, "eval_every": 0}, "eval": {"episodes": 1}},
            "grid": {"agent.algorithm": ["q_learning", "sarsa"]},
            "seeds": "0-1",
        },
    )
    result = invoke("sweep", sweep, "--out", in_tmp / "out", "--workers", 2)
    assert result.exit_code == 0, result.output
    assert "compiling 2 training loops first" in result.stderr
    result = invoke("sweep", sweep, "--out", in_tmp / "quiet", "--workers", 2, "--quiet")
    assert "compiling" not in result.stderr


def test_the_numba_engine_compiles_the_loops_its_epsilon_plays(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """An exploring loop for epsilon > 0, a greedy one for epsilon 0: a run names those it plays.

    After exploring episodes, the greedy loop only where it is cached or its episodes may
    take a million steps (engines/base.py, ``greedy_loop_pays``).
    """
    cached: set[str] = set()
    monkeypatch.setattr(cartpole_q.engines.base, "is_cached", lambda name: name in cached)

    def names(greedy_loop: bool | None = None, **overrides: Any) -> list[str]:
        config = load_config(overrides=overrides)
        info = inspect_env(config)
        return [
            name.split("__")[0] for name in loop_names(config, info, "numba", None, greedy_loop)
        ]

    # The default's log schedule reaches 0 at episode 89 (0-based) of its 1,000: at most
    # 911 x 500 greedy steps, under a million.
    assert names() == ["train_exploring"]
    assert names(True) == ["train_exploring", "train_greedy"]
    assert names(**{"train.episodes": 2089}) == ["train_exploring", "train_greedy"]
    assert names(**{"train.episodes": 2088}) == ["train_exploring"]
    assert names(False, **{"train.episodes": 5000}) == ["train_exploring"]
    config = load_config()
    cached.update(loop_names(config, inspect_env(config), "numba", None, True))
    assert names() == ["train_exploring", "train_greedy"]  # cached: it is played
    assert names(**{"train.episodes": 89}) == ["train_exploring"]
    assert names(**{"agent.epsilon": 0.1}) == ["train_exploring"]
    assert names(**{"agent.epsilon": 0.0}) == ["train_greedy"]  # the only loop it plays
    assert names(False, **{"agent.epsilon": 0.0}) == ["train_greedy"]


def test_a_run_compiles_the_greedy_loop_where_it_pays_or_is_cached(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The exploring loop plays every episode of the default config, greedy ones included.

    The decision is the engine's, made once per run: a later chunk of greedy episodes stays
    on the exploring loop (the test re-derivation proves both ways byte-identical).
    """
    from cartpole_q.engines import make_engine
    from cartpole_q.engines.base import TrainingState

    monkeypatch.setattr(cartpole_q.engines.base, "is_cached", lambda name: False)

    def engine_and_state(greedy_loop: bool | None = None, **overrides: Any) -> tuple[Any, Any]:
        config = load_config(overrides=overrides)
        info = inspect_env(config)
        state = TrainingState.fresh(config, info, np.random.default_rng(0))
        return make_engine("numba", config, info, 0, greedy_loop=greedy_loop), state

    engine, state = engine_and_state()
    assert engine.loops(state) == (False,)
    state.episode = 500  # a later chunk: greedy episodes only
    assert engine.loops(state) == (False,)
    engine, state = engine_and_state(**{"train.episodes": 3000})
    assert engine.loops(state) == (False, True)
    engine, state = engine_and_state(True)
    assert engine.loops(state) == (False, True)
    state.episode = 500
    assert engine.loops(state) == (True,)
    engine, state = engine_and_state(**{"agent.epsilon": 0.0})
    assert engine.loops(state) == (True,)  # the only loop it plays
    # A run resumed among its greedy episodes plays the loops its first part played.
    engine, state = engine_and_state()
    state.episode = 500
    assert engine.loops(state) == (False,)
    engine, state = engine_and_state(**{"train.episodes": 3000})
    state.episode = 500
    assert engine.loops(state) == (True,)


@pytest.mark.parametrize(
    "overrides",
    [{}, {"train.episodes": 3000}, {"agent.epsilon": 0.1}, {"agent.epsilon": 0.0}, RANDOMIZE],
)
@pytest.mark.parametrize("cached", [False, True])
def test_a_runs_loops_are_the_loops_its_notice_names(
    monkeypatch: pytest.MonkeyPatch, overrides: dict[str, Any], cached: bool
) -> None:
    """``loop_names`` (the compile notice, a sweep's compile-ahead) and the engine agree."""
    from cartpole_q.engines import make_engine
    from cartpole_q.engines.base import TrainingState

    monkeypatch.setattr(cartpole_q.engines.base, "is_cached", lambda name: cached)
    config = load_config(overrides=overrides)
    info = inspect_env(config)
    state = TrainingState.fresh(config, info, np.random.default_rng(0))
    engine = make_engine("numba", config, info, 0)
    names = {name.split("__")[0] for name in loop_names(config, info, "numba")}
    assert names == {
        f"train_{'greedy' if greedy else 'exploring'}" for greedy in engine.loops(state)
    }
