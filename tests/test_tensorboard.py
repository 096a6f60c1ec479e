"""train --tensorboard: event files read back with TensorBoard's own reader equal the run's files."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

pytest.importorskip("tensorboardX")
event_accumulator = pytest.importorskip("tensorboard.backend.event_processing.event_accumulator")
hparams_metadata = pytest.importorskip("tensorboard.plugins.hparams.metadata")

QUICK = (
    "--episodes", "120", "--set", "train.stop_when_solved=false", "--set", "train.eval_every=20",
    "--quiet",
)  # fmt: skip
PER_EPISODE = {
    "charts/episodic_return": "return",
    "charts/episodic_length": "length",
    "charts/epsilon": "epsilon",
    "charts/learning_rate": "alpha",
}


def _accumulator(directory: Path):  # type: ignore[no-untyped-def]
    accumulator = event_accumulator.EventAccumulator(
        str(directory), size_guidance={event_accumulator.SCALARS: 0}
    )
    accumulator.Reload()
    return accumulator


def _scalars(directory: Path) -> dict[str, tuple[list[int], list[float]]]:
    accumulator = _accumulator(directory)
    return {
        tag: ([event.step for event in accumulator.Scalars(tag)],
              [event.value for event in accumulator.Scalars(tag)])
        for tag in accumulator.Tags()["scalars"]
    }  # fmt: skip


def _csv_columns(path: Path) -> dict[str, list[str]]:
    with path.open(newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {key: [row[key] for row in rows] for key in rows[0]}


def _float32(texts: list[str]) -> list[float]:
    """The CSV's numbers as TensorBoard stores them (float32), widened back for comparing."""
    return [float(np.float32(float(text))) for text in texts]


def _hparams(directory: Path) -> dict[str, object]:
    content = _accumulator(directory).PluginTagToContent("hparams")
    start = hparams_metadata.parse_session_start_info_plugin_data(
        content[hparams_metadata.SESSION_START_INFO_TAG]
    )
    values: dict[str, object] = {}
    for name, value in start.hparams.items():
        values[name] = getattr(value, value.WhichOneof("kind"))
    return values


@pytest.fixture(scope="module")
def boarded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tensorboard") / "run"
    result = invoke("train", *QUICK, "--tensorboard", "--out", out)
    assert result.exit_code == 0, result.output
    return out


def test_scalars_have_cleanrl_and_sb3_names_and_the_values_of_metrics_csv(boarded: Path) -> None:
    scalars = _scalars(boarded / "tensorboard")
    assert sorted(scalars) == sorted(
        [*PER_EPISODE, "rollout/ep_rew_mean", "rollout/ep_len_mean", "eval/mean_reward",
         "charts/SPS", "summary/eval_mean", "summary/success"]
    )  # fmt: skip
    metrics = _csv_columns(boarded / "metrics.csv")
    env_steps = np.cumsum([int(length) for length in metrics["length"]]).tolist()
    assert len(env_steps) == 120
    for tag, column in PER_EPISODE.items():
        steps, values = scalars[tag]
        assert steps == env_steps, tag
        assert values == _float32(metrics[column]), tag
    returns = [float(value) for value in metrics["return"]]
    lengths = [float(value) for value in metrics["length"]]
    expected_means = [np.mean(returns[max(0, i - 99) : i + 1]) for i in range(120)]
    assert scalars["rollout/ep_rew_mean"] == (env_steps, _float32(list(map(str, expected_means))))
    expected_lengths = [np.mean(lengths[max(0, i - 99) : i + 1]) for i in range(120)]
    assert scalars["rollout/ep_len_mean"][1] == _float32(list(map(str, expected_lengths)))

    evaluations = _csv_columns(boarded / "evaluations.csv")
    assert evaluations["episode"] == ["20", "40", "60", "80", "100", "120"]
    assert scalars["eval/mean_reward"] == (
        [int(steps) for steps in evaluations["env_steps"]], _float32(evaluations["mean"])
    )  # fmt: skip
    assert [env_steps[int(episode) - 1] for episode in evaluations["episode"]] == [
        int(steps) for steps in evaluations["env_steps"]
    ]
    summary = json.loads((boarded / "summary.json").read_text())
    assert scalars["charts/SPS"] == ([env_steps[-1]], _float32([str(summary["steps_per_second"])]))
    assert scalars["summary/eval_mean"] == (
        [env_steps[-1]],
        _float32([str(summary["eval"]["mean"])]),
    )
    success = summary["eval"]["mean"] >= summary["reward_threshold"]
    assert scalars["summary/success"] == ([env_steps[-1]], [float(success)])


def test_the_config_is_logged_as_hyperparameters(boarded: Path) -> None:
    hparams = _hparams(boarded / "tensorboard")
    config = yaml.safe_load((boarded / "config.yaml").read_text())
    assert hparams["seed"] == 0.0
    assert hparams["env.id"] == "CartPole-v1"
    assert hparams["agent.algorithm"] == config["agent"]["algorithm"]
    assert hparams["agent.gamma"] == config["agent"]["gamma"]
    assert hparams["train.episodes"] == 120.0
    assert hparams["train.stop_when_solved"] is False
    assert hparams["discretization.bins"] == json.dumps(config["discretization"]["bins"])
    assert hparams["env.physics"] == "{}"
    assert "train.tensorboard" not in hparams and "train.seeds" not in hparams
    content = _accumulator(boarded / "tensorboard").PluginTagToContent("hparams")
    # no experiment of its own: TensorBoard builds the table from all the runs it finds
    assert sorted(content) == sorted(
        [hparams_metadata.SESSION_START_INFO_TAG, hparams_metadata.SESSION_END_INFO_TAG]
    )


def test_tensorboard_changes_no_other_output(boarded: Path, tmp_path: Path) -> None:
    plain = tmp_path / "plain"
    assert invoke("train", *QUICK, "--out", plain).exit_code == 0
    for name in ("q_table.npy", "visits.npy", "metrics.csv", "evaluations.csv"):
        assert (boarded / name).read_bytes() == (plain / name).read_bytes(), name
    timing = {"wall_seconds", "train_seconds", "steps_per_second", "finished_at"}
    with_board, without = (
        json.loads((path / "summary.json").read_text()) for path in (boarded, plain)
    )
    assert {k: v for k, v in with_board.items() if k not in timing} == {
        k: v for k, v in without.items() if k not in timing
    }
    assert (boarded / "config.yaml").read_text().replace(
        "tensorboard: true", "tensorboard: false"
    ) == (plain / "config.yaml").read_text()
    assert not (plain / "tensorboard").exists()


def test_an_extended_run_holds_one_event_file_with_the_whole_history(tmp_path: Path) -> None:
    run = tmp_path / "run"
    assert invoke("train", *QUICK, "--tensorboard", "--episodes", "50", "--out", run).exit_code == 0
    assert len(list((run / "tensorboard").iterdir())) == 1
    extended = invoke("train", "--resume", run, "--episodes", "80", "--quiet")
    assert extended.exit_code == 0, extended.output
    assert len(list((run / "tensorboard").iterdir())) == 1
    steps, returns = _scalars(run / "tensorboard")["charts/episodic_return"]
    metrics = _csv_columns(run / "metrics.csv")
    assert len(returns) == 80
    assert returns == _float32(metrics["return"])
    assert steps == np.cumsum([int(length) for length in metrics["length"]]).tolist()


def test_each_seed_of_a_multi_seed_run_is_one_hparams_session(tmp_path: Path) -> None:
    parent = tmp_path / "seeds"
    result = invoke(
        "train", *QUICK, "--seeds", "3,5", "--tensorboard", "--workers", "1", "--out", parent
    )
    assert result.exit_code == 0, result.output
    for seed in (3, 5):
        child = parent / f"seed-{seed:03d}"
        assert _hparams(child / "tensorboard")["seed"] == float(seed)
        returns = _scalars(child / "tensorboard")["charts/episodic_return"][1]
        assert returns == _float32(_csv_columns(child / "metrics.csv")["return"])
    assert not (parent / "tensorboard").exists()


def test_without_the_extra_the_option_names_it(
    in_tmp: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "tensorboardX", None)  # import fails as if not installed
    result = invoke("train", "--tensorboard", "--out", in_tmp / "run")
    assert_refused(result, "--tensorboard", 'pip install "cartpole-q[tensorboard]"')
    assert not (in_tmp / "run").exists()
    result = invoke("train", "--set", "train.tensorboard=true", "--out", in_tmp / "run")
    assert_refused(result, "train.tensorboard", "cartpole-q[tensorboard]")
    assert not (in_tmp / "run").exists()


def test_tensorboard_is_a_boolean_and_off_by_default(in_tmp: Path) -> None:
    from cartpole_q.config import load_config

    assert load_config().train.tensorboard is False
    assert_refused(invoke("train", "--set", "train.tensorboard=maybe"), "train.tensorboard")


def test_resume_takes_the_run_as_it_was_configured(boarded: Path) -> None:
    assert_refused(invoke("train", "--resume", boarded, "--tensorboard"), "--tensorboard")


STUDY_BASE = {
    "name": "board",
    "train": {"episodes": 30, "stop_when_solved": False, "eval_every": 0, "tensorboard": True},
    "eval": {"episodes": 2},
}


def test_a_sweep_writes_one_hparams_session_per_point_and_seed(tmp_path: Path) -> None:
    from cartpole_q.store.sweepdir import read_curves

    sweep = write_yaml(
        tmp_path / "s.yaml",
        {"name": "board", "base": STUDY_BASE, "seeds": "0-1", "grid": {"agent.alpha": [0.1, 0.5]}},
    )
    result = invoke("sweep", sweep, "--out", tmp_path / "out", "--workers", "1", "-q")
    assert result.exit_code == 0, result.output
    board = tmp_path / "out" / "tensorboard"
    sessions = sorted(path.relative_to(board).as_posix() for path in board.glob("*/*"))
    assert sessions == ["000/seed-000", "000/seed-001", "001/seed-000", "001/seed-001"]
    for point, alpha in (("000", 0.1), ("001", 0.5)):
        curves = read_curves(tmp_path / "out", point)
        for seed in (0, 1):
            directory = board / point / f"seed-{seed:03d}"
            hparams = _hparams(directory)
            assert (hparams["agent.alpha"], hparams["seed"]) == (alpha, float(seed))
            scalars = _scalars(directory)
            returns, lengths = curves[f"seed-{seed:03d}"]
            assert scalars["charts/episodic_return"] == (
                np.cumsum(lengths).tolist(), [float(np.float32(value)) for value in returns]
            )  # fmt: skip
            assert "summary/eval_mean" in scalars and "charts/epsilon" not in scalars


def test_a_tune_study_writes_one_hparams_session_per_trial_and_seed(tmp_path: Path) -> None:
    pytest.importorskip("optuna")
    tune = write_yaml(
        tmp_path / "t.yaml",
        {
            "name": "board", "base": STUDY_BASE, "seeds": "0-1", "trials": 2,
            "space": {"agent.alpha": {"low": 0.05, "high": 1.0}},
            "sampler": {"type": "random", "seed": 3},
        },
    )  # fmt: skip
    result = invoke("tune", tune, "--out", tmp_path / "out", "--workers", "1", "-q")
    assert result.exit_code == 0, result.output
    board = tmp_path / "out" / "tensorboard"
    sessions = sorted(path.relative_to(board).as_posix() for path in board.glob("*/*"))
    assert sessions == [
        "trial-0000/seed-000", "trial-0000/seed-001", "trial-0001/seed-000", "trial-0001/seed-001"
    ]  # fmt: skip
    alphas = {_hparams(board / "trial-0000" / "seed-000")["agent.alpha"]}
    alphas.add(_hparams(board / "trial-0001" / "seed-001")["agent.alpha"])
    assert len(alphas) == 2  # each trial's own sampled value
    assert _hparams(board / "trial-0001" / "seed-001")["seed"] == 1.0


def test_a_study_without_the_extra_is_refused_before_it_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "tensorboardX", None)
    sweep = write_yaml(tmp_path / "s.yaml", {"name": "board", "base": STUDY_BASE, "seeds": "0"})
    assert_refused(invoke("sweep", sweep, "--out", tmp_path / "out"), "cartpole-q[tensorboard]")
    assert not (tmp_path / "out").exists()
