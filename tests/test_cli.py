"""The command line, in-process: run directories, output, and every bad input refused."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from cartpole_q.config import load_config
from tests.conftest import CONFIGS, invoke, write_yaml


def assert_refused(result, *named: str) -> None:  # type: ignore[no-untyped-def]
    """Exit code 2, a one-paragraph message naming ``named``, and no traceback."""
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    message = result.stderr
    assert message.startswith("error: "), message
    for text in named:
        assert text in message, message
    assert message.strip().count("\n") == 0, "one paragraph"


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run directory of the default config (solves CartPole in about 180 episodes)."""
    out = tmp_path_factory.mktemp("runs") / "default"
    result = invoke("train", "--out", out)
    assert result.exit_code == 0, result.output
    return out


def test_train_writes_the_contract_run_directory(trained_run: Path) -> None:
    files = {p.name for p in trained_run.iterdir()}
    assert {
        "config.yaml",
        "q_table.npy",
        "metrics.csv",
        "summary.json",
        "reward_curve.png",
    } <= files
    assert "checkpoint.npz" not in files  # removed once the run finished
    assert not [name for name in files if name.endswith(".tmp")]
    config = load_config(trained_run / "config.yaml")
    assert config == load_config()  # every default filled in, reproducing the run
    q = np.load(trained_run / "q_table.npy", allow_pickle=False)
    assert q.dtype == np.float64 and q.shape == (*config.discretization.bins, 2)
    visits = np.load(trained_run / "visits.npy", allow_pickle=False)
    assert visits.shape == q.shape and visits.dtype == np.int64
    summary = json.loads((trained_run / "summary.json").read_text())
    for key in ("episodes", "env_steps", "wall_seconds", "steps_per_second", "solved_episode",
                "eval", "engine", "seed", "versions"):  # fmt: skip
        assert key in summary
    assert set(summary["versions"]) == {"python", "numpy", "gymnasium", "numba", "cartpole_q"}
    assert summary["engine"] == "numba" and summary["seed"] == 0
    assert set(summary["eval"]) == {"mean", "std", "min", "max", "episodes", "seed", "played_in"}
    assert summary["q_table"] == {"episode": summary["solved_episode"], "source": "solve point"}
    lines = (trained_run / "metrics.csv").read_text().splitlines()
    assert lines[0] == "episode,return,length,epsilon,alpha"
    assert len(lines) - 1 == summary["episodes"]
    assert lines[1].startswith("1,")
    assert sum(int(line.split(",")[2]) for line in lines[1:]) == summary["env_steps"]
    with Image.open(trained_run / "reward_curve.png") as image:
        image.load()
        assert image.format == "PNG" and image.size == (800, 450)


def test_default_run_solves_and_evaluates_above_475(trained_run: Path) -> None:
    summary = json.loads((trained_run / "summary.json").read_text())
    assert summary["solved_episode"] is not None and summary["solved_episode"] <= 300
    result = invoke("eval", trained_run, "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert set(report) == {"mean", "std", "min", "max", "episodes", "seed", "played_in"}
    assert report["episodes"] == 100 and report["seed"] == 1000000
    assert report["played_in"] == "gymnasium"
    assert report["mean"] >= 475
    # the evaluation in summary.json ran on the twin and must equal Gymnasium's exactly
    assert {**report, "played_in": "twin"} == summary["eval"]


def test_train_prints_the_run_directory_last(in_tmp: Path) -> None:
    result = invoke("train", "--episodes", "20", "--quiet")
    assert result.exit_code == 0, result.output
    last = result.stdout.strip().splitlines()[-1]
    assert result.stdout.strip() == last  # --quiet prints nothing else
    assert last.startswith("runs/default-")
    assert (in_tmp / last / "summary.json").is_file()


@pytest.mark.parametrize(
    ("args", "prefix"),
    [
        (("--set", "env.id=FrozenLake-v1"), "frozenlake-"),
        (("--set", "env.id=FrozenLake-v1", "--set", "name=mine"), "mine-"),
        (("--set", "env.id=FrozenLake-v1", "--set", "name=default"), "default-"),
    ],
)
def test_a_run_of_another_env_is_named_after_it_unless_named(
    in_tmp: Path, args: tuple[str, ...], prefix: str
) -> None:
    result = invoke("train", *args, "--episodes", "2", "--engine", "gymnasium", "-q")
    assert result.exit_code == 0, result.output
    run = in_tmp / result.stdout.strip()
    assert run.parent.name == "runs" and run.name.startswith(prefix), run
    assert load_config(run / "config.yaml").name == prefix[:-1]


def test_two_runs_in_the_same_second_get_different_directories(in_tmp: Path) -> None:
    first = invoke("train", "--episodes", "5", "-q").stdout.strip()
    second = invoke("train", "--episodes", "5", "-q").stdout.strip()
    assert first != second and Path(first).is_dir() and Path(second).is_dir()


def test_same_config_and_seed_twice_gives_identical_files(tmp_path: Path) -> None:
    for name in ("a", "b"):
        assert invoke("train", "--seed", "3", "--out", tmp_path / name, "-q").exit_code == 0
    for file in ("q_table.npy", "metrics.csv", "visits.npy", "evaluations.csv", "config.yaml"):
        assert (tmp_path / "a" / file).read_bytes() == (tmp_path / "b" / file).read_bytes(), file


def test_config_yaml_of_a_run_reproduces_it(trained_run: Path, tmp_path: Path) -> None:
    assert (
        invoke(
            "train", "--config", trained_run / "config.yaml", "--out", tmp_path / "again", "-q"
        ).exit_code
        == 0
    )
    assert (tmp_path / "again/q_table.npy").read_bytes() == (
        trained_run / "q_table.npy"
    ).read_bytes()


def test_command_line_values_override_the_file(tmp_path: Path, small_config_file: Path) -> None:
    out = tmp_path / "run"
    result = invoke("train", "-c", small_config_file, "--episodes", "12", "--seed", "9",
                    "--engine", "gymnasium", "--out", out, "-q")  # fmt: skip
    assert result.exit_code == 0, result.output
    config = load_config(out / "config.yaml")
    assert (config.train.episodes, config.seed, config.engine, config.name) == (
        12,
        9,
        "gymnasium",
        "small",
    )
    assert json.loads((out / "summary.json").read_text())["engine"] == "gymnasium"


def test_plain_progress_lines_when_not_a_terminal(tmp_path: Path) -> None:
    result = invoke("train", "--episodes", "50", "--out", tmp_path / "r")
    assert result.exit_code == 0
    assert "\x1b" not in result.output  # no control codes
    assert "episode 10/50" in result.stdout and "avg100" in result.stdout
    assert "Training summary" in result.stdout


def test_eval_and_plot(trained_run: Path, tmp_path: Path) -> None:
    result = invoke("eval", trained_run, "--episodes", "3", "--seed", "5")
    assert result.exit_code == 0
    assert "over 3 episodes from seed 5" in result.stdout
    out = tmp_path / "curves.png"
    result = invoke("plot", trained_run, trained_run, "--out", out)
    assert result.exit_code == 0 and result.stdout.strip() == str(out)
    with Image.open(out) as image:
        assert image.size == (800, 450)


@pytest.mark.parametrize(
    ("kwargs", "engine"),
    # the twin reproduces no Gymnasium make option but the time limit
    [({}, "numba"), ({"disable_env_checker": True}, "gymnasium")],
)
def test_training_another_environment_picks_its_engine(
    tmp_path: Path, kwargs: dict, engine: str
) -> None:
    config = write_yaml(tmp_path / "mc.yaml", {
        "name": "mountaincar",
        "env": {"id": "MountainCar-v0", "kwargs": kwargs},
        "discretization": {"bins": [6, 6], "low": [-1.2, -0.07], "high": [0.6, 0.07]},
        "train": {"episodes": 3, "eval_every": 0},
        "eval": {"episodes": 1},
    })  # fmt: skip
    result = invoke("train", "-c", config, "--out", tmp_path / "run", "-q")
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "run/summary.json").read_text())
    assert summary["engine"] == engine and summary["env_steps"] == 600
    assert summary["reward_threshold"] == -110.0


# -- bad input: exit code 2, the field named, no traceback, no directory ----------------


@pytest.mark.parametrize(
    ("content", "named"),
    [
        ("seed: [unclosed", "not valid YAML"),
        ("[1, 2]", "must be a mapping"),
        ("seed: !!python/object/apply:os.system ['true']", "tag that is not allowed"),
        ("agent:\n  alpah: 0.1\n", "unknown key 'agent.alpah'; did you mean 'agent.alpha'?"),
        ("train:\n  episodes: many\n", "train.episodes"),
        ("discretization:\n  bins: [1, 1, 6.5, 12]\n", "discretization.bins"),
        ("seed: 1.5", "seed"),
        ("agent:\n  alpha: 1.5\n", "agent.alpha"),
        ("agent:\n  gamma: 2\n", "agent.gamma"),
        ("train:\n  episodes: 0\n", "train.episodes"),
        ("discretization:\n  bins: [1, 1, 0, 12]\n", "discretization.bins"),
        ("seed: -3", "seed"),
        ("discretization:\n  high: [2.4, 3.0, .nan, 3.5]\n", "discretization.high[2]"),
        (
            "discretization:\n  low: [-2.4, -.inf, -0.2, -3.5]\n",
            ("discretization.low[1]", "finite"),
        ),
        ("discretization:\n  low: [-1, -1]\n", ("discretization.low", "has 2 entries")),
        ("discretization:\n  low: [-2.4, -3.0, 0.3, -3.5]\n", "discretization.low"),
        (
            "discretization:\n  bins: [2, 10]\n  low: [-1, -1]\n  high: [1, 1]\n",
            ("discretization.bins", "4 dimensions"),
        ),
        ("env:\n  id: NoSuchEnv-v9\n", ("env.id", "NoSuchEnv")),
        (
            "env:\n  id: Pendulum-v1\ndiscretization:\n  bins: [2, 2, 2]\n  low: [-1, -1, -8]\n  high: [1, 1, 8]\n",
            ("env.id", "Discrete actions"),
        ),
        (
            "env:\n  id: FrozenLake-v1\ndiscretization:\n  bins: [4]\n  low: [0]\n  high: [16]\n",
            ("discretization", "Discrete(16)", "leave discretization out"),
        ),
        ("env:\n  kwargs: {no_such_argument: 1}\n", "env.kwargs"),
        (
            "discretization:\n  bins: [100, 100, 100, 100]\n",
            ("discretization.bins", "1.5 GiB", "agent.max_q_table_bytes"),
        ),
        (
            "agent:\n  max_q_table_bytes: 100\n",
            ("discretization.bins", "320 bytes", "above the limit of 100 bytes"),
        ),
        ("name: ../../escape", "name"),
        ("name: a/b", "name"),
        (
            "engine: numba\nenv:\n  kwargs: {disable_env_checker: true}\n",
            ("engine: numba", "'disable_env_checker'"),
        ),
        # training never renders; a window with no display failed only after ~12 s
        (
            "env:\n  kwargs: {render_mode: human}\n",
            ("env.kwargs.render_mode: cannot be set in a config", "eval RUN --video"),
        ),
    ],
)
def test_bad_config_is_refused_without_a_trace(
    in_tmp: Path, content: str, named: str | tuple[str, ...]
) -> None:
    path = in_tmp / "bad.yaml"
    path.write_text(content, encoding="utf-8")
    result = invoke("train", "--config", path)
    assert_refused(result, str(path), *((named,) if isinstance(named, str) else named))
    assert not (in_tmp / "runs").exists()


@pytest.mark.parametrize(
    ("content", "named"),
    [
        ("discretization:\n  bins: [2, 10]\n  low: [-1, -1]\n  high: [1, 1]\n", "4 dimensions"),
        (
            "env:\n  id: Pendulum-v1\ndiscretization:\n  bins: [2, 2, 2]\n  low: [-1, -1, -8]\n  high: [1, 1, 8]\n",
            "Discrete actions",
        ),
        ("discretization:\n  bins: [100, 100, 100, 100]\n", "1.5 GiB"),
    ],
)
def test_environment_errors_explain_themselves(in_tmp: Path, content: str, named: str) -> None:
    path = in_tmp / "bad.yaml"
    path.write_text(content, encoding="utf-8")
    assert_refused(invoke("train", "-c", path), named)


def test_missing_config_file(in_tmp: Path) -> None:
    assert_refused(invoke("train", "-c", in_tmp / "missing.yaml"), "missing.yaml", "not found")
    assert_refused(invoke("train", "-c", "blgo"), "blgo", "blog, ", "default, ", "sarsa")
    assert not (in_tmp / "runs").exists()


def test_configs_lists_the_shipped_configs_and_train_takes_their_names(in_tmp: Path) -> None:
    listed = invoke("configs")
    assert listed.exit_code == 0, listed.output
    names = [line.split()[0] for line in listed.stdout.splitlines()]
    assert names == sorted(path.stem for path in CONFIGS.glob("*.yaml"))
    assert {"blog", "default", "sarsa", "mountaincar"} <= set(names)
    assert "Sutton & Barto" in listed.stdout
    out = in_tmp / "run"
    result = invoke("train", "-c", "sutton_barto", "--episodes", "3", "--out", out, "-q")
    assert result.exit_code == 0, result.output
    assert load_config(out / "config.yaml") == load_config(
        CONFIGS / "sutton_barto.yaml", {"train.episodes": 3}
    )


def test_set_changes_any_key_and_is_validated_like_a_file(in_tmp: Path) -> None:
    out = in_tmp / "run"
    result = invoke(
        "train", "--set", "agent.alpha=5e-4", "--set", "discretization.bins=[1,1,6,12]",
        "--set", "env.kwargs.max_episode_steps=1000", "--set", "agent.epsilon.k=25",
        "--set", "train.episodes=4", "--out", out, "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    config = load_config(out / "config.yaml")
    assert config.agent.alpha.start == 0.0005
    assert config.discretization.bins == (1, 1, 6, 12)
    assert config.env.kwargs["max_episode_steps"] == 1000
    assert (config.agent.epsilon.kind, config.agent.epsilon.rate) == ("log", 25.0)
    assert config.train.episodes == 4
    # the default threshold scales with the time limit: 475 of 500 steps is 950 of 1000
    assert json.loads((out / "summary.json").read_text())["reward_threshold"] == 950.0
    # an explicit option given after --set wins
    result = invoke(
        "train", "--set", "train.episodes=9", "--episodes", "3", "--out", in_tmp / "r2", "-q"
    )
    assert load_config(in_tmp / "r2" / "config.yaml").train.episodes == 3


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--set", "agent.alpha"], ("--set 'agent.alpha'", "KEY=VALUE")),
        (["--set", "agent.alpah=0.1"], ("unknown key 'agent.alpah'", "did you mean 'agent.alpha'?")),
        (["--set", "agent.alpha=2"], ("command line: agent.alpha: must be in (0, 1]",)),
        (["--set", "discretization.bins=[1,1,6]"], ("discretization.low: has 4 entries",)),
        (["--set", "env.id=no_such_module_xyz:Env-v0"], ("env.id", "'no_such_module_xyz' cannot be imported")),
    ],
)  # fmt: skip
def test_bad_set_values_are_refused(in_tmp: Path, args: list[str], named: tuple[str, ...]) -> None:
    assert_refused(invoke("train", *args), *named)
    assert not (in_tmp / "runs").exists()


def test_eval_of_a_run_whose_env_id_names_a_module(trained_run: Path, tmp_path: Path) -> None:
    # A run directory is data: what its env.id names is not imported (issue 29).
    run = tmp_path / "run"
    shutil.copytree(trained_run, run)
    path = run / "config.yaml"
    path.write_text(path.read_text().replace("id: CartPole-v1", "id: no_such_module_xyz:Env-v0"))
    assert_refused(
        invoke("eval", run, "--episodes", "1"),
        "config.yaml: env.id:",
        "would import the module 'no_such_module_xyz'",
    )
    video = tmp_path / "x.gif"
    assert_refused(invoke("eval", run, "--episodes", "1", "--video", video), "'no_such_module_xyz'")
    assert not video.exists()


def test_an_empty_config_file_trains_the_default(in_tmp: Path) -> None:
    path = in_tmp / "empty.yaml"
    path.write_text("# nothing to change\n", encoding="utf-8")
    result = invoke("train", "-c", path, "--episodes", "3", "--out", in_tmp / "run", "-q")
    assert result.exit_code == 0, result.output
    assert load_config(in_tmp / "run" / "config.yaml") == load_config(
        overrides={"train.episodes": 3}
    )


def test_bad_command_line_values(in_tmp: Path) -> None:
    for args in (["--episodes", "0"], ["--seed", "-1"], ["--engine", "turbo"], ["--seeds", "9-1"]):
        result = invoke("train", *args)
        assert result.exit_code == 2, (args, result.output)
        assert "Traceback" not in result.output
    assert_refused(invoke("train", "--seed", "1", "--seeds", "0-3"), "--seed", "--seeds")
    assert not (in_tmp / "runs").exists()


@pytest.mark.parametrize("args", [("--seeds", "0,0"), ("--set", "train.seeds=[0, 3, 0]")])
def test_a_seed_given_twice_is_refused(in_tmp: Path, args: tuple[str, ...]) -> None:
    """Not one run silently: a repeated seed is more likely a typo."""
    assert_refused(invoke("train", *args), "train.seeds: seed 0 is given twice")
    assert not (in_tmp / "runs").exists()


def test_out_must_be_new_or_empty(tmp_path: Path) -> None:
    existing = tmp_path / "existing"
    existing.mkdir()
    (existing / "keep.txt").write_text("mine")
    assert_refused(invoke("train", "--out", existing), str(existing), "non-empty directory")
    assert sorted(p.name for p in existing.iterdir()) == ["keep.txt"]
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    assert_refused(invoke("train", "--out", a_file), str(a_file), "this is a file")
    assert a_file.read_text() == "x"
    assert_refused(invoke("train", "--out", a_file / "run"), "cannot create the run directory")
    empty = tmp_path / "empty"
    empty.mkdir()
    assert invoke("train", "--out", empty, "--episodes", "3", "-q").exit_code == 0


# -- eval and plot refuse what is not a complete, sound run ------------------------------


def _damaged(trained_run: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "damaged"
    shutil.copytree(trained_run, copy)
    return copy


@pytest.mark.parametrize("command", ["eval", "plot"])
def test_not_a_run_directory(tmp_path: Path, command: str) -> None:
    assert_refused(invoke(command, tmp_path / "nowhere"), "nowhere", "does not exist")
    assert_refused(invoke(command, tmp_path), str(tmp_path), "not a run directory")


@pytest.mark.parametrize(
    ("damage", "named"),
    [
        (lambda d: (d / "q_table.npy").unlink(), "q_table.npy: is missing"),
        (lambda d: (d / "summary.json").unlink(), "training did not finish"),
        (lambda d: (d / "metrics.csv").unlink(), "metrics.csv: is missing"),
        (
            lambda d: (d / "q_table.npy").write_bytes((d / "q_table.npy").read_bytes()[:100]),
            "q_table.npy",
        ),
        (
            lambda d: (d / "q_table.npy").write_bytes(b"not an array"),
            "q_table.npy: is not a NumPy array file",
        ),
        (
            lambda d: (d / "q_table.npy").write_bytes(np.random.default_rng(0).bytes(256)),
            "q_table.npy: is not a NumPy array file",
        ),
        (lambda d: np.save(d / "q_table.npy", np.zeros((3, 3))), "has shape (3, 3)"),
        (
            lambda d: (
                np.save(d / "q_table.npy", np.zeros((1, 1, 2, 10, 3))),
                np.save(d / "visits.npy", np.zeros((1, 1, 2, 10, 3), dtype=np.int64)),
            ),
            "3 actions per state",
        ),
        (
            lambda d: np.save(d / "q_table.npy", np.zeros((1, 1, 2, 10, 2), dtype=np.float32)),
            "float64",
        ),
        (lambda d: np.save(d / "q_table.npy", np.full((1, 1, 2, 10, 2), np.nan)), "NaN"),
        (
            lambda d: np.save(
                d / "q_table.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True
            ),
            "Python objects",
        ),
        (lambda d: (d / "config.yaml").write_text("agent: {alpha: 7}\n"), "config.yaml"),
        (lambda d: (d / "summary.json").write_text("{truncated"), "summary.json"),
        (
            lambda d: ((d / "q_table.npy").unlink(), (d / "q_table.npy").mkdir()),
            "q_table.npy: is a directory, but a .npy array file is expected here",
        ),
        (
            lambda d: ((d / "summary.json").unlink(), (d / "summary.json").mkdir()),
            "summary.json: is a directory, not a JSON file",
        ),
        (
            lambda d: ((d / "metrics.csv").unlink(), (d / "metrics.csv").mkdir()),
            "metrics.csv: is a directory, not a CSV file",
        ),
        (lambda d: (d / "metrics.csv").write_text("a,b\n1,2\n"), "metrics.csv"),
    ],
)
def test_eval_refuses_damaged_runs(trained_run: Path, tmp_path: Path, damage, named: str) -> None:  # type: ignore[no-untyped-def]
    run = _damaged(trained_run, tmp_path)
    damage(run)
    assert_refused(invoke("eval", run), named)


def test_plot_refuses_a_damaged_run(trained_run: Path, tmp_path: Path) -> None:
    run = _damaged(trained_run, tmp_path)
    (run / "metrics.csv").write_text("episode,return,length,epsilon,alpha\n1,x,2,3,4\n")
    assert_refused(invoke("plot", run, "--out", tmp_path / "p.png"), "metrics.csv")
    assert not (tmp_path / "p.png").exists()
    assert_refused(invoke("plot", trained_run, "--out", tmp_path), "is a directory")


# -- start-up cost -----------------------------------------------------------------------


def _imported_modules(code: str) -> set[str]:
    output = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    return set(output.split())


@pytest.mark.slow
def test_help_does_not_import_heavy_libraries() -> None:
    code = (
        "import sys\nfrom typer.testing import CliRunner\nfrom cartpole_q.cli import app\n"
        "assert CliRunner().invoke(app, ['--help']).exit_code == 0\n"
        "assert CliRunner().invoke(app, ['train', '--help']).exit_code == 0\n"
        "print(' '.join(sys.modules))"
    )
    modules = _imported_modules(code)
    assert not {"numba", "matplotlib", "gymnasium", "numpy"} & modules


@pytest.mark.slow
def test_eval_and_plot_do_not_import_numba(trained_run: Path, tmp_path: Path) -> None:
    code = (
        "import sys\nfrom typer.testing import CliRunner\nfrom cartpole_q.cli import app\n"
        f"assert CliRunner().invoke(app, ['eval', r'{trained_run}', '--episodes', '2']).exit_code == 0\n"
        f"assert CliRunner().invoke(app, ['plot', r'{trained_run}', '--out', r'{tmp_path / 'p.png'}']).exit_code == 0\n"
        "print(' '.join(sys.modules))"
    )
    modules = _imported_modules(code)
    assert "gymnasium" in modules and "numba" not in modules


def test_resolved_config_shows_every_key(trained_run: Path) -> None:
    resolved = yaml.safe_load((trained_run / "config.yaml").read_text())
    default = yaml.safe_load((CONFIGS / "default.yaml").read_text())
    assert resolved.keys() == default.keys()
    for section in ("env", "discretization", "agent", "train", "eval"):
        assert resolved[section].keys() == default[section].keys()


def test_the_version_is_one_the_command_the_package_and_its_metadata_agree_on() -> None:
    import importlib.metadata

    import cartpole_q

    result = invoke("--version")
    assert result.exit_code == 0
    assert result.output.strip() == f"cartpole-q {cartpole_q.__version__}"
    assert importlib.metadata.version("cartpole-q") == cartpole_q.__version__
    changelog = (Path(__file__).resolve().parents[1] / "CHANGELOG.md").read_text()
    assert f"## [{cartpole_q.__version__}]" in changelog
