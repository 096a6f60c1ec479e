"""CartPole's physics as config: the twin equals Gymnasium with the same physics, exactly."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils import seeding

from cartpole_q.config import ConfigError, load_config
from cartpole_q.envs.gym import make_env
from cartpole_q.envs.registry import TwinSettings, twin_settings
from cartpole_q.families.cartpole import twin
from cartpole_q.store.rundir import metrics_csv
from cartpole_q.training import train

PHYSICS_SETTINGS = [
    {"kinematics_integrator": "semi-implicit euler"},
    {"length": 0.75, "masspole": 0.3},
    {"gravity": 3.7, "force_mag": 5.0},
    {"masscart": 2.5, "tau": 0.01, "kinematics_integrator": "semi-implicit euler"},
    {"theta_threshold_radians": 0.3, "x_threshold": 4.0},
    {"length": 0.05, "masspole": 0.01, "force_mag": 20.0, "x_threshold": 1.0},
]


@pytest.mark.parametrize("physics", PHYSICS_SETTINGS)
def test_twin_with_physics_follows_gymnasium_exactly(physics: dict) -> None:
    config = load_config(overrides={"env.physics": physics})
    env = make_env(config.env)
    settings = twin_settings("CartPole-v1", {}, 500, config.env.physics)
    assert isinstance(settings, TwinSettings)
    unwrapped = env.unwrapped
    for key, value in physics.items():
        assert getattr(unwrapped, key) == value
    assert unwrapped.total_mass == unwrapped.masspole + unwrapped.masscart
    assert unwrapped.polemass_length == unwrapped.masspole * unwrapped.length
    seed, steps = 3, 10_000
    actions = np.random.default_rng(seed).integers(0, 2, size=steps)
    rng = seeding.np_random(seed)[0]
    state, observation = np.empty(4), np.empty(4, dtype=np.float32)
    gym_observation, _ = env.reset(seed=seed)
    twin.reset(state, observation, rng, settings.params)
    length, episodes = 0, 0
    for step in range(steps):
        assert np.array_equal(state, unwrapped.state), f"state differs at step {step}"
        assert observation.tobytes() == gym_observation.tobytes(), step
        action = int(actions[step])
        gym_observation, gym_reward, gym_terminated, gym_truncated, _ = env.step(action)
        reward, terminated = twin.step(state, action, observation, rng, settings.params)
        length += 1
        assert (reward, terminated, length >= 500) == (gym_reward, gym_terminated, gym_truncated)
        if terminated or length >= 500:
            gym_observation, _ = env.reset()
            twin.reset(state, observation, rng, settings.params)
            length, episodes = 0, episodes + 1
    assert episodes > 20  # the comparison crossed many resets and terminations


@pytest.mark.parametrize(
    "env_overrides",
    [
        {"env.physics": {"length": 0.75, "kinematics_integrator": "semi-implicit euler"}},
        {"env.randomize": {"masspole": [0.05, 0.5], "force_mag": [5.0, 15.0]}},
        {
            "env.physics": {"gravity": 9.0, "tau": 0.015},
            "env.randomize": {"gravity": [8.0, 12.0], "length": [0.25, 0.75], "tau": [0.02, 0.02]},
        },
    ],
)
@pytest.mark.parametrize("algorithm", ["q_learning", "sarsa"])
def test_engines_agree_with_physics_and_randomisation(env_overrides: dict, algorithm: str) -> None:
    overrides = {**env_overrides, "agent.algorithm": algorithm, "train.episodes": 150,
                 "train.stop_when_solved": False}  # fmt: skip
    results = [
        train(load_config(overrides={**overrides, "engine": engine}), final_eval=False)
        for engine in ("numba", "gymnasium")
    ]
    assert results[0].engine == "numba" and results[1].engine == "gymnasium"
    assert results[0].q_table.tobytes() == results[1].q_table.tobytes()
    assert metrics_csv(results[0].metrics) == metrics_csv(results[1].metrics)
    assert results[0].evaluations == results[1].evaluations


def test_randomisation_draws_from_its_own_generator() -> None:
    # Adding a physics generator changed no existing run; a zero-width range changes nothing
    # but the physics generator's stream, so the run equals the plain one.
    plain = train(load_config(overrides={"train.episodes": 120}), final_eval=False)
    pinned = train(
        load_config(overrides={"train.episodes": 120, "env.randomize": {"tau": [0.02, 0.02]}}),
        final_eval=False,
    )
    assert plain.q_table.tobytes() == pinned.q_table.tobytes()
    varied = train(
        load_config(overrides={"train.episodes": 120, "env.randomize": {"tau": [0.01, 0.03]}}),
        final_eval=False,
    )
    assert metrics_csv(varied.metrics) != metrics_csv(plain.metrics)


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        ({"env.physics": {"lenght": 0.5}}, "env.physics.lenght"),
        ({"env.physics": {"masspole": 0}}, "env.physics.masspole"),
        ({"env.physics": {"length": -0.5}}, "env.physics.length"),
        ({"env.physics": {"tau": 0.0}}, "env.physics.tau"),
        ({"env.physics": {"kinematics_integrator": "rk4"}}, "env.physics.kinematics_integrator"),
        ({"env.randomize": {"masspole": [0.5, 0.05]}}, "env.randomize.masspole"),
        ({"env.randomize": {"x_threshold": [1, 2]}}, "env.randomize.x_threshold"),
        ({"env.randomize": {"length": 0.5}}, "env.randomize.length"),
        ({"env.id": "MountainCar-v0", "env.physics": {"tau": 0.01}}, "env.physics"),
        ({"env.id": "Acrobot-v1", "env.randomize": {"tau": [0.01, 0.02]}}, "env.randomize"),
    ],
)
def test_bad_physics_is_a_config_error_naming_the_key(overrides: dict, named: str) -> None:
    with pytest.raises(ConfigError, match=named.replace(".", r"\.")):
        load_config(overrides=overrides)


def test_config_yaml_writes_physics_as_given() -> None:
    config = load_config(
        overrides={"env.physics": {"length": 1}, "env.randomize": {"tau": [0.01, 0.02]}}
    )
    env = config.to_dict()["env"]
    assert env["physics"] == {"length": 1.0} and env["randomize"] == {"tau": [0.01, 0.02]}
    assert load_config().to_dict()["env"]["physics"] == {}  # never filled with defaults


@pytest.fixture(scope="module")
def solved_run(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    from tests.conftest import invoke

    out = tmp_path_factory.mktemp("runs") / "default"
    assert invoke("train", "--out", out, "-q").exit_code == 0
    return out


def _eval_json(*args: object) -> dict:
    import json

    from tests.conftest import invoke

    result = invoke("eval", *args, "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_eval_plays_under_other_physics_and_horizons(solved_run) -> None:  # type: ignore[no-untyped-def]
    assert _eval_json(solved_run, "--episodes", "5")["mean"] == 500.0
    weak = _eval_json(solved_run, "--episodes", "5", "--physics", "force_mag=0.5")
    assert weak["mean"] < 200  # too weak a push to hold the pole
    longer = _eval_json(solved_run, "--episodes", "3", "--max-steps", "800")
    assert 500 < longer["max"] <= 800


def test_eval_refuses_bad_physics(solved_run) -> None:  # type: ignore[no-untyped-def]
    from tests.conftest import invoke
    from tests.test_cli import assert_refused

    assert_refused(invoke("eval", solved_run, "--physics", "lenght=1"), "env.physics.lenght")
    assert_refused(invoke("eval", solved_run, "--physics", "masspole=-1"), "env.physics.masspole")
    assert_refused(invoke("eval", solved_run, "--physics", "masspole"), "masspole")


def test_robustness_grid_equals_eval_under_the_same_physics(solved_run, tmp_path) -> None:  # type: ignore[no-untyped-def]
    import csv

    from tests.conftest import invoke

    out = tmp_path / "robust.png"
    result = invoke(
        "robustness", solved_run, "--vary", "force_mag=0.5:10.5:3", "--episodes", "4",
        "--seed", "7", "--out", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert out.is_file() and out.read_bytes()[:4] == b"\x89PNG"
    rows = list(csv.DictReader((tmp_path / "robust_seeds.csv").open()))
    assert [float(row["force_mag"]) for row in rows] == [0.5, 5.5, 10.5]
    # the figure's data: the one seed's means as drawn, the trained value, the threshold
    drawn = list(csv.DictReader(out.with_suffix(".csv").open()))
    assert [(r["series"], r["x"], r["y"]) for r in drawn] == [
        *(("greedy mean return", row["force_mag"], row["mean"]) for row in rows),
        ("trained with force_mag", "10.0", ""), ("threshold", "", "475.0"),
    ]  # fmt: skip
    # the grid plays on the twin; eval --physics plays in gymnasium.make: the same returns
    for row in rows:
        played = _eval_json(
            solved_run,
            "--episodes",
            "4",
            "--seed",
            "7",
            "--physics",
            f"force_mag={row['force_mag']}",
        )
        assert float(row["mean"]) == played["mean"]
    assert float(rows[0]["mean"]) < 200 <= float(rows[2]["mean"])


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("--vary", "length=0.1:1"), "KEY=START:STOP:N"),
        (("--vary", "x_threshold=1:2:3"), "cannot vary"),
        (("--vary", "length=a:1:3"), "numbers"),
        (("--vary", "length=0.1:1:3", "--vary", "length=0.1:1:3"), "two different keys"),
        (("--preset", "nope"), "unknown"),
        ((), "--vary"),
    ],
)
def test_robustness_refuses_bad_axes(solved_run, tmp_path, args, named: str) -> None:  # type: ignore[no-untyped-def]
    from tests.conftest import invoke
    from tests.test_cli import assert_refused

    assert_refused(invoke("robustness", solved_run, *args, "--out", tmp_path / "r.png"), named)


def test_another_horizon_judges_success_by_the_environment_threshold_for_it(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """--max-steps 10000 counts success at 9,500, also for a run trained with its own threshold.

    A run's ``train.reward_threshold`` (such as 1995 of 2000 steps) stops its training;
    at its own horizon it stays the yardstick, at another one CartPole's scaled default is.
    """
    from cartpole_q.envs.gym import inspect_env
    from cartpole_q.evaluation import under_conditions
    from tests.conftest import invoke

    overrides = {
        "env.kwargs.max_episode_steps": 2000, "train.reward_threshold": 1995,
        "train.episodes": 3, "eval.episodes": 1,
    }  # fmt: skip
    config = load_config(overrides=overrides)
    for max_steps, threshold in ((None, 1995), (2000, 1995), (10_000, 9500), (500, 475)):
        assert inspect_env(under_conditions(config, None, max_steps)).reward_threshold == threshold
    default = load_config(overrides={"train.episodes": 3})
    assert inspect_env(under_conditions(default, None, 10_000)).reward_threshold == 9500

    run = tmp_path / "run"
    args = [f"{key}={value}" for key, value in overrides.items()]
    assert invoke("train", *(f"--set={arg}" for arg in args), "--out", run, "-q").exit_code == 0
    for options, shown in (([], ">= 1995"), (["--max-steps", "10000"], ">= 9500")):
        result = invoke("eval", run, "--episodes", "1", *options)
        assert result.exit_code == 0, result.output
        assert f"[{shown}: no]" in result.stdout, result.stdout
