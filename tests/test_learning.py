"""Learning: the default config solves CartPole; the blog tutorial's does not."""

from __future__ import annotations

import numpy as np
import pytest

from cartpole_q.config import load_config
from cartpole_q.envs.gym import inspect_env
from cartpole_q.evaluation import evaluate
from cartpole_q.training import train
from tests.conftest import CONFIGS

pytestmark = pytest.mark.slow


def test_default_config_solves_on_real_gymnasium_for_nine_of_ten_seeds() -> None:
    config = load_config(overrides={"engine": "gymnasium", "train.eval_every": 0})
    info = inspect_env(config)
    means, solved = [], []
    for seed in range(10):
        result = train(config.for_seed(seed), env_info=info)
        assert result.engine == "gymnasium" and result.eval is not None
        means.append(result.eval.mean)
        solved.append(result.solved_episode)
    assert sum(mean >= 475 for mean in means) >= 9, means
    assert all(episode is not None and episode <= 300 for episode in solved), solved


def test_default_config_on_the_twin_succeeds_and_solves_fast_across_seeds() -> None:
    config = load_config(overrides={"train.eval_every": 0})
    info = inspect_env(config)
    results = [train(config.for_seed(seed), env_info=info) for seed in range(100, 140)]
    assert all(result.engine == "numba" for result in results)
    successes = sum(result.eval is not None and result.eval.mean >= 475 for result in results)
    assert successes >= 39
    assert np.median([result.solved_episode or 10**6 for result in results]) <= 200


def test_a_kept_table_plays_as_well_in_gymnasium_as_its_summary_says() -> None:
    result = train(load_config(overrides={"seed": 11}))
    played = evaluate(result.q_table, result.config)
    assert result.eval is not None and played.played_in == "gymnasium"
    assert (played.returns, played.seed) == (
        result.eval.returns,
        result.eval.seed,
    )  # twin = Gymnasium


def test_blog_config_learns_almost_nothing() -> None:
    config = load_config(CONFIGS / "blog.yaml", {"train.eval_every": 0})
    info = inspect_env(config)
    means = []
    for seed in range(5):
        result = train(config.for_seed(seed), env_info=info)
        assert result.solved_episode is None and result.episodes == 1000
        means.append(result.eval.mean if result.eval else 0.0)
    assert max(means) < 200 and np.mean(means) < 100, means


CANON_CONFIGS = {
    # shipped config: successes it must reach on 20 seeds it was not tuned on (the README's
    # 100-seed figures: 99-100/100 for the TD methods, 96/100 for Monte Carlo)
    "n_step_sarsa": 19,
    "tree_backup": 19,
    "sarsa_lambda": 19,
    "q_lambda": 19,
    "true_online_sarsa_lambda": 19,
    "dyna_q": 19,
    "dyna_q_plus": 19,
    "monte_carlo": 17,
    "actor_critic": 19,
}


@pytest.mark.parametrize("name", list(CANON_CONFIGS))
def test_each_canon_config_solves_cartpole_on_unseen_seeds(name: str) -> None:
    config = load_config(CONFIGS / f"{name}.yaml", {"train.eval_every": 0})
    info = inspect_env(config)
    results = [train(config.for_seed(seed), env_info=info) for seed in range(3000, 3020)]
    assert all(result.engine == "numba" for result in results)
    means = [result.eval.mean if result.eval is not None else 0.0 for result in results]
    assert sum(mean >= 475 for mean in means) >= CANON_CONFIGS[name], means
