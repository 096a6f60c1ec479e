"""Average reward (issue 50, Figure 10.5): access control, differential semi-gradient SARSA.

Byte for byte: both engines against the plain re-derivation of docs/algorithms.md
(``tests/reference_average_reward.py``). Exact where the answer is known: the world's table
against Example 10.2's rules, the optimal gain of relative value iteration against a second
computation (the exact gain of its policy by a linear solve, the optimality equation, and
the discounted optimum as the discount nears 1), on the full task and on a small one checked
against every deterministic policy. Bad input is refused naming the file and key.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest

from cartpole_q.experiments import average_reward as study_kind
from cartpole_q.experiments.study import RunHandle, study_of
from cartpole_q.families.book_mdps.access_control import ACCEPT, REJECT, state_of
from cartpole_q.rl.mdp import FiniteMDP
from cartpole_q.rl.solvers import policy_gain, relative_value_iteration, value_iteration
from tests import reference_average_reward as reference
from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

ACCESS = "cartpole_q/AccessControl-v0"


def read(raw: Mapping[str, Any]) -> study_kind.Study:
    """An average-reward study from its mapping."""
    return study_kind.read_study(study_of(raw, "t.yaml", "t", Path(".")))


def model_of(kwargs: Mapping[str, Any] | None = None) -> FiniteMDP:
    env = gymnasium.make(ACCESS, **dict(kwargs or {}))
    world: Any = env.unwrapped
    return FiniteMDP.from_transitions(world.P, world.initial_state_distrib, 2)


CASES = [
    # kwargs, curve
    ({}, {"alpha": 0.01, "beta": 0.01, "epsilon": 0.1}),
    ({"servers": 3, "free_probability": 0.3}, {"alpha": 0.1, "beta": 0.05, "epsilon": 0.5,
                                               "w0": 1.5, "r_bar0": 2.0}),
    ({"servers": 2}, {"alpha": 0.2, "beta": 0.1, "epsilon": 0.0, "w0": 0.5, "r_bar0": 1.0}),
    ({"servers": 1}, {"alpha": 0.05, "beta": 0.5, "epsilon": 1.0}),
]  # fmt: skip


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize(("kwargs", "curve"), CASES, ids=[str(i) for i in range(len(CASES))])
def test_both_engines_equal_the_re_derivation_byte_for_byte(
    engine: str, kwargs: dict[str, Any], curve: dict[str, Any]
) -> None:
    raw = {"kind": "average_reward", "world": {"id": ACCESS, "kwargs": kwargs}, "seeds": 3,
           "steps": 3_001, "record_every": 500, "engine": engine,
           "curves": [{"algorithm": "differential_sarsa", **curve}]}  # fmt: skip
    record = study_kind.run_one(
        read(raw), {"curve": 0, "seed": 3}, RunHandle(lambda: False, lambda n: None)
    )
    assert record is not None
    ours = {name: np.asarray(value) for name, value in record.arrays.items()}
    theirs = reference.run_differential_sarsa(
        ACCESS, kwargs, curve["alpha"], curve["beta"], curve["epsilon"], curve.get("w0", 0.0),
        curve.get("r_bar0", 0.0), 3, 3_001, 500,
    )  # fmt: skip
    for name in ("at", "r_bar", "rate", "w", "visits"):
        assert ours[name].tobytes() == theirs[name].tobytes(), name
    assert ours["at"].tolist() == [500, 1000, 1500, 2000, 2500, 3000, 3001]
    assert int(ours["visits"].sum()) == 3_001
    assert not np.array_equal(ours["w"], np.full_like(ours["w"], curve.get("w0", 0.0)))


def test_the_world_is_example_10_2() -> None:
    world: Any = gymnasium.make(ACCESS).unwrapped
    assert len(world.P) == 44
    for index, priority in enumerate((1.0, 2.0, 4.0, 8.0)):
        for free in range(11):
            state = state_of(index, free)
            for action in (REJECT, ACCEPT):
                outcomes = world.P[state][action]
                served = action == ACCEPT and free > 0
                after = free - 1 if served else free
                busy = 10 - after
                assert len(outcomes) == (busy + 1) * 4
                assert sum(p for p, *_ in outcomes) == pytest.approx(1.0, abs=1e-12)
                assert {r for _, _, r, _ in outcomes} == {priority if served else 0.0}
                assert not any(t for *_, t in outcomes)
                # the chance that k servers free and the next customer has priority index j
                for p, following, _, _ in outcomes:
                    j, free_next = divmod(following, 11)
                    k = free_next - after
                    assert 0 <= j < 4 and 0 <= k <= busy
                    exact = math.comb(busy, k) * 0.06**k * 0.94 ** (busy - k) / 4
                    assert p == pytest.approx(exact, rel=1e-12)
    starts = np.flatnonzero(world.initial_state_distrib)
    assert [divmod(int(s), 11)[1] for s in starts] == [10, 10, 10, 10]


def test_the_optimal_gain_by_relative_value_iteration_agrees_with_a_second_computation() -> None:
    model = model_of()
    found = relative_value_iteration(model)
    # the exact gain of the policy it found, by one linear solve
    gain, values = policy_gain(model, found.policy)
    assert gain == pytest.approx(found.gain, abs=1e-10)
    assert np.allclose(values, found.values, atol=1e-8)
    # (gain, values) solve the average-reward optimality equation: no action improves
    backup = model.backup(values, 1.0)
    assert np.allclose(backup.max(axis=1) - values, gain, atol=1e-9)
    # the discounted optimum's (1 - gamma) v*(s) nears the gain as gamma nears 1
    for gamma, tolerance in ((0.999, 2e-2), (0.9999, 2e-3)):
        discounted = value_iteration(model, gamma, tolerance=1e-9)
        assert (1 - gamma) * discounted.values == pytest.approx(gain, abs=tolerance)
    assert found.gain == pytest.approx(2.747642, abs=1e-6)
    # the optimal policy: reject priority 1 always, priority 2 below 4 free servers
    policy = found.policy.reshape(4, 11)
    assert policy[0].tolist() == [0] * 11
    assert policy[1].tolist() == [0, 0, 0, 0] + [1] * 7
    assert policy[2].tolist() == policy[3].tolist() == [0] + [1] * 10
    theirs_gain, theirs_policy = reference.relative_value_iteration(ACCESS, {})
    assert found.gain == pytest.approx(theirs_gain, abs=1e-12)
    assert found.policy.tolist() == theirs_policy


def test_on_a_small_task_no_deterministic_policy_beats_the_optimal_gain() -> None:
    kwargs = {"servers": 2, "free_probability": 0.3}
    model = model_of(kwargs)
    found = relative_value_iteration(model)
    free_states = [s for s in range(model.n_states) if s % 3 > 0]  # where the actions differ
    gains = []
    for choice in itertools.product((0, 1), repeat=len(free_states)):
        policy = np.zeros(model.n_states, dtype=np.int64)
        policy[free_states] = choice
        gains.append(policy_gain(model, policy)[0])
    assert max(gains) == pytest.approx(found.gain, abs=1e-10)
    assert policy_gain(model, found.policy)[0] == pytest.approx(max(gains), abs=1e-10)


def test_optimum_prints_the_gain_and_the_policy_by_priority() -> None:
    result = invoke("optimum", ACCESS)
    assert result.exit_code == 0, result.output
    assert (
        "optimal gain (reward per step, relative value iteration, 167 sweeps): 2.747642"
        in result.output
    )
    assert "  2  reject reject reject reject accept accept" in result.output
    data = json.loads(invoke("optimum", ACCESS, "--json").output)
    assert data["gain"] == pytest.approx(2.747642, abs=1e-6) and len(data["policy"]) == 44


def test_a_study_runs_by_one_command_with_its_figure_data_and_resume(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "ac.yaml", {
        "kind": "average_reward", "name": "ac", "world": {"id": ACCESS}, "seeds": 0,
        "steps": 200_000, "record_every": 10_000,
        "curves": [{"label": "SARSA", "algorithm": "differential_sarsa", "alpha": 0.01,
                    "beta": 0.01, "epsilon": 0.1}],
        "figure": {"kind": "policy", "file": "ac.png"},
    })  # fmt: skip
    out = tmp_path / "out"
    result = invoke("study", path, "--out", out, "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    summary = (out / "summary.txt").read_text(encoding="utf-8")
    assert "optimal gain (relative value iteration, 167 sweeps): 2.747642" in summary
    data = (out / "ac.csv").read_text(encoding="utf-8")
    assert "optimal policy (relative value iteration),action (-1: never visited),0,8,,,0\n" in data
    assert "optimal policy (relative value iteration),action (-1: never visited),1,8,,,1\n" in data
    assert "reward per step,optimal gain r* = 2.7476,,2.747641950572408" in data
    first = (out / "results.csv").read_bytes()
    again = tmp_path / "again"
    assert invoke("study", path, "--out", again, "--workers", 1, "-q").exit_code == 0
    assert (again / "results.csv").read_bytes() == first
    assert (again / "ac.csv").read_bytes() == (out / "ac.csv").read_bytes()


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"curves": [{"algorithm": "differential_sarsa", "alpha": 0.1, "beta": 0.0}]},
         "curves[0].beta: a step size must be above 0, got 0"),
        ({"curves": [{"algorithm": "differential_sarsa", "alpha": 0.1, "beta": -1}]},
         "curves[0].beta: a step size must be above 0, got -1"),
        ({"curves": [{"algorithm": "differential_sarsa", "alpha": 0.1}]},
         "curves[0].beta: is missing"),
        ({"world": {"id": "cartpole_q/ShortCorridor-v0"}}, "world: cartpole_q/ShortCorridor-v0 is episodic"),
        ({"curves": [{"algorithm": "reinforce", "alpha": 0.1, "beta": 0.1}]},
         "curves[0].algorithm: must be one of differential_sarsa"),
        ({"curves": [{"algorithm": "differential_sarsa", "alpha": 0.1, "beta": 0.1,
                      "epsilon": 2}]}, "curves[0].epsilon: must be in [0, 1]"),
        ({"record_every": 20}, "record_every: at most steps (10)"),
        ({"steps": 10**16}, "steps: must be at most 1,000,000,000,000,000"),
        ({"world": {"id": "cartpole_q/Baird-v0"}, "figure": {"kind": "policy"}},
         "figure.kind: policy draws a world whose states are two components"),
    ],
)  # fmt: skip
def test_bad_input_is_refused_naming_the_file_and_key(
    tmp_path: Path, change: dict[str, Any], named: str
) -> None:
    raw = {"kind": "average_reward", "world": {"id": ACCESS}, "steps": 10,
           "curves": [{"algorithm": "differential_sarsa", "alpha": 0.1, "beta": 0.1}], **change}  # fmt: skip
    path = write_yaml(tmp_path / "bad.yaml", raw)
    assert_refused(invoke("study", path, "--check"), named, str(path))
