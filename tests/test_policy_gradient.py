"""Policy gradient (issue 50, Figures 13.1, 13.2): REINFORCE, with a baseline, actor-critic.

Byte for byte: both engines against the plain re-derivation of docs/algorithms.md
(``tests/reference_policy_gradient.py``) for every algorithm, both policy layers, both value
layers, with and without the floor. Exact where the answer is known: the short corridor's
best start value (``2 - √2``, from its closed form), the softmax's gradient against finite
differences, the draw's frequencies. Bad input is refused naming the file and key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cartpole_q.experiments import policy_gradient as study_kind
from cartpole_q.experiments.study import RunHandle, study_of
from cartpole_q.rl import policy_gradient as methods
from tests import reference_policy_gradient as reference
from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

CORRIDOR = "cartpole_q/ShortCorridor-v0"
WALK = "cartpole_q/RandomWalk5-v0"
THETA0 = [-1.47, 1.47]


def read(raw: Mapping[str, Any]) -> study_kind.Study:
    """A policy-gradient study from its mapping."""
    return study_kind.read_study(study_of(raw, "t.yaml", "t", Path(".")))


def run(raw: Mapping[str, Any], seed: int) -> dict[str, np.ndarray]:
    """The first curve's run on ``seed``: its arrays."""
    record = study_kind.run_one(
        read(raw), {"curve": 0, "seed": seed}, RunHandle(lambda: False, lambda n: None)
    )
    assert record is not None
    return {name: np.asarray(value) for name, value in record.arrays.items()}


CASES = [
    # world, kwargs, gamma, curve (as a study file gives it)
    (CORRIDOR, {}, 1.0, {"algorithm": "reinforce", "alpha": 2**-12, "theta0": THETA0}),
    (CORRIDOR, {}, 1.0,
     {"algorithm": "reinforce", "alpha": 2**-9, "theta0": THETA0, "min_probability": 0.05}),
    (CORRIDOR, {}, 1.0,
     {"algorithm": "reinforce_baseline", "alpha": 2**-9, "alpha_w": 2**-6, "theta0": THETA0}),
    (CORRIDOR, {}, 0.9,
     {"algorithm": "actor_critic", "alpha": 0.05, "alpha_w": 0.1, "value_features": "table"}),
    (WALK, {}, 0.9,
     {"algorithm": "reinforce_baseline", "alpha": 0.1, "alpha_w": 0.2, "value_features": "table",
      "theta0": 0.3, "w0": 0.5}),
    (WALK, {"max_episode_steps": 6}, 1.0,
     {"algorithm": "actor_critic", "alpha": 0.2, "alpha_w": 0.1, "min_probability": 0.1}),
    (CORRIDOR, {}, 0.95,
     {"algorithm": "actor_critic_lambda", "alpha": 0.02, "alpha_w": 0.05, "lambda_theta": 0.9,
      "lambda_w": 0.7, "theta0": THETA0}),
    (WALK, {}, 0.9,
     {"algorithm": "actor_critic_lambda", "alpha": 0.1, "alpha_w": 0.1, "lambda_theta": 0.5,
      "lambda_w": 0.8, "value_features": "table", "min_probability": 0.05}),
]  # fmt: skip


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize(
    ("world", "kwargs", "gamma", "curve"), CASES,
    ids=[f"{c[3]['algorithm']}-{c[0].split('/')[1]}-{i}" for i, c in enumerate(CASES)],
)  # fmt: skip
def test_every_algorithm_and_layer_equals_the_re_derivation_byte_for_byte(
    engine: str, world: str, kwargs: dict[str, Any], gamma: float, curve: dict[str, Any]
) -> None:
    raw = {"kind": "policy_gradient", "world": {"id": world, "kwargs": kwargs}, "gamma": gamma,
           "seeds": 4, "episodes": 40, "engine": engine, "curves": [curve]}  # fmt: skip
    ours = run(raw, seed=4)
    theirs = reference.run_policy_gradient(
        world, kwargs, gamma, curve["algorithm"], curve["alpha"], curve.get("alpha_w", 0.0),
        curve.get("policy_features"), curve.get("value_features"), curve.get("theta0", 0.0),
        curve.get("w0", 0.0), 4, 40, curve.get("min_probability", 0.0),
        curve.get("lambda_theta", 0.0), curve.get("lambda_w", 0.0),
    )  # fmt: skip
    assert ours["rewards"].tobytes() == theirs["rewards"].tobytes()
    assert ours["lengths"].tobytes() == theirs["lengths"].tobytes()
    assert ours["theta"].tobytes() == theirs["theta"].tobytes()
    if curve["algorithm"] != "reinforce":
        assert ours["w"].tobytes() == theirs["w"].tobytes()
    assert not np.array_equal(
        ours["theta"], np.broadcast_to(curve.get("theta0", 0.0), ours["theta"].shape)
    )


def test_a_policy_that_never_reaches_the_goal_is_cut_at_ten_thousand_steps() -> None:
    raw = {"kind": "policy_gradient", "world": {"id": CORRIDOR}, "episodes": 2,
           "curves": [{"algorithm": "reinforce", "alpha": 1e-9, "theta0": [-30, 30]}]}  # fmt: skip
    ours = run(raw, seed=0)
    assert ours["lengths"].tolist() == [10_000, 10_000]
    assert ours["rewards"].tolist() == [-10_000.0, -10_000.0]


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_long_episodes_return_to_python_every_hundred_thousand_steps(engine: str) -> None:
    """A policy that never reaches the goal: 10,000-step episodes, 10 per compiled call."""
    raw = {"kind": "policy_gradient", "world": {"id": CORRIDOR}, "episodes": 12, "engine": engine,
           "curves": [{"algorithm": "reinforce", "alpha": 1e-9, "theta0": [-30, 30]}]}  # fmt: skip
    study = read(raw)
    reports: list[int] = []
    record = study_kind.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: False, reports.append)
    )
    assert record is not None
    assert reports == [10, 12]
    assert np.asarray(record.arrays["lengths"]).tolist() == [10_000] * 12
    stopped = study_kind.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: len(reports) > 2, reports.append)
    )
    assert stopped is None and reports[2:] == [10]  # asked between calls: it stops after one


def test_the_short_corridors_best_start_value_is_its_closed_form() -> None:
    # v(s0) = -(4 - 6p + 2p^2) / (p (1 - p))... solved by hand from the three Bellman equations:
    # v0 = v1 - 1/p, v1 = -1 + p v0 + (1 - p) v2, v2 = -1 + (1 - p) v1; best at p = 2 - √2.
    study = read({"kind": "policy_gradient", "world": {"id": CORRIDOR}, "episodes": 1,
                  "curves": [{"algorithm": "reinforce", "alpha": 0.1}],
                  "figure": {"kind": "rewards", "optimum": True}})  # fmt: skip
    p, value = study_kind.best_start(study)
    assert p == pytest.approx(2 - math.sqrt(2), abs=1e-4)
    facts = study_kind.world_facts(CORRIDOR, (), "t.yaml")
    for chance in (0.05, 0.3, 0.5, 0.9):
        closed = (2 * chance - 4) / (chance * (1 - chance))
        assert study_kind.start_value(facts, chance) == pytest.approx(closed, rel=1e-12)
    assert value == pytest.approx((2 * p - 4) / (p * (1 - p)), rel=1e-12)
    assert value == pytest.approx(-11.6569, abs=1e-4)
    assert (p, value) == reference.best_start_value(CORRIDOR, {})


@settings(max_examples=40, deadline=None)
@given(
    theta=st.lists(st.floats(-5, 5), min_size=4, max_size=4),
    action=st.integers(0, 1),
    state=st.integers(0, 1),
)
def test_the_eligibility_vector_is_the_gradient_of_log_pi(
    theta: list[float], action: int, state: int
) -> None:
    index = np.arange(8, dtype=np.int64).reshape(4, 2) % 4
    value = np.array([[1.0, 0.5], [0.0, 2.0], [1.5, 0.0], [0.3, 0.7]])
    agent = methods.new_agent(
        "reinforce", methods.Settings(0.1, 0.0, 1.0), 2,
        methods.Layer(index, value, np.asarray(theta)),
        methods.Layer(np.zeros((2, 1), dtype=np.int64), np.ones((2, 1)), np.zeros(1)),
    )  # fmt: skip

    def log_pi(weights: np.ndarray) -> float:
        trial = agent._replace(theta=weights.copy(), probabilities=np.zeros(2))
        methods.policy(trial, state)
        return math.log(trial.probabilities[action])

    before = agent.theta.copy()
    methods.move_policy(agent, state, action, 1.0)  # θ + 1.0 * g: g is the step
    gradient = agent.theta - before
    for i in range(4):
        bump = np.zeros(4)
        bump[i] = 1e-6
        numeric = (log_pi(before + bump) - log_pi(before - bump)) / 2e-6
        assert gradient[i] == pytest.approx(numeric, abs=1e-6)


def test_the_floor_keeps_either_action_at_least_as_likely_as_it_says() -> None:
    index, value = np.array([[0], [1]]), np.ones((2, 1))
    agent = methods.new_agent(
        "reinforce", methods.Settings(0.1, 0.0, 1.0, floor=0.05), 2,
        methods.Layer(index, value, np.array([-9.0, 9.0])),
        methods.Layer(np.zeros((1, 1), dtype=np.int64), np.ones((1, 1)), np.zeros(1)),
    )  # fmt: skip
    methods.policy(agent, 0)
    assert agent.probabilities.tolist() == [0.05, 0.95]
    rng = np.random.Generator(np.random.PCG64(1))
    draws = [methods.choose(agent, 0, rng) for _ in range(4000)]
    assert 0.04 < draws.count(0) / 4000 < 0.06


def test_a_study_runs_by_one_command_with_its_figure_and_data(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "pg.yaml", {
        "kind": "policy_gradient", "name": "pg", "world": {"id": CORRIDOR}, "seeds": "0-3",
        "episodes": 50,
        "curves": [{"label": "baseline", "algorithm": "reinforce_baseline", "alpha": 2**-9,
                    "alpha_w": 2**-6, "theta0": THETA0},
                   {"label": "plain", "algorithm": "reinforce", "alpha": 2**-13,
                    "theta0": THETA0}],
        "figure": {"kind": "rewards", "optimum": True},
    })  # fmt: skip
    out = tmp_path / "out"
    result = invoke("study", path, "--out", out, "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    summary = (out / "summary.txt").read_text(encoding="utf-8")
    assert "the best policy blind to the state: P(action 1) 0.5858, start value -11.6569" in summary
    assert "its starting policy (p 0.0502) has start value -81.77" in summary
    data = (out / "pg.csv").read_text(encoding="utf-8")
    assert "baseline" in data and "plain" in data and "v*(s₀) = -11.66" in data
    assert (out / "pg.png").stat().st_size > 10_000


BAD = [
    ({"world": {"id": "cartpole_q/Baird-v0"}}, "world: cartpole_q/Baird-v0 is continuing"),
    ({"curves": [{"algorithm": "reinforce", "alpha": 0.1, "alpha_w": 0.1}]},
     "curves[0].alpha_w: reinforce learns no value"),
    ({"curves": [{"algorithm": "actor_critic", "alpha": 0.1}]}, "curves[0].alpha_w: is missing"),
    ({"curves": [{"algorithm": "reinforce", "alpha": 0}]}, "curves[0].alpha: a step size must be above 0"),
    ({"curves": [{"algorithm": "reinforce", "alpha": 0.1, "theta0": [1, 2, 3]}]},
     "curves[0].theta0: must be a number (every weight) or a list of 2 numbers"),
    ({"world": {"id": WALK}, "curves": [{"algorithm": "reinforce", "alpha": 0.1,
                                          "policy_features": "declared"}]},
     "curves[0].policy_features: cartpole_q/RandomWalk5-v0 declares no features of its actions"),
    ({"curves": [{"algorithm": "reinforce", "alpha": 0.1, "min_probability": 0.7}]},
     "curves[0].min_probability: the least probability of either of two actions, in (0, 0.5)"),
    ({"world": {"id": WALK}, "figure": {"kind": "rewards", "optimum": True},
      "curves": [{"algorithm": "reinforce", "alpha": 0.1}]}, "figure.optimum: the best start value"),
    ({"episodes": 0}, "episodes: must be a whole number >= 1"),
    ({"curves": [{"algorithm": "actor_critic_lambda", "alpha": 0.1, "alpha_w": 0.1,
                  "lambda_theta": 0.9}]}, "curves[0].lambda_w: is missing"),
    ({"curves": [{"algorithm": "actor_critic", "alpha": 0.1, "alpha_w": 0.1, "lambda_w": 0.5}]},
     "curves[0].lambda_w: actor_critic keeps no traces"),
    ({"curves": [{"algorithm": "actor_critic_lambda", "alpha": 0.1, "alpha_w": 0.1,
                  "lambda_theta": 1.5, "lambda_w": 0.5}]}, "curves[0].lambda_theta: a trace decay in [0, 1]"),
    ({"episodes": 10**13}, "episodes"),
]  # fmt: skip


@pytest.mark.parametrize(("change", "message"), BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_bad_input_is_refused_naming_the_file_and_key(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    raw = {"kind": "policy_gradient", "name": "bad", "world": {"id": CORRIDOR}, "episodes": 5,
           "curves": [{"algorithm": "reinforce", "alpha": 0.1}], **change}  # fmt: skip
    path = write_yaml(tmp_path / "bad.yaml", raw)
    out = tmp_path / "out"
    assert_refused(invoke("study", path, "--out", out), "bad.yaml", message)
    assert not out.exists()
