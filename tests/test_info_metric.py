"""``train.info_metric``: a per-episode column summed from the environment's step ``info``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cartpole_q.config import load_config
from cartpole_q.engines import resolve_engine
from cartpole_q.envs.gym import inspect_env
from cartpole_q.experiments.run import execute_run, prepare, start_run
from cartpole_q.learning_curves import seed_curves
from cartpole_q.store import rundir
from cartpole_q.store.checkpoint import CHECKPOINT_FILE
from cartpole_q.store.runsets import load_run_set
from tests.conftest import invoke, write_yaml

BIAS = {
    "env.id": "cartpole_q/MaximizationBias-v0",
    "agent.gamma": 1.0, "agent.alpha": 0.1, "agent.epsilon": 0.1, "agent.q_init": 0.0,
    "agent.tie_break": "random", "train.episodes": 60, "train.stop_when_solved": False,
    "train.eval_every": 0, "train.checkpoint_every": 0, "eval.episodes": 1,
    "train.info_metric": "left_from_a",
}  # fmt: skip
"""Fig. 6.5's world: one decision in A per episode; left lasts 2 steps, right 1"""
FROZEN_SLIPPERY = {
    "env.id": "FrozenLake-v1", "env.kwargs": {"is_slippery": True}, "train.episodes": 30,
    "train.stop_when_solved": False, "train.eval_every": 0, "train.checkpoint_every": 0,
    "eval.episodes": 1, "train.info_metric": "prob",
}  # fmt: skip
"""FrozenLake reports the transition's probability, ``info["prob"]``, at every step"""


def _run(tmp_path: Path, overrides: dict, name: str = "run") -> Path:
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / name)
    execute_run(run, prepared)
    return run


def test_the_column_is_the_hand_counted_sum_of_info_per_episode(tmp_path: Path) -> None:
    run = rundir.load_run(_run(tmp_path, BIAS))
    header = (run.path / "metrics.csv").read_text().splitlines()[0]
    assert header == "episode,return,length,epsilon,alpha,info_left_from_a"
    assert run.info is not None and run.info.dtype == np.float64
    # the world says left from A exactly when the episode lasts 2 steps (right: 1)
    assert run.info.tolist() == (run.metrics.lengths == 2).astype(float).tolist()
    assert 0 < run.info.sum() < 60


def test_the_column_sums_each_steps_info_in_step_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Slippery FrozenLake's ``info["prob"]`` (1/3, written two ways), recorded as it steps."""
    import gymnasium

    import cartpole_q.engines.gymnasium_engine as engine_module

    recorded: list[list[tuple[float, bool]]] = []
    make_env = engine_module.make_env

    class Recorder(gymnasium.Wrapper):  # type: ignore[type-arg]
        def __init__(self, env: gymnasium.Env) -> None:  # type: ignore[type-arg]
            super().__init__(env)
            self.steps: list[tuple[float, bool]] = []
            recorded.append(self.steps)

        def step(self, action: int):  # type: ignore[no-untyped-def]
            observation, reward, terminated, truncated, info = self.env.step(action)
            self.steps.append((info["prob"], terminated or truncated))
            return observation, reward, terminated, truncated, info

    monkeypatch.setattr(engine_module, "make_env", lambda env: Recorder(make_env(env)))
    lake = rundir.load_run(_run(tmp_path, FROZEN_SLIPPERY))
    expected, total = [], 0.0
    for prob, ended in recorded[0]:  # the training environment (the evaluation's is the next)
        total += prob  # by hand, in step order
        if ended:
            expected.append(total)
            total = 0.0
    assert {prob for prob, _ in recorded[0]} == {1.0 / 3.0, 0.33333333333333337}
    assert lake.info is not None and lake.info.tolist() == expected
    assert len(expected) == 30 and lake.metrics.lengths.sum() == len(recorded[0])


def test_an_unused_key_leaves_every_file_as_before(tmp_path: Path) -> None:
    overrides = {key: value for key, value in BIAS.items() if key != "train.info_metric"}
    plain = _run(tmp_path, {**overrides, "train.checkpoint_every": 20}, "plain")
    counted = _run(tmp_path, {**BIAS, "train.checkpoint_every": 20}, "counted")
    assert (plain / "metrics.csv").read_text().splitlines()[0] == ",".join(rundir.METRICS_HEADER)
    # the other columns, the tables and the evaluation do not change with the column
    for name in ("q_table.npy", "visits.npy", "evaluations.csv"):
        assert (plain / name).read_bytes() == (counted / name).read_bytes(), name
    drop_last = [line.rsplit(",", 1)[0] for line in (counted / "metrics.csv").read_text().split()]
    assert drop_last == (plain / "metrics.csv").read_text().split()
    with np.load(plain / CHECKPOINT_FILE) as data:
        assert "info" not in data.files
    with np.load(counted / CHECKPOINT_FILE) as data:
        assert data["info"].tolist() == rundir.load_run(counted).info.tolist()  # type: ignore[union-attr]


def test_an_interrupted_run_resumes_byte_identically(tmp_path: Path) -> None:
    overrides = {**BIAS, "train.checkpoint_every": 10}
    reference = _run(tmp_path, overrides, "reference")
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    polls = iter(range(10**9))
    outcome = execute_run(run, prepared, should_stop=lambda: next(polls) >= 2)
    assert outcome.result.interrupted and 0 < outcome.result.episodes < 60
    assert rundir.load_run(run).info is not None
    result = invoke("train", "--resume", run, "-q")
    assert result.exit_code == 0, result.output
    for name in ("metrics.csv", "q_table.npy", "visits.npy"):
        assert (run / name).read_bytes() == (reference / name).read_bytes(), name


def test_the_sweep_keeps_the_curve_and_the_plot_reads_it(in_tmp: Path) -> None:
    base = {
        "env": {"id": BIAS["env.id"]},
        "agent": {"gamma": 1.0, "alpha": 0.1, "epsilon": 0.1, "q_init": 0.0,
                  "tie_break": "random"},
        "train": {"episodes": 40, "stop_when_solved": False, "eval_every": 0,
                  "checkpoint_every": 0, "info_metric": "left_from_a"},
        "eval": {"episodes": 1},
    }  # fmt: skip
    figure = {"metric": "info:left_from_a", "scale": 100.0, "file": "fig.svg",
              "y_label": "% left actions from A"}  # fmt: skip
    sweep = write_yaml(in_tmp / "s.yaml", {
        "name": "bias", "base": base, "seeds": "0-2",
        "grid": {"agent.algorithm": ["q_learning", "double_q_learning"]}, "figure": figure,
    })  # fmt: skip
    result = invoke("sweep", sweep, "--out", "sw", "--workers", "1", "-q")
    assert result.exit_code == 0, result.output
    assert "% left actions from A" in Path("sw/fig.svg").read_text()
    with np.load("sw/points/001/curves.npz") as curves:
        kept = {name: curves[name] for name in curves.files}
    assert sorted(kept) == sorted(
        f"seed-00{s}.{column}" for s in range(3) for column in ("returns", "lengths",
                                                                 "info_left_from_a")
    )  # fmt: skip
    # each kept curve is the column `cartpole-q train` writes for the point and seed
    trained = invoke("train", "-c", "sw/points/001/config.yaml", "--seed", "2", "--out", "one",
                     "-q")  # fmt: skip
    assert trained.exit_code == 0, trained.output
    assert rundir.load_run(Path("one")).info.tolist() == kept["seed-002.info_left_from_a"].tolist()  # type: ignore[union-attr]
    # the point loads with its curves, and the plot's curve is theirs
    runs = load_run_set(Path("sw/points/001")).runs
    assert [run.info.tolist() for run in runs] == [  # type: ignore[union-attr]
        kept[f"seed-00{s}.info_left_from_a"].tolist() for s in range(3)
    ]
    # and with the metrics `train` writes: epsilon and alpha from the point's schedules
    one = rundir.load_run(Path("one")).metrics
    for column, values in runs[2].metrics._asdict().items():
        assert values.tolist() == getattr(one, column).tolist(), column
    curves = seed_curves(
        [r.metrics.returns for r in runs], [r.metrics.lengths for r in runs],
        "info:left_from_a", "episode", records=[r.info for r in runs],
    )  # fmt: skip
    assert curves.values.tolist() == [kept[f"seed-00{s}.info_left_from_a"].tolist()
                                      for s in range(3)]  # fmt: skip
    drawn = invoke("plot", "sw/points/000", "sw/points/001", "--metric", "info:left_from_a",
                   "--out", "p.svg")  # fmt: skip
    assert drawn.exit_code == 0, drawn.output
    assert "left_from_a per episode (sum of info)" in Path("p.svg").read_text()
    single = invoke("plot", "one", "--metric", "info:left_from_a")
    assert single.exit_code == 0 and single.output.strip() == "one/info_left_from_a_by_episode.png"


def test_engine_auto_takes_gymnasium_and_numba_is_refused(tmp_path: Path) -> None:
    config = load_config(overrides=FROZEN_SLIPPERY)
    info = inspect_env(config)
    assert resolve_engine(config, info) == "gymnasium"
    without = load_config(overrides={**FROZEN_SLIPPERY, "train.info_metric": None})
    assert resolve_engine(without, inspect_env(without)) == "numba"  # FrozenLake's twin
    result = invoke("train", "--set", "env.id=FrozenLake-v1", "--set", "train.info_metric=prob",
                    "--engine", "numba", "--out", tmp_path / "r")  # fmt: skip
    assert result.exit_code == 2
    assert (
        "command line: engine: numba cannot record train.info_metric (prob): the compiled "
        "twins report no info." in result.output
    )
    assert "Traceback" not in result.output and not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("left.from_a", "train.info_metric: must be a key of the environment's info"),
        ("1left", "train.info_metric: must be a key of the environment's info"),
        ("''", "train.info_metric: must be a key of the environment's info"),
        ("3", "train.info_metric: must be a key of the environment's info"),
        (
            "left_from_b",
            "train.info_metric: left_from_b: a step of cartpole_q/MaximizationBias-v0 has no "
            "such key in its info (it reported: left_from_a)",
        ),
    ],
)
def test_a_bad_key_is_refused_before_training(tmp_path: Path, value: str, message: str) -> None:
    result = invoke("train", "--set", f"env.id={BIAS['env.id']}", "--set",
                    f"train.info_metric={value}", "--out", tmp_path / "r")  # fmt: skip
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output and not (tmp_path / "r").exists()


def test_a_value_that_is_no_number_is_refused(tmp_path: Path) -> None:
    # Taxi's info["action_mask"] is an array: nothing to sum
    result = invoke("train", "--set", "env.id=Taxi-v4", "--set", "train.info_metric=action_mask",
                    "--out", tmp_path / "r")  # fmt: skip
    assert result.exit_code == 2
    assert "train.info_metric: action_mask: Taxi-v4 reports a ndarray there" in " ".join(
        result.output.split()
    )


def test_plot_and_sweep_refuse_an_info_metric_the_runs_did_not_keep(in_tmp: Path) -> None:
    plain = {key: value for key, value in BIAS.items() if key != "train.info_metric"}
    _run(in_tmp, plain, "plain")
    result = invoke("plot", "plain", "--metric", "info:left_from_a")
    assert result.exit_code == 2
    assert (
        "plain: --metric info:left_from_a: its runs were trained with no train.info_metric"
        in " ".join(result.output.split())
    )
    result = invoke("plot", "plain", "--metric", "info:left-from-a")
    assert result.exit_code == 2
    assert "--metric info:left-from-a: not info:KEY with a key of letters" in result.output
    sweep = write_yaml(in_tmp / "s.yaml", {
        "name": "bias", "base": {"env": {"id": BIAS["env.id"]}}, "seeds": "0-1",
        "figure": {"metric": "info:left_from_a"},
    })  # fmt: skip
    result = invoke("sweep", sweep, "--out", "sw", "-q")
    assert result.exit_code == 2
    assert (
        "figure.metric: info:left_from_a draws each episode's sum of info['left_from_a'], but "
        "point 0 sets train.info_metric: null" in " ".join(result.output.split())
    )
    assert not Path("sw").exists()


def test_metrics_csv_must_have_the_column_its_config_names(tmp_path: Path) -> None:
    run = _run(tmp_path, BIAS)
    text = (run / "metrics.csv").read_text()
    (run / "metrics.csv").write_text(
        "\n".join(line.rsplit(",", 1)[0] for line in text.splitlines()) + "\n"
    )
    result = invoke("plot", run, "--metric", "length", "--out", tmp_path / "p.png")
    assert result.exit_code == 2
    assert (
        "must start with the header episode,return,length,epsilon,alpha,info_left_from_a "
        "(its config's train.info_metric is left_from_a)" in " ".join(result.output.split())
    )
    metrics, info, errors = rundir.read_metric_columns(run / "metrics.csv", None)
    assert info is None and errors is None and metrics.returns.size == 60
