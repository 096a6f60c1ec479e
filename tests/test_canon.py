"""The tabular canon (docs/algorithms.md): special cases, truncation, sparse traces, resume.

The byte-for-byte comparison of every algorithm with an independent re-derivation, on both
engines and every observation kind, is in tests/test_rederivation.py.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cartpole_q import load_config, train
from cartpole_q.config import ConfigError
from cartpole_q.rl.algorithm import MemoryContext
from cartpole_q.rl.algorithms import get, names
from cartpole_q.rl.tabular import Rates, Transition
from tests.conftest import invoke

NEW = (
    "n_step_sarsa", "n_step_tree_backup", "sarsa_lambda", "watkins_q_lambda",
    "true_online_sarsa_lambda", "dyna_q", "dyna_q_plus", "monte_carlo", "off_policy_monte_carlo",
    "monte_carlo_es",
)  # fmt: skip
SHORT = {
    "train": {"episodes": 150, "stop_when_solved": False, "eval_every": 0},
    "eval": {"episodes": 1},
}
CLIFF = {
    # CliffWalking (-1 a step, -100 off the cliff): every table changes from the first
    # episode. It runs on the transition-table twin, whose loops test_rederivation.py
    # compiles for every algorithm (a CartPole pair costs several times more to compile).
    "env": {"id": "CliffWalking-v1"},
    "agent": {"gamma": 1.0, "alpha": 0.5, "epsilon": 0.2, "q_init": 0.0},
    "train": {"episodes": 100, "stop_when_solved": False, "eval_every": 0},
    "eval": {"episodes": 1},
}


def _run(base: dict[str, Any], agent: dict[str, Any], engine: str = "auto") -> Any:
    return train(
        load_config({**base, "engine": engine, "agent": {**base.get("agent", {}), **agent}})
    )


def test_every_algorithm_of_the_contract_is_registered() -> None:
    assert set(NEW) <= set(names())
    assert names()[:4] == ("q_learning", "sarsa", "expected_sarsa", "double_q_learning")


@pytest.mark.parametrize(
    ("special", "general"),
    [
        ({"algorithm": "n_step_sarsa", "n": 1}, {"algorithm": "sarsa"}),
        ({"algorithm": "n_step_tree_backup", "n": 1}, {"algorithm": "expected_sarsa"}),
        ({"algorithm": "sarsa_lambda", "lambda": 0.0, "trace": "accumulating"}, {"algorithm": "sarsa"}),
        ({"algorithm": "sarsa_lambda", "lambda": 0.0, "trace": "dutch"}, {"algorithm": "sarsa"}),
        ({"algorithm": "watkins_q_lambda", "lambda": 0.0}, {"algorithm": "q_learning"}),
        ({"algorithm": "dyna_q", "planning_steps": 0}, {"algorithm": "q_learning"}),
    ],
    ids=["n_step_sarsa-1", "tree_backup-1", "sarsa_lambda-0", "sarsa_lambda-0-dutch",
         "watkins-0", "dyna-0"],
)  # fmt: skip
@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_the_special_cases_are_their_one_step_methods_byte_for_byte(
    special: dict[str, Any], general: dict[str, Any], engine: str
) -> None:
    one, other = _run(CLIFF, special, engine), _run(CLIFF, general, engine)
    assert one.q_table.tobytes() == other.q_table.tobytes()
    assert one.visits.tobytes() == other.visits.tobytes()
    assert np.array_equal(one.returns, other.returns)


def test_the_general_cases_differ_from_their_one_step_methods() -> None:
    """The equalities above are not vacuous: n = 4, lambda = 0.9, planning do change tables."""
    sarsa = _run(CLIFF, {"algorithm": "sarsa"}, "numba").q_table
    q_learning = _run(CLIFF, {"algorithm": "q_learning"}, "numba").q_table
    for agent, one_step in [
        ({"algorithm": "n_step_sarsa", "n": 4}, sarsa),
        ({"algorithm": "sarsa_lambda"}, sarsa),
        ({"algorithm": "watkins_q_lambda"}, q_learning),
        ({"algorithm": "dyna_q"}, q_learning),
    ]:
        assert not np.array_equal(_run(CLIFF, agent, "numba").q_table, one_step), agent


@pytest.mark.parametrize("name", NEW)
def test_every_algorithm_resumes_byte_identically_from_its_checkpoint(
    name: str, tmp_path: Path
) -> None:
    """Stopped between episodes, its checkpoint written to disk and read back: same bytes."""
    from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint

    engine = "gymnasium" if NEW.index(name) % 2 else "numba"
    # CartPole on the gymnasium engine; CliffWalking's table twin on the numba engine.
    base = SHORT if engine == "gymnasium" else CLIFF
    config = load_config(
        {**base, "engine": engine, "seed": 4, "agent": {**base.get("agent", {}), "algorithm": name},
         "train": {**base["train"], "checkpoint_every": 20}}
    )  # fmt: skip
    whole = train(config)
    checkpoints = 0

    def save(snapshot: Any) -> None:
        nonlocal checkpoints
        checkpoints += 1
        write_checkpoint(tmp_path, snapshot)

    stopped = train(config, should_stop=lambda: checkpoints >= 3, on_checkpoint=save)
    assert stopped.interrupted and 0 < stopped.episodes < config.train.episodes
    resumed = train(config, resume=load_checkpoint(tmp_path))
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()
    assert resumed.visits.tobytes() == whole.visits.tobytes()
    assert np.array_equal(resumed.returns, whole.returns)


# -- truncation bootstraps, terminal states do not ------------------------------------------


def _hook_memory(name: str, n_states: int = 3, n_actions: int = 2, **params: Any) -> Any:
    algorithm = get(name)
    values = {param.key: params.get(param.key, param.default) for param in algorithm.params}
    context = MemoryContext(n_states, n_actions, 0.0, values, max_steps=10)
    return algorithm, algorithm.memory(context), algorithm.hook_params(values)


def _last_step(name: str, *, terminated: bool, truncated: bool, **params: Any) -> np.ndarray:
    """Q after one step 0 -(r=1)-> 1 that ends the episode; Q(1, .) = (2, 4), epsilon 0."""
    algorithm, memory, hook_params = _hook_memory(name, **params)
    q = np.zeros((3, 2))
    q[1] = (2.0, 4.0)
    rng = np.random.default_rng(0)
    last = Transition(0, 0, 1.0, 1, terminated, truncated)
    ended = algorithm.step(q, memory, hook_params, last, Rates(0.5, 0.9, 0.0), rng)
    assert ended == -1
    return q


@pytest.mark.parametrize(
    ("name", "params", "bootstrap"),
    [
        ("n_step_sarsa", {"n": 3}, 4.0),  # Q(s', a') with a' greedy
        ("n_step_tree_backup", {"n": 3}, 4.0),  # E(s') at epsilon 0
        ("sarsa_lambda", {}, 4.0),
        ("watkins_q_lambda", {}, 4.0),
        ("true_online_sarsa_lambda", {}, 4.0),
        ("dyna_q", {"planning_steps": 0}, 4.0),
        ("monte_carlo", {"update": "constant_alpha"}, 4.0),  # E(s'), the epsilon-greedy value
        ("monte_carlo_es", {"update": "constant_alpha"}, 4.0),  # monte_carlo's, unchanged
        ("off_policy_monte_carlo", {}, 4.0),  # max(s'), the greedy target's value
    ],
)
def test_a_time_limit_bootstraps_and_a_terminal_state_does_not(
    name: str, params: dict[str, Any], bootstrap: float
) -> None:
    cut = _last_step(name, terminated=False, truncated=True, **params)
    ended = _last_step(name, terminated=True, truncated=False, **params)
    both = _last_step(name, terminated=True, truncated=True, **params)
    # alpha 0.5 toward r (+ gamma 0.9 * the bootstrap): sample averages take the whole step
    rate = 1.0 if name == "off_policy_monte_carlo" else 0.5
    assert ended[0, 0] == rate * 1.0
    assert cut[0, 0] == rate * (1.0 + 0.9 * bootstrap)
    assert both.tobytes() == ended.tobytes()  # terminated and truncated is terminated


def test_monte_carlo_cuts_an_episode_at_its_record_length_as_a_time_limit() -> None:
    """Without a time limit the record is 10,000 steps (here 3): the step ends the episode."""
    algorithm = get("monte_carlo")
    values = {"update": "constant_alpha"}
    memory = algorithm.memory(MemoryContext(2, 2, 0.0, values, max_steps=3))
    hook_params = algorithm.hook_params(values)
    q = np.zeros((2, 2))
    q[1] = (2.0, 4.0)
    rng = np.random.default_rng(0)
    one_step = Transition(0, 0, 1.0, 1, False, False)
    actions = [
        algorithm.step(q, memory, hook_params, one_step, Rates(0.5, 1.0, 0.0), rng)
        for _ in range(3)
    ]
    assert actions[:2] == [1, 1] and actions[2] == -1
    assert int(memory[4][0]) == 0  # the record is empty again
    assert q[0, 0] == 0.5 * (3.0 + 4.0)  # first visit, G = 1 + 1 + 1 + E(1) = 7


# -- sparse traces are the dense ones --------------------------------------------------------

_transitions = st.lists(
    st.tuples(
        st.integers(0, 3),
        st.integers(0, 1),
        st.floats(-2, 2),
        st.integers(0, 3),
        st.booleans(),
        st.booleans(),
    ),
    min_size=1,
    max_size=40,
)


@settings(max_examples=60)
@given(
    _transitions,
    st.sampled_from(["accumulating", "replacing", "dutch"]),
    st.sampled_from([0.0, 0.5, 0.9, 1.0]),
)
def test_sparse_traces_give_the_dense_traces_results(
    transitions: list[tuple[int, int, float, int, bool, bool]], trace: str, lam: float
) -> None:
    """SARSA(lambda) on a dense trace table, written from the book, equals the sparse one."""
    algorithm, memory, hook_params = _hook_memory(
        "sarsa_lambda", 4, 2, **{"lambda": lam, "trace": trace}
    )
    alpha, gamma, epsilon = 0.3, 0.9, 0.0
    q = np.zeros((4, 2))
    dense_q, z = np.zeros((4, 2)), np.zeros((4, 2))
    rng = np.random.default_rng(0)
    for s, a, r, s2, terminated, truncated in transitions:
        algorithm.step(q, memory, hook_params, Transition(s, a, r, s2, terminated, truncated),
                       Rates(alpha, gamma, epsilon), rng)  # fmt: skip
        a2 = int(np.argmax(dense_q[s2]))
        y = r if terminated else r + gamma * dense_q[s2, a2]
        delta = y - dense_q[s, a]
        if trace == "accumulating":
            z[s, a] = z[s, a] + 1.0
        elif trace == "replacing":
            z[s, a] = 1.0
        else:
            z[s, a] = (1.0 - alpha) * z[s, a] + 1.0
        dense_q = dense_q + alpha * delta * z
        z = np.zeros_like(z) if terminated or truncated else (gamma * lam) * z
        assert q.tobytes() == dense_q.tobytes()


# -- configs ------------------------------------------------------------------------------


def test_the_new_keys_are_checked_and_written(tmp_path: Path) -> None:
    config = load_config({"agent": {"algorithm": "sarsa_lambda", "lambda": 0.8}})
    assert dict(config.agent.params) == {"lambda": 0.8, "trace": "replacing"}
    assert "lambda: 0.8" in config.to_yaml() and "trace: replacing" in config.to_yaml()
    for agent, named in [
        ({"algorithm": "n_step_sarsa", "n": 0}, "agent.n"),
        ({"algorithm": "sarsa_lambda", "lambda": 1.5}, "agent.lambda"),
        ({"algorithm": "watkins_q_lambda", "trace": "sticky"}, "agent.trace"),
        ({"algorithm": "dyna_q", "planning_steps": 2.5}, "agent.planning_steps"),
        ({"algorithm": "dyna_q_plus", "kappa": -1}, "agent.kappa"),
        ({"algorithm": "monte_carlo", "update": "median"}, "agent.update"),
    ]:
        with pytest.raises(ConfigError, match=named):
            load_config({"agent": agent})
    result = invoke(
        "train", "--set", "agent.algorithm=n_step_tree_backup", "--set", "agent.n=2",
        "--episodes", "20", "--out", tmp_path / "run", "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert load_config(tmp_path / "run" / "config.yaml").agent.params["n"] == 2


def test_discount_powers_are_pythons() -> None:
    """n-step returns use gamma ** float(k), which is not repeated multiplication."""
    gamma = 0.995
    assert any(gamma ** float(k) != math.prod([gamma] * k) for k in range(2, 30))
