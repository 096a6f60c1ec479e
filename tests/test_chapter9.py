"""Sutton & Barto chapter 9: the 1000-state walk (Example 9.1) and state aggregation.

The world, its table and its groups; the true values on the aggregated world (one per
true state, measured on the state's group); the on-policy distribution; the values figure
drawn against the true states. The re-derivation of the algorithms on the aggregated walk
is in ``test_rederivation.py`` (case ``walk1000``).
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from cartpole_q import load_config
from cartpole_q.engines.base import prediction_truth
from cartpole_q.envs.gym import inspect_env
from cartpole_q.envs.models import EnvModel, env_model
from cartpole_q.envs.registry import twin_settings
from cartpole_q.experiments.run import execute_run, prepare, start_run
from cartpole_q.families.tables import twin as transition_table
from cartpole_q.rl.solvers import on_policy_distribution, reachable_states
from cartpole_q.store import rundir
from cartpole_q.training import train
from tests.conftest import invoke, write_yaml

WALK = "cartpole_q/RandomWalk1000-v0"


def _config(groups: int | None = None, **agent: Any) -> Any:
    kwargs = {} if groups is None else {"groups": groups}
    return load_config({
        "env": {"id": WALK, "kwargs": kwargs},
        "agent": {"algorithm": "td", "policy": "random", "gamma": 1.0, **agent},
    })  # fmt: skip


@pytest.mark.parametrize("groups", [None, 10, 20])
def test_the_walk_passes_check_env_and_observes_its_groups(groups: int | None) -> None:
    env = gymnasium.make(WALK, **({} if groups is None else {"groups": groups}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    assert env.spec is not None and env.spec.max_episode_steps == 10_000
    assert env.action_space.n == 2 and len(env.unwrapped.P) == 1002
    assert env.observation_space.n == (1002 if groups is None else groups)
    observation, _ = env.reset(seed=0)
    assert observation == (500 if groups is None else 499 * groups // 1000)
    if groups is not None:  # groups of 1000 / groups neighbours; each end in its neighbour's
        expected = [0, *((s - 1) * groups // 1000 for s in range(1, 1001)), groups - 1]
        assert env.unwrapped.observation_of_state.tolist() == expected


def test_the_table_is_example_9_1s() -> None:
    """Jumps of 1-100 either way, each 1/100; the jumps beyond an end terminate there."""
    table = gymnasium.make(WALK).unwrapped.P
    for state in range(1002):
        for action in (0, 1):
            assert math.isclose(sum(p for p, *_ in table[state][action]), 1.0, abs_tol=1e-12)
    assert table[500][1] == [(0.01, 500 + k, 0.0, False) for k in range(1, 101)]
    assert table[50][0][:49] == [(0.01, 50 - k, 0.0, False) for k in range(1, 50)]
    assert table[50][0][49:] == [(0.51, 0, -1.0, True)]
    assert table[1000][1] == [(1.0, 1001, 1.0, True)]
    assert table[0][0] == [(1.0, 0, 0.0, True)] and table[1001][1] == [(1.0, 1001, 0.0, True)]
    with pytest.raises(ValueError, match="groups must divide"):
        gymnasium.make(WALK, groups=3)


def test_the_true_values_are_the_books_s_curve_per_true_state() -> None:
    """v(1) = -0.922 ... v(1000) = 0.922, odd about the middle; the same with groups."""
    plain = prediction_truth(_config(), inspect_env(_config()))
    assert plain.states.tolist() == list(range(1, 1001)) == plain.rows[:, 0].tolist()
    values = plain.values
    assert values[0] == pytest.approx(-0.92196046, abs=1e-8)
    assert values[-1] == pytest.approx(0.92196046, abs=1e-8)
    assert np.allclose(values, -values[::-1], atol=1e-12)
    assert np.all(np.diff(values) > 0)
    # Nearly straight in the middle, bending near the ends (the book's figure).
    assert values[399] == pytest.approx(-0.18964, abs=1e-5)
    assert values[99] == pytest.approx(-0.75418, abs=1e-5)
    grouped = prediction_truth(_config(10), inspect_env(_config(10)))
    assert grouped.states.tolist() == list(range(1, 1001))
    assert grouped.rows[:, 0].tolist() == [(s - 1) // 100 for s in range(1, 1001)]
    assert grouped.values.tobytes() == values.tobytes()  # the world is the same, observed in groups


def test_the_model_maps_each_state_to_its_group_and_the_twin_plays_it() -> None:
    model = env_model(_config(20).env)
    assert isinstance(model, EnvModel) and model.aggregates
    assert model.row_of_state[[0, 1, 50, 51, 1000, 1001]].tolist() == [0, 0, 0, 1, 19, 19]
    settings = twin_settings(WALK, {"groups": 20}, 10_000)
    assert not isinstance(settings, str)
    assert settings.twin.name == "tables_aggregated"
    assert settings.params[-1].tolist() == model.row_of_state.tolist()
    # The plain table twin would observe the states: it refuses a world that groups them.
    refused = transition_table.twin_params({"groups": 20}, WALK)
    assert isinstance(refused, str) and "observes groups of states" in refused


def test_the_on_policy_distribution_is_figure_9_1s() -> None:
    """mu peaks by the start (about 0.0137, the book's axis) and sums to 1."""
    model = env_model(_config().env)
    assert isinstance(model, EnvModel)
    pi = np.full((1002, 2), 0.5)
    states = np.flatnonzero(reachable_states(model.model, pi))[1:-1]
    mu = on_policy_distribution(model.model, pi, states)
    assert math.isclose(float(mu.sum()), 1.0, abs_tol=1e-12)
    assert abs(int(np.argmax(mu)) + 1 - 500) <= 2
    assert float(mu.max()) == pytest.approx(0.0137, abs=0.0001)
    assert float(mu[0]) == pytest.approx(0.000148, abs=1e-6)  # a hundredth of the peak at the ends


def test_a_values_figure_draws_each_true_state_on_its_group_with_mu(tmp_path: Path) -> None:
    """Figure 9.1's kind: x is the true state; V of its group (a staircase); mu shaded."""
    study = write_yaml(
        tmp_path / "values.yaml",
        {
            "name": "values",
            "base": {
                "env": {"id": WALK, "kwargs": {"groups": 10}},
                "agent": {"algorithm": "mc_prediction", "gamma": 1.0, "alpha": 0.01},
                "train": {"episodes": 20, "eval_every": 0, "checkpoint_every": 0},
                "eval": {"episodes": 1},
            },
            "seeds": "0",
            "grid": {"agent.alpha": [0.01]},
            "figure": {"metric": "values", "distribution": True, "file": "v.png"},
        },
    )  # fmt: skip
    done = invoke("sweep", study, "--out", tmp_path / "sweep", "-q")
    assert done.exit_code == 0, done.output
    rows = list(csv.DictReader((tmp_path / "sweep" / "v.csv").open(encoding="utf-8")))
    series: dict[str, list[dict[str, str]]] = {}
    for row in rows:
        series.setdefault(row["series"], []).append(row)
    mu_name = "on-policy distribution mu (shaded, right axis)"
    assert set(series) == {mu_name, "initial values", "alpha 0.01", "true values"}
    for found in series.values():
        assert [float(row["x"]) for row in found] == [float(s) for s in range(1, 1001)]
    mu = np.array([float(row["y"]) for row in series[mu_name]])
    assert math.isclose(float(mu.sum()), 1.0, abs_tol=1e-9) and float(mu.max()) > 0.013
    tables = np.load(tmp_path / "sweep" / "points" / "000" / "q_tables.npz")
    v = tables[tables.files[0]].reshape(-1)
    assert v.shape == (10,)
    drawn = [float(row["y"]) for row in series["alpha 0.01"]]
    assert drawn == [float(v[(s - 1) // 100]) for s in range(1, 1001)]  # the staircase


def test_the_distribution_needs_the_values_figure(tmp_path: Path) -> None:
    study = {
        "name": "wrong",
        "base": {"env": {"id": WALK, "kwargs": {"groups": 10}},
                 "agent": {"algorithm": "td", "gamma": 1.0}, "train": {"episodes": 2}},
        "seeds": "0",
        "figure": {"metric": "rms_error", "distribution": True},
    }  # fmt: skip
    refused = invoke("sweep", write_yaml(tmp_path / "w.yaml", study), "--out", tmp_path / "s")
    assert refused.exit_code == 2, refused.output
    assert "figure.distribution" in refused.stderr and "Traceback" not in refused.output


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_an_interrupted_aggregated_run_resumes_byte_identically(
    tmp_path: Path, engine: str
) -> None:
    overrides = {
        "env.id": WALK, "env.kwargs.groups": 20, "engine": engine, "agent.gamma": 1.0,
        "agent.algorithm": "n_step_td", "agent.n": 4, "agent.alpha": 0.2,
        "train.episodes": 40, "train.checkpoint_every": 10,
    }  # fmt: skip
    whole = train(load_config(overrides=overrides), final_eval=False)
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    polls = iter(range(10**9))
    outcome = execute_run(run, prepared, should_stop=lambda: next(polls) >= 2)
    assert outcome.result.interrupted
    resumed = invoke("train", "--resume", str(run), "-q")
    assert resumed.exit_code == 0, resumed.output
    assert np.load(run / rundir.V_TABLE_FILE).tobytes() == whole.v_table.tobytes()
    assert whole.v_table.shape == (20,)
    loaded = rundir.load_run(run)
    assert whole.errors is not None and loaded.errors is not None
    assert loaded.errors.tolist() == whole.errors.tolist()


def _asymptotes(groups: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """v_pi, mu, and the two fixed points of Section 9.4 with state aggregation, exact.

    Gradient MC's is each group's mu-weighted mean of v_pi (the minimum of VE, eq. 9.1);
    semi-gradient TD(0)'s solves ``A w = b`` (eq. 9.12), both from the walk's table.
    """
    model = env_model(_config().env)
    assert isinstance(model, EnvModel)
    pi = np.full((1002, 2), 0.5)
    states = np.arange(1, 1001)
    expected, matrix = model.model.stochastic_policy_matrix(pi)
    p_pi, r_pi = matrix[np.ix_(states, states)], expected[states]
    v = np.linalg.solve(np.eye(1000) - p_pi, r_pi)
    mu = on_policy_distribution(model.model, pi, states)
    features = np.zeros((1000, groups))
    features[np.arange(1000), np.arange(1000) * groups // 1000] = 1.0
    weighted = features.T * mu
    mc = np.linalg.solve(weighted @ features, weighted @ v)
    td = np.linalg.solve(weighted @ (features - p_pi @ features), weighted @ r_pi)
    return v, mu, mc, td


def test_gradient_mc_and_semi_gradient_td_approach_their_fixed_points() -> None:
    """Section 9.4: MC towards the VE minimum, TD towards its fixed point, farther from v_pi."""
    v, _, mc, td = _asymptotes(10)
    group = (np.arange(1000) * 10) // 1000
    assert np.sqrt(np.mean((mc[group] - v) ** 2)) == pytest.approx(0.0541, abs=1e-4)
    assert np.sqrt(np.mean((td[group] - v) ** 2)) == pytest.approx(0.1325, abs=1e-4)
    assert mc[0] > v[:100].mean() and td[0] > mc[0]  # the left end pulled up, TD the most
    # MC's targets vary more (whole returns, one sign per episode): a smaller alpha.
    for algorithm, alpha, target in (("mc_prediction", 1e-4, mc), ("td", 1e-3, td)):
        config = load_config({
            "seed": 0, "engine": "numba",
            "env": {"id": WALK, "kwargs": {"groups": 10}},
            "agent": {"algorithm": algorithm, "gamma": 1.0, "alpha": alpha, "q_init": 0.0},
            "train": {"episodes": 30000, "eval_every": 0, "checkpoint_every": 0},
        })  # fmt: skip
        learned = train(config, final_eval=False).v_table
        assert np.max(np.abs(learned - target)) < 0.06, (algorithm, learned, target)


# -- tile coding: the walk observed as a point (env.kwargs.position) ---------------------------

TILES = {"bins": [5], "low": [1.0], "high": [1001.0], "tilings": 50}


def test_the_walk_observed_as_a_point_passes_check_env_and_refuses_groups() -> None:
    env = gymnasium.make(WALK, position=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(env.unwrapped)
    observation, _ = env.reset(seed=3)
    assert observation.dtype == np.float32 and observation.tolist() == [500.0]
    with pytest.raises(ValueError, match="position and groups"):
        gymnasium.make(WALK, position=True, groups=10)
    settings = twin_settings(WALK, {"position": True}, 10_000)
    assert isinstance(settings, str)  # no twin observes points: the gymnasium engine


def test_the_truth_on_tiles_is_each_states_fifty_tiles() -> None:
    """Figure 9.10's coding: 50 tilings of 5 tiles of 200 states, offset by 4 states."""
    overrides = {
        "env.id": WALK, "env.kwargs": {"position": True}, "discretization": TILES,
        "agent.algorithm": "td", "agent.gamma": 1.0,
    }  # fmt: skip
    config = load_config(overrides=overrides)
    truth = prediction_truth(config, inspect_env(config))
    assert truth.rows.shape == (1000, 50) and truth.states.tolist() == list(range(1, 1001))
    table = load_config(overrides={**overrides, "discretization": None, "env.kwargs": {}})
    exact = prediction_truth(table, inspect_env(table))
    assert truth.values.tobytes() == exact.values.tobytes()  # the same walk, the same values
    # state 1 lies in tile 0 of every tiling; the tilings shift by 4 states (1/50 of 200)
    assert truth.rows[0].tolist() == [t * 6 for t in range(50)]
    tiling_1 = truth.rows[:, 1] - 6  # tiling 1's tile of each state
    assert tiling_1[:196].tolist() == [0] * 196 and tiling_1[196] == 1  # state 197 moves on
    no_truth = load_config(overrides={**overrides, "discretization": {**TILES, "tilings": 1}})
    assert not prediction_truth(no_truth, inspect_env(no_truth)).measured
