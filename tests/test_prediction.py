"""Prediction: the state values of a fixed policy, their true values, and the run's files.

The algorithms' bytes are compared with the plain re-derivation in test_rederivation.py
(``test_prediction``); here: the true values the errors are measured against, what a
prediction run writes and reads back, resuming, and the equalities docs/algorithms.md
states.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from cartpole_q.config import ConfigError, load_config
from cartpole_q.engines.base import prediction_truth
from cartpole_q.envs.gym import inspect_env
from cartpole_q.experiments.run import execute_run, prepare, start_run
from cartpole_q.store import rundir
from cartpole_q.training import train
from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

WALK5 = {"env.id": "cartpole_q/RandomWalk5-v0", "discretization": None, "agent.gamma": 1.0}
WALK19 = {"env.id": "cartpole_q/RandomWalk-v0", "discretization": None, "agent.gamma": 1.0}


def _config(overrides: dict[str, object], algorithm: str = "td", **more: object) -> object:
    return load_config(
        overrides={
            **overrides, "agent.algorithm": algorithm, "agent.alpha": 0.1, "agent.q_init": 0.5,
            "train.episodes": 60, "seed": 4, **more,
        }
    )  # fmt: skip


def test_the_walks_true_values_are_the_book_s() -> None:
    """Example 6.2: 1/6 ... 5/6; Example 7.1 (Figure 7.2): -0.9 ... 0.9 (to within 1e-15)."""
    for overrides, expected in (
        (WALK5, [k / 6 for k in range(1, 6)]),
        (WALK19, [k / 10 for k in range(-9, 10)]),
    ):
        config = _config(overrides)
        truth = prediction_truth(config, inspect_env(config))
        assert truth.rows[:, 0].tolist() == list(
            range(1, len(expected) + 1)
        )  # the ends are left out
        np.testing.assert_allclose(truth.values, expected, rtol=0, atol=1e-15)


def test_control_and_worlds_without_a_model_measure_nothing() -> None:
    assert train(_config(WALK5, "q_learning"), final_eval=False).errors is None
    cartpole = load_config(overrides={"agent.algorithm": "td", "train.episodes": 3})
    assert not prediction_truth(cartpole, inspect_env(cartpole)).measured
    result = train(cartpole, final_eval=False)
    assert result.errors is None and result.v_table.shape == (1, 1, 2, 10)
    assert result.eval is None and result.solved_episode is None


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_a_prediction_run_writes_v_and_its_errors(tmp_path: Path, engine: str) -> None:
    out = tmp_path / "run"
    result = invoke(
        "train", "--set", f"env.id={WALK5['env.id']}", "--set", "discretization=null",
        "--set", "agent.algorithm=td", "--set", "agent.gamma=1", "--set", "agent.q_init=0.5",
        "--episodes", "40", "--engine", engine, "--out", str(out), "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert not (out / rundir.Q_TABLE_FILE).exists()
    values = np.load(out / rundir.V_TABLE_FILE)
    assert values.shape == (7,) and values.dtype == np.float64
    assert values[0] == values[6] == 0.5  # the ends are never learnt
    header = (out / "metrics.csv").read_text().splitlines()[0]
    assert header == "episode,return,length,epsilon,alpha,rms_error"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["eval"] is None and summary["solved_episode"] is None
    run = rundir.load_run(out)
    assert run.predicts and run.errors is not None and len(run.errors) == 40
    assert run.q_table[..., 0].tobytes() == values.tobytes()


def test_a_prediction_run_has_no_policy_to_play_but_its_curves_plot(tmp_path: Path) -> None:
    out = tmp_path / "run"
    trained = invoke(
        "train", "--set", f"env.id={WALK5['env.id']}", "--set", "discretization=null",
        "--set", "agent.algorithm=td", "--episodes", "20", "--out", str(out), "-q",
    )  # fmt: skip
    assert trained.exit_code == 0, trained.output
    for args in (("eval", out), ("plot", out, "--policy")):
        refused = invoke(*args)
        assert refused.exit_code == 2, refused.output
        assert "is a prediction run (td)" in refused.stderr and "Traceback" not in refused.output
    plotted = invoke("plot", out, "--out", tmp_path / "curves.png")
    assert plotted.exit_code == 0, plotted.output
    assert (tmp_path / "curves.png").stat().st_size > 0


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_an_interrupted_prediction_run_resumes_byte_identically(
    tmp_path: Path, engine: str
) -> None:
    overrides = {
        **WALK19, "engine": engine, "agent.algorithm": "true_online_td_lambda",
        "agent.lambda": 0.8, "agent.alpha": 0.1, "train.episodes": 50,
        "train.checkpoint_every": 10,
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
    loaded = rundir.load_run(run)
    assert whole.errors is not None and loaded.errors is not None
    assert loaded.errors.tolist() == whole.errors.tolist()
    # resumed at a multiple of train.eval_every (10): still no greedy evaluation of V
    assert (run / "evaluations.csv").read_text().splitlines()[1:] == []
    assert json.loads((run / "summary.json").read_text())["eval"] is None
    assert set(loaded.metrics.epsilons.tolist()) == {0.0}  # epsilon is ignored: 0


@pytest.mark.parametrize(
    ("special", "general"),
    [
        ({"agent.algorithm": "n_step_td", "agent.n": 1}, {"agent.algorithm": "td"}),
        ({"agent.algorithm": "td_lambda", "agent.lambda": 0.0}, {"agent.algorithm": "td"}),
    ],
    ids=["n_step_td-n1-is-td", "td_lambda-lambda0-is-td"],
)
def test_the_equalities_the_contract_states(special: dict, general: dict) -> None:
    base = {**WALK19, "agent.alpha": 0.2, "train.episodes": 30, "seed": 11}
    one = train(load_config(overrides={**base, **special}), final_eval=False)
    other = train(load_config(overrides={**base, **general}), final_eval=False)
    assert one.v_table.tobytes() == other.v_table.tobytes()


@pytest.mark.slow
def test_td_learns_the_walk_faster_than_mc() -> None:
    """Example 6.2's right panel: from V = 0.5 (error 0.236), TD at alpha 0.1 ends below MC
    at alpha 0.02 (mean error of episodes 91-100 over 10 seeds)."""
    ends = {}
    for algorithm, alpha in (("td", 0.1), ("mc_prediction", 0.02)):
        errors = []
        for seed in range(10):
            config = _config(
                WALK5, algorithm, **{"agent.alpha": alpha, "train.episodes": 100, "seed": seed}
            )
            result = train(config, final_eval=False)
            assert result.errors is not None
            assert result.errors[0] == pytest.approx(0.236, abs=0.05)
            errors.append(float(result.errors[-10:].mean()))
        ends[algorithm] = float(np.mean(errors))
    assert ends["td"] < ends["mc_prediction"] < 0.12


def test_a_sweep_draws_the_errors_and_plot_draws_them_too(tmp_path: Path) -> None:
    """figure.metric: rms_error, each point's errors kept in curves.npz (seed-NNN.rms_error)."""
    study = tmp_path / "walk.yaml"
    write_yaml(
        study,
        {
            "name": "walk",
            "base": {
                "env": {"id": WALK5["env.id"]},
                "agent": {"algorithm": "td", "gamma": 1.0, "alpha": 0.1, "q_init": 0.5},
                "train": {"episodes": 20, "eval_every": 0, "checkpoint_every": 0},
                "eval": {"episodes": 1},
            },
            "seeds": "0-2",
            "zip": {"agent.algorithm": ["td", "mc_prediction"], "agent.alpha": [0.1, 0.1]},
            "figure": {"metric": "rms_error", "file": "walk.png"},
        },
    )
    out = tmp_path / "sweep"
    result = invoke("sweep", study, "--out", out, "--quiet")
    assert result.exit_code == 0, result.output
    kept = np.load(out / "points" / "000" / "curves.npz")
    whole = train(
        _config(WALK5, "td", **{"agent.alpha": 0.1, "train.episodes": 20, "seed": 1}),
        final_eval=False,
    )
    assert whole.errors is not None
    assert kept["seed-001.rms_error"].tolist() == whole.errors.tolist()
    rows = (out / "walk.csv").read_text().splitlines()
    assert rows[0] == "panel,series,x,y,y_low,y_high,value" and len(rows) > 40
    plotted = invoke(
        "plot", out / "points" / "001", "--metric", "rms_error", "--out", tmp_path / "p.png"
    )
    assert plotted.exit_code == 0, plotted.output
    refused = invoke(
        "plot", out / "points" / "001", "--metric", "info:left", "--out", tmp_path / "q.png"
    )
    assert refused.exit_code == 2


def test_a_control_point_cannot_draw_errors(tmp_path: Path) -> None:
    study = tmp_path / "mixed.yaml"
    write_yaml(
        study,
        {
            "base": {"env": {"id": WALK5["env.id"]}, "train": {"episodes": 5}},
            "seeds": "0",
            "grid": {"agent.algorithm": ["td", "q_learning"]},
            "figure": {"metric": "rms_error"},
        },
    )
    result = invoke("sweep", study, "--out", tmp_path / "s")
    assert result.exit_code == 2
    assert "point 1 runs agent.algorithm q_learning, a control algorithm" in result.stderr


def test_optimum_prints_the_policy_s_exact_values() -> None:
    result = invoke("optimum", WALK5["env.id"], "--policy", "random", "--json")
    assert result.exit_code == 0, result.output
    found = json.loads(result.stdout)
    assert (found["policy"], found["gamma"]) == ("random", 1.0)
    assert [round(v * 6, 12) for v in found["values"].values()] == [1.0, 2.0, 3.0, 4.0, 5.0]
    text = invoke("optimum", "FrozenLake-v1", "--policy", "random", "--gamma", "0.9")
    assert text.exit_code == 0 and "values of the random policy (gamma 0.9)" in text.stdout
    refused = invoke("optimum", "CartPole-v1", "--policy", "random")
    assert refused.exit_code == 2 and "no exact values" in refused.stderr


def test_optimum_s_policy_values_are_a_prediction_run_s_truth() -> None:
    """``optimum --policy`` evaluates the policy on the world, with no algorithm: its values
    are exactly those a prediction run's RMS error is measured against."""
    shown = invoke("optimum", "FrozenLake-v1", "--policy", "random", "--gamma", "0.9", "--json")
    assert shown.exit_code == 0, shown.output
    values = json.loads(shown.stdout)["values"]
    config = load_config(
        overrides={"env.id": "FrozenLake-v1", "agent.algorithm": "td", "agent.gamma": 0.9}
    )
    truth = prediction_truth(config, inspect_env(config))
    assert [int(state) for state in values] == truth.states.tolist()
    assert list(values.values()) == truth.values.tolist()


@pytest.mark.parametrize(
    ("arguments", "named", "why"),
    [
        (["--policy", "sideways"], "--policy sideways", "random, stick_20, left, greedy"),
        (["--policy", "left"], "--policy", "left is not a rule FrozenLake-v1 declares"),
        (["--policy", "greedy"], "--set agent.policy_run", "give its run directory"),
        (
            ["--policy", "random", "--set", "agent.policy_run=runs/x"],
            "--set agent.policy_run",
            "read only with agent.policy greedy or epsilon_greedy",
        ),
        (
            ["--policy", "epsilon_greedy", "--set", "agent.policy_epsilon=2"],
            "agent.policy_epsilon=2",
            "in [0, 1]",
        ),
        (["--set", "agent.policy_run=runs/x"], "--set agent.policy_run", "without --policy"),
    ],
)
def test_optimum_refuses_a_policy_as_a_prediction_config_would(
    arguments: list[str], named: str, why: str
) -> None:
    assert_refused(invoke("optimum", "FrozenLake-v1", *arguments), named, why)


def test_the_measured_states_are_those_an_episode_can_be_in() -> None:
    """Taxi's 100 states with the passenger at the destination are never occupied."""
    taxi = load_config(overrides={"env.id": "Taxi-v4", "agent.algorithm": "td", "agent.gamma": 0.9})
    truth = prediction_truth(taxi, inspect_env(taxi))
    assert len(truth.rows) == 400 and len(set(truth.rows[:, 0].tolist())) == 400


def test_a_policy_that_may_never_end_is_refused_at_gamma_1() -> None:
    endless = {"env.id": "FrozenLake-v1", "env.kwargs.desc": ["SF", "FF"], "agent.algorithm": "td"}
    with pytest.raises(ConfigError, match=r"agent\.policy: .* not defined at agent\.gamma 1"):
        train(load_config(overrides={**endless, "agent.gamma": 1.0, "train.episodes": 1}))
    assert prediction_truth(
        load_config(overrides={**endless, "agent.gamma": 0.9}),
        inspect_env(load_config(overrides=endless)),
    ).measured


def test_what_needs_a_policy_refuses_a_prediction_run(tmp_path: Path) -> None:
    run = tmp_path / "run"
    base = ["--set", f"env.id={WALK5['env.id']}", "--set", "agent.algorithm=td"]
    assert invoke("train", *base, "--episodes", "5", "--out", run, "-q").exit_code == 0
    watched = invoke("train", *base, "--video-every", "2", "--out", tmp_path / "w")
    assert watched.exit_code == 2 and "there is none to watch" in watched.stderr
    other = tmp_path / "other"
    assert invoke("train", *base, "--episodes", "5", "--out", other, "-q").exit_code == 0
    compared = invoke("compare", run, other)
    assert compared.exit_code == 2 and "is a prediction run (td)" in compared.stderr
    tune = write_yaml(
        tmp_path / "t.yaml",
        {"base": {"env": {"id": WALK5["env.id"]}, "agent": {"algorithm": "td"}},
         "space": {"agent.alpha": [0.1, 0.5]}},
    )  # fmt: skip
    tuned = invoke("tune", tune, "--out", tmp_path / "tune")
    assert tuned.exit_code == 2 and "is a prediction algorithm" in tuned.stderr


def test_a_checkpoint_of_another_length_is_refused(tmp_path: Path) -> None:
    overrides = {
        **WALK19,
        "agent.algorithm": "td",
        "train.episodes": 20,
        "train.checkpoint_every": 10,
    }
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    polls = iter(range(10**9))
    execute_run(run, prepared, should_stop=lambda: next(polls) >= 0)
    with np.load(run / "checkpoint.npz") as data:
        arrays = {name: data[name] for name in data.files}
    arrays["rms_errors"] = arrays["rms_errors"][:-1]  # one error short
    np.savez(run / "checkpoint.npz", **arrays)
    resumed = invoke("train", "--resume", str(run), "-q")
    assert resumed.exit_code == 2, resumed.output
    assert "the checkpoint's rms_errors has shape" in resumed.stderr
    assert "Traceback" not in resumed.output


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_a_batch_run_extends_byte_identically(tmp_path: Path, engine: str) -> None:
    """batch_prediction keeps every transition: an extended run's batch grows from its checkpoint."""
    overrides = {
        **WALK5, "engine": engine, "agent.algorithm": "batch_prediction", "agent.alpha": 0.002,
        "agent.tolerance": 1e-4, "seed": 5,
    }  # fmt: skip
    whole = train(load_config(overrides={**overrides, "train.episodes": 40}), final_eval=False)
    prepared = prepare(load_config(overrides={**overrides, "train.episodes": 15}), "test")
    run = start_run(prepared, tmp_path / "run")
    execute_run(run, prepared)
    extended = invoke("train", "--resume", str(run), "--episodes", "40", "-q")
    assert extended.exit_code == 0, extended.output
    assert np.load(run / rundir.V_TABLE_FILE).tobytes() == whole.v_table.tobytes()
    loaded = rundir.load_run(run)
    assert whole.errors is not None and loaded.errors is not None
    assert loaded.errors.tolist() == whole.errors.tolist()


def test_batch_mc_converges_to_every_visit_average_returns() -> None:
    """Sutton & Barto 6.3: batch constant-alpha MC settles on each state's average return.

    The policy draws the same actions in both runs, so both see the same episodes; every-visit
    sample-average MC's values are those averages, computed incrementally.
    """
    base = {**WALK19, "train.episodes": 12, "seed": 9, "agent.q_init": 0.0}
    batch = train(
        load_config(
            overrides={
                **base, "agent.algorithm": "batch_prediction", "agent.target": "mc",
                "agent.alpha": 0.001, "agent.tolerance": 1e-13,
            }
        ),
        final_eval=False,
    )  # fmt: skip
    averaged = train(
        load_config(
            overrides={
                **base, "agent.algorithm": "mc_prediction", "agent.update": "sample_average",
                "agent.alpha": 0.1,
            }
        ),
        final_eval=False,
    )  # fmt: skip
    assert batch.lengths.tolist() == averaged.lengths.tolist()
    visited = averaged.visits.sum(axis=-1) > 0
    assert visited.sum() > 5
    np.testing.assert_allclose(batch.v_table[visited], averaged.v_table[visited], atol=1e-9)
    assert (batch.v_table[~visited] == 0.0).all()  # never a state of the batch: as it began


def test_a_values_figure_draws_v_beside_the_true_values(tmp_path: Path) -> None:
    """figure.metric: values (Example 6.2's left panel): V per state, the truth, the start."""
    study = write_yaml(
        tmp_path / "values.yaml",
        {
            "name": "values",
            "base": {
                "env": {"id": WALK5["env.id"]}, "discretization": None,
                "agent": {"algorithm": "td", "gamma": 1.0, "alpha": 0.1, "q_init": 0.5},
                "train": {"episodes": 10, "eval_every": 0, "checkpoint_every": 0},
                "eval": {"episodes": 1},
            },
            "seeds": "0-2",
            "grid": {"train.episodes": [1, 10]},
            "figure": {"metric": "values", "file": "v.png"},
        },
    )  # fmt: skip
    done = invoke("sweep", study, "--out", tmp_path / "sweep", "-q")
    assert done.exit_code == 0, done.output
    rows = (tmp_path / "sweep" / "v.csv").read_text().splitlines()[1:]
    series = {row.split(",")[1] for row in rows}
    assert series == {"initial values", "episodes 1", "episodes 10", "true values"}
    truth = [float(row.split(",")[3]) for row in rows if ",true values," in row]
    assert truth == pytest.approx([1 / 6, 2 / 6, 3 / 6, 4 / 6, 5 / 6], abs=1e-15)
    ten = train(_config(WALK5, **{"train.episodes": 10, "seed": 1}), final_eval=False)
    tables = np.load(tmp_path / "sweep" / "points" / "001" / "q_tables.npz")
    assert tables[sorted(tables.files)[1]].tobytes() == ten.v_table.tobytes()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"base.agent.algorithm": "q_learning"}, "figure.metric: values is a prediction run's"),
        ({"figure.against": "train.episodes"}, "figure.against: draws a metric against an axis"),
    ],
)
def test_a_values_figure_refuses_control_runs_and_against(
    tmp_path: Path, change: dict[str, str], words: str
) -> None:
    study: dict = {
        "name": "values",
        "base": {"env": {"id": WALK5["env.id"]}, "discretization": None,
                 "agent": {"algorithm": "td", "gamma": 1.0}, "train": {"episodes": 5}},
        "seeds": "0",
        "grid": {"train.episodes": [1, 5]},
        "figure": {"metric": "values"},
    }  # fmt: skip
    for dotted, value in change.items():
        *parents, last = dotted.split(".")
        node = study
        for parent in parents:
            node = node[parent]
        node[last] = value
    refused = invoke("sweep", write_yaml(tmp_path / "v.yaml", study), "--out", tmp_path / "s")
    assert refused.exit_code == 2, refused.output
    assert words in refused.stderr and "Traceback" not in refused.output


def test_a_named_policy_plays_its_rule_without_draws() -> None:
    """stick_20 (Blackjack, Example 5.1): stick on 20 or 21, else hit; no rng draw."""
    overrides = {
        "env.id": "Blackjack-v1", "agent.algorithm": "mc_prediction", "agent.policy": "stick_20",
        "agent.update": "sample_average", "agent.visits": "first", "agent.gamma": 1.0,
        "train.episodes": 2000, "seed": 3,
    }  # fmt: skip
    result = train(load_config(overrides=overrides), final_eval=False)
    visits = result.visits  # (32, 11, 2, 2): the actions the rule took in each state
    assert visits[:20, ..., 0].sum() == 0 and visits[20:, ..., 1].sum() == 0
    assert visits[12:20, ..., 1].sum() > 1000 and visits[20:22, ..., 0].sum() > 300


@pytest.mark.parametrize(
    ("overrides", "words"),
    [
        ({"env.id": WALK5["env.id"], "discretization": None}, "stick_20 is not a rule"),
        (
            {"env.id": "MountainCar-v0", "discretization.tilings": 4,
             "discretization.bins": [4, 4], "discretization.low": [-1.2, -0.07],
             "discretization.high": [0.6, 0.07]},
            "stick_20 is not a rule",
        ),
    ],
)  # fmt: skip
def test_a_named_policy_of_another_world_is_refused(overrides: dict, words: str) -> None:
    with pytest.raises(ConfigError, match=r"agent\.policy") as raised:
        load_config(overrides={**overrides, "agent.algorithm": "td", "agent.policy": "stick_20"})
    assert words in str(raised.value)


def test_the_one_state_mdp_and_importance_sampling() -> None:
    """Example 5.5: v(s) = 1 under left (1/11 under random); weighted IS is exact at once."""
    import gymnasium
    from gymnasium.utils.env_checker import check_env

    check_env(gymnasium.make("cartpole_q/OneState-v0").unwrapped)
    base = {
        "env.id": "cartpole_q/OneState-v0", "discretization": None, "agent.gamma": 1.0,
        "agent.q_init": 0.0,
    }  # fmt: skip
    for policy, value in (("left", 1.0), ("random", 1 / 11)):
        config = load_config(overrides={**base, "agent.algorithm": "td", "agent.policy": policy})
        truth = prediction_truth(config, inspect_env(config))
        assert truth.rows.tolist() == [[0]] and truth.values[0] == pytest.approx(value, abs=1e-15)
    overrides = {
        **base, "agent.algorithm": "off_policy_mc_prediction", "agent.policy": "left",
        "train.episodes": 200, "seed": 2,
    }  # fmt: skip
    weighted = train(load_config(overrides=overrides), final_eval=False)
    assert weighted.errors is not None
    # Weighted: every episode that ended with right has W = 0 and leaves V at 0 ...
    first = int(np.flatnonzero(weighted.errors < 1.0)[0])
    assert (weighted.errors[:first] == 1.0).all()
    # ... and from the first that ends left with +1, V(s) = G = 1 exactly, for good.
    assert (weighted.errors[first:] == 0.0).all()
    ordinary = train(
        load_config(overrides={**overrides, "agent.sampling": "ordinary"}), final_eval=False
    )
    assert ordinary.errors is not None and len(set(ordinary.errors.tolist())) > 20


def test_blackjacks_named_policy_is_evaluated_exactly() -> None:
    """optimum --policy stick_20: Figure 5.3's state (13, usable ace, dealer 2) is -0.2772.

    The book gives -0.27726 from 100 million simulated episodes; the rules' exact value is
    -0.277204. A natural 21 is a model state of its own (it wins unless the dealer has one).
    A prediction run on Blackjack measures no error (the natural shares a row).
    """
    import json

    shown = invoke("optimum", "Blackjack-v1", "--policy", "stick_20")
    assert shown.exit_code == 0, shown.output
    assert "  13 with a usable ace, dealer 2: -0.277204\n" in shown.stdout
    assert "  a natural 21, dealer 5: 1\n" in shown.stdout
    listed = json.loads(invoke("optimum", "Blackjack-v1", "--policy", "stick_20", "--json").stdout)
    values = {int(state): value for state, value in listed["values"].items()}
    assert values[(13 * 11 + 2) * 2 + 1] == pytest.approx(-0.27726, abs=1e-4)
    config = load_config(
        overrides={"env.id": "Blackjack-v1", "agent.algorithm": "td", "agent.policy": "stick_20"}
    )
    assert not prediction_truth(config, inspect_env(config)).measured


def test_blackjack_dealt_one_hand_measures_that_state() -> None:
    """Example 5.4: every episode is 13 with a usable ace against a 2; its error alone."""
    import gymnasium
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("cartpole_q/BlackjackDealt-v0")
    check_env(env.unwrapped)
    starts = {env.reset(seed=seed)[0] for seed in range(20)}
    assert starts == {(13, 2, 1)}
    config = load_config(
        overrides={
            "env.id": "cartpole_q/BlackjackDealt-v0", "agent.algorithm": "off_policy_mc_prediction",
            "agent.policy": "stick_20", "agent.sampling": "ordinary", "agent.visits": "first",
            "agent.q_init": 0.0, "agent.gamma": 1.0, "train.episodes": 300, "seed": 1,
        }
    )  # fmt: skip
    truth = prediction_truth(config, inspect_env(config))
    assert truth.rows.tolist() == [[(13 * 11 + 2) * 2 + 1]]
    assert truth.values[0] == pytest.approx(-0.277204, abs=1e-6)
    result = train(config, final_eval=False)
    assert result.errors is not None
    v = result.v_table[13, 2, 1]
    assert result.errors[-1] == pytest.approx(abs(v - truth.values[0]), abs=1e-15)


def test_the_mean_square_aggregate_is_the_mean_of_squares() -> None:
    from cartpole_q.learning_curves import aggregate_band

    curves = np.array([[1.0, -2.0], [3.0, 0.0], [np.nan, 2.0]])
    centre, low, high = aggregate_band(curves, "mean_square", np.random.default_rng(0))
    assert centre.tolist() == [5.0, 8.0 / 3.0]  # (1 + 9) / 2 (a NaN is no seed); (4 + 0 + 4) / 3
    assert (low <= centre).all() and (centre <= high).all()


# -- a control run's policy (agent.policy greedy / epsilon_greedy, agent.policy_run) --------

LAKE = {"env.id": "FrozenLake-v1", "discretization": None, "agent.gamma": 0.95}


def _control_run(path: Path, q_table: np.ndarray, env_id: str = "FrozenLake-v1") -> Path:
    """A control run's two files the policy is read from."""
    path.mkdir(parents=True)
    np.save(path / rundir.Q_TABLE_FILE, q_table)
    write_yaml(path / "config.yaml", {"env": {"id": env_id}})
    return path


def test_the_greedy_policy_of_q_star_has_the_optimal_values(tmp_path: Path) -> None:
    """Evaluating the greedy policy of Q* gives v* (the two solvers agree to rounding)."""
    from cartpole_q.envs.models import EnvModel, env_model
    from cartpole_q.rl.solvers import value_iteration

    config = load_config(overrides={**LAKE, "agent.algorithm": "td"})
    model = env_model(config.env)
    assert isinstance(model, EnvModel)
    optimum = value_iteration(model.model, 0.95, tolerance=1e-14)
    run = _control_run(tmp_path / "lake", optimum.q)
    for policy in ("greedy", "epsilon_greedy"):
        overrides = {**LAKE, "agent.algorithm": "td", "agent.policy": policy}
        config = load_config(overrides={**overrides, "agent.policy_run": str(run)})
        truth = prediction_truth(config, inspect_env(config))
        assert truth.states is not None
        # no hole, no goal; Q*'s greedy policy never reaches state 3 (up from 1, left from 2)
        reached = (
            [0, 1, 2, 4, 6, 8, 9, 10, 13, 14]
            if policy == "greedy"
            else [0, 1, 2, 3, 4, 6, 8, 9, 10, 13, 14]
        )
        assert truth.states.tolist() == reached
        exact = optimum.values[truth.states]
        if policy == "greedy":
            np.testing.assert_allclose(truth.values, exact, rtol=0, atol=1e-12)
        else:  # epsilon 0.1 of uniform moves costs something in every state
            assert (truth.values < exact - 1e-3).all()


def test_a_runs_epsilon_greedy_policy_plays_its_probabilities(tmp_path: Path) -> None:
    """greedy plays its action alone; epsilon 0.4 gives it 0.7 and each other action 0.1."""
    run = _control_run(tmp_path / "lake", np.tile(np.array([0.0, 1.0, 0.0, 0.0]), (16, 1)))
    base = {**LAKE, "agent.algorithm": "td", "train.episodes": 300, "agent.policy_run": str(run)}
    greedy = train(load_config(overrides={**base, "agent.policy": "greedy"}), final_eval=False)
    assert greedy.visits[..., [0, 2, 3]].sum() == 0 and greedy.visits[..., 1].sum() > 0
    mixed = train(
        load_config(
            overrides={**base, "agent.policy": "epsilon_greedy", "agent.policy_epsilon": 0.4}
        ),
        final_eval=False,
    )
    shares = mixed.visits.sum(axis=0) / mixed.visits.sum()
    np.testing.assert_allclose(shares, [0.1, 0.7, 0.1, 0.1], atol=0.03)


@pytest.mark.parametrize(
    ("assignments", "message"),
    [
        (["agent.policy=greedy"], "agent.policy_run: agent.policy greedy evaluates a control run"),
        (["agent.policy=greedy", "agent.policy_run=PREDICTION"], "is a prediction run"),
        (["agent.policy=greedy", "agent.policy_run=NOWHERE"], "does not exist (moved or removed?)"),
        (["agent.policy_run=CONTROL"], "is read only with agent.policy greedy or epsilon_greedy"),
        (
            ["agent.policy=greedy", "agent.policy_run=CONTROL", "env.kwargs.map_name=8x8"],
            "its q_table.npy is float64 of shape (16, 4); this config's table is float64 of shape (64, 4)",
        ),
        (
            ["agent.policy=epsilon_greedy", "agent.policy_run=TAXI"],
            "its config.yaml's env.id is Taxi-v4, not this config's FrozenLake-v1",
        ),
        (
            ["agent.policy=greedy", "agent.policy_run=CONTROL", "discretization.tilings=4"],
            "agent.policy: greedy takes a run's table policy",
        ),
        (
            ["agent.policy=greedy", "agent.policy_run=STRING_ENV"],
            "its config.yaml's env.id is missing",
        ),
        (["agent.policy=greedy", "agent.policy_run=EMPTY_TABLE"], "cannot read its q_table.npy"),
    ],
    ids=[
        "no-run",
        "prediction-run",
        "missing",
        "not-asked",
        "shape",
        "other-world",
        "tiles",
        "env-a-string",
        "empty-table",
    ],
)
def test_a_runs_policy_is_refused_before_anything_is_written(
    tmp_path: Path, assignments: list[str], message: str
) -> None:
    places = {
        "CONTROL": _control_run(tmp_path / "control", np.zeros((16, 4))),
        "TAXI": _control_run(tmp_path / "taxi", np.zeros((16, 4)), env_id="Taxi-v4"),
        "PREDICTION": tmp_path / "prediction",
        "NOWHERE": tmp_path / "nowhere",
        "STRING_ENV": _control_run(tmp_path / "string", np.zeros((16, 4))),
        "EMPTY_TABLE": _control_run(tmp_path / "empty", np.zeros((16, 4))),
    }
    (tmp_path / "string" / "config.yaml").write_text("env: FrozenLake-v1\n")
    (tmp_path / "empty" / rundir.Q_TABLE_FILE).write_bytes(b"")
    (tmp_path / "prediction").mkdir()
    np.save(tmp_path / "prediction" / rundir.V_TABLE_FILE, np.zeros(16))
    args = ["train", "--set", "env.id=FrozenLake-v1", "--set", "agent.algorithm=td"]
    for assignment in assignments:
        for name, place in places.items():
            assignment = assignment.replace(name, str(place))
        args += ["--set", assignment]
    out = tmp_path / "out"
    result = invoke(*args, "--out", str(out))
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.stderr.split()), result.stderr
    assert "Traceback" not in result.output
    assert not out.exists()


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_an_interrupted_run_of_a_runs_policy_resumes_byte_identically(
    tmp_path: Path, engine: str
) -> None:
    control = str(Path(__file__).parent / "data" / "frozenlake_q_learning_run")
    overrides = {
        **LAKE, "engine": engine, "agent.algorithm": "mc_prediction",
        "agent.policy": "epsilon_greedy", "agent.policy_run": control,
        "train.episodes": 60, "train.checkpoint_every": 10,
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
    loaded = rundir.load_run(run)
    assert whole.errors is not None and loaded.errors is not None
    assert loaded.errors.tolist() == whole.errors.tolist()


def test_a_runs_policy_is_read_from_an_absolute_path_and_only_when_training(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A config naming a run that is not there (moved, or read from elsewhere) still loads:
    the run is read when training starts; the path is kept absolute."""
    monkeypatch.chdir(tmp_path)
    config = load_config(
        overrides={
            **LAKE,
            "agent.algorithm": "td",
            "agent.policy": "greedy",
            "agent.policy_run": "gone",
        }
    )
    assert config.agent.params["policy_run"] == str(tmp_path / "gone")
    again = load_config(overrides=config.to_dict())
    assert again.agent.params["policy_run"] == str(tmp_path / "gone")
    with pytest.raises(ConfigError, match=r"does not exist \(moved or removed\?\)"):
        prepare(config, "test")


def test_the_true_values_on_tiles_follow_the_discretization() -> None:
    """Two tilings of the walk over different ranges: each its own tiles (not one cached)."""
    base = {
        "env.id": "cartpole_q/RandomWalk1000-v0", "env.kwargs": {"position": True},
        "agent.algorithm": "td", "agent.gamma": 1.0,
    }  # fmt: skip
    rows = []
    for high in (1001.0, 2001.0):
        tiles = {"bins": [5], "low": [1.0], "high": [high], "tilings": 4}
        config = load_config(overrides={**base, "discretization": tiles})
        rows.append(prediction_truth(config, inspect_env(config)).rows[500].tolist())
    # state 501: v = 2.5 (then 1.25) bins, floor(4 v) + t over 4 tiles of 6 per tiling
    assert rows == [[2, 8, 15, 21], [1, 7, 13, 20]]


def test_optimum_evaluates_a_runs_greedy_policy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from cartpole_q.envs.models import EnvModel, env_model
    from cartpole_q.rl.solvers import value_iteration

    model = env_model(load_config(overrides={**LAKE, "agent.algorithm": "td"}).env)
    assert isinstance(model, EnvModel)
    optimum = value_iteration(model.model, 0.95, tolerance=1e-14)
    run = _control_run(tmp_path / "lake", optimum.q)
    result = invoke(
        "optimum", "FrozenLake-v1", "--policy", "greedy", "--gamma", "0.95",
        "--set", f"agent.policy_run={run}", "--json",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    values = json.loads(result.stdout)["values"]
    assert values["0"] == pytest.approx(float(optimum.values[0]), abs=1e-12)
    # the run's directory is read as a config's agent.policy_run is: ~ expanded
    monkeypatch.setenv("HOME", str(tmp_path))
    home = invoke(
        "optimum", "FrozenLake-v1", "--policy", "greedy", "--gamma", "0.95",
        "--set", "agent.policy_run=~/lake", "--json",
    )  # fmt: skip
    assert home.exit_code == 0, home.output
    assert json.loads(home.stdout)["values"] == values
    refused = invoke("optimum", "FrozenLake-v1", "--policy", "greedy", "--set", "agent.alpha=0.1")
    assert refused.exit_code == 2 and "agent.policy_run=RUN_DIR" in refused.stderr


def test_the_sample_averages_example_shows_what_its_comment_measures() -> None:
    """examples/book/example6_2_sample_averages.yaml, its first 20 seeds: sample averages
    fall faster than a constant alpha at first (TD(0)) and end lower (Monte Carlo)."""
    from cartpole_q.experiments.sweep_spec import load_sweep

    study = Path(__file__).resolve().parents[1] / "examples/book/example6_2_sample_averages.yaml"
    points = load_sweep(study).points
    assert [point.config.agent.alpha.averages for point in points] == [False, True, False, True]
    errors = []
    for point in points:
        # (the gymnasium engine: its step functions of these are compiled by other tests)
        config = dataclasses.replace(point.config, engine="gymnasium")
        runs = [train(config.for_seed(seed), final_eval=False) for seed in range(20)]
        assert all(run.errors is not None for run in runs)
        errors.append(np.mean([run.errors for run in runs], axis=0))
    td, td_averaged, mc, mc_averaged = errors
    assert td_averaged[9] < td[9]  # episode 10
    assert mc_averaged[99] < mc[99]  # episode 100


DRIVING = {
    "env.id": "cartpole_q/DrivingHome-v0", "discretization": None, "agent.gamma": 1.0,
    "agent.alpha": 1.0, "train.episodes": 1, "train.eval_every": 0,
    "train.checkpoint_every": 0, "eval.episodes": 1,
}  # fmt: skip
PREDICTED_TO_GO = [30.0, 35.0, 15.0, 10.0, 3.0, 0.0]
"""Example 6.1's predicted minutes to go, leaving office to arriving home"""


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize(
    ("algorithm", "after"),
    [
        # Monte Carlo: every prediction moves to the actual minutes to go (43 in total)
        ("mc_prediction", [43.0, 38.0, 23.0, 13.0, 3.0, 0.0]),
        # TD(0): each to the minutes the leg took plus the next situation's prediction
        ("td", [40.0, 30.0, 20.0, 13.0, 3.0, 0.0]),
    ],
)
def test_initial_values_start_v_state_by_state_as_example_6_1(
    tmp_path: Path, engine: str, algorithm: str, after: list[float]
) -> None:
    """One drive with alpha 1 from the example's predictions: Figure 6.1's changes."""
    config = tmp_path / "drive.yaml"
    write_yaml(config, {})
    sets = [f"{key}={json.dumps(value)}" for key, value in DRIVING.items()]
    result = invoke(
        "train", "-c", config, *[arg for item in sets for arg in ("--set", item)],
        "--set", f"agent.algorithm={algorithm}",
        "--set", f"agent.initial_values={json.dumps(PREDICTED_TO_GO)}",
        "--engine", engine, "--out", tmp_path / "run", "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert np.load(tmp_path / "run" / rundir.V_TABLE_FILE).tolist() == after
    written = (tmp_path / "run" / "config.yaml").read_text(encoding="utf-8")
    assert "initial_values: [30.0, 35.0, 15.0, 10.0, 3.0, 0.0]" in written


@pytest.mark.parametrize(
    ("overrides", "words"),
    [
        ({"agent.algorithm": "q_learning"}, "q_learning learns action values"),
        ({"agent.initial_values": [1.0, 2.0]}, "has 2 values but the table"),
        ({"agent.initial_values": "fast"}, "must be a non-empty list of numbers"),
        ({"agent.initial_values": [1.0, float("nan")]}, "must be a finite number"),
    ],
)
def test_initial_values_are_refused_where_they_cannot_start_v(
    tmp_path: Path, overrides: dict, words: str
) -> None:
    """In the file, the error names the file; nothing is written."""
    config = tmp_path / "drive.yaml"
    agent = {"algorithm": "td", "initial_values": PREDICTED_TO_GO}
    agent.update({key.removeprefix("agent."): value for key, value in overrides.items()})
    write_yaml(config, {"env": {"id": DRIVING["env.id"]}, "discretization": None, "agent": agent})
    result = invoke("train", "-c", config, "--out", tmp_path / "run")
    assert_refused(result, "agent.initial_values", words, str(config))
    assert not (tmp_path / "run").exists()


def test_initial_values_are_refused_on_tiles() -> None:
    with pytest.raises(ConfigError, match=r"agent\.initial_values.*on tiles"):
        load_config(
            overrides={
                "env.id": "MountainCar-v0", "discretization.tilings": 4,
                "discretization.bins": [4, 4], "discretization.low": [-1.2, -0.07],
                "discretization.high": [0.6, 0.07], "agent.algorithm": "td",
                "agent.initial_values": [0.0] * 50,
            }
        )  # fmt: skip
