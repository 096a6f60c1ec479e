"""Tile coding: the tile rule's properties, its config errors, greedy play, the shipped configs.

The byte-exact contract (every algorithm on tiles, both engines) is re-derived in
``test_rederivation.py::test_tile_coding``; here are the rule's own properties and learning.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from cartpole_q import load_config, train
from cartpole_q.errors import ConfigError
from cartpole_q.evaluation import evaluate
from cartpole_q.rl.tiles import active_tiles, tile_shape, values_on_grid
from tests.conftest import invoke

BINS = st.lists(st.integers(1, 7), min_size=1, max_size=4)


def _rows(x: list[float], bins: list[int], tilings: int) -> list[int]:
    rows = np.zeros(tilings, dtype=np.int64)
    active_tiles(x, [0.0] * len(bins), [1.0] * len(bins), bins, tilings, rows)
    return rows.tolist()


@settings(max_examples=300, deadline=None)
@given(bins=BINS, tilings=st.integers(2, 16), data=st.data())
def test_each_tiling_has_one_tile_in_its_own_block(
    bins: list[int], tilings: int, data: st.DataObject
) -> None:
    """Tiling t's row lies in [t * P, (t + 1) * P), P the tiles of one tiling."""
    x = data.draw(st.lists(st.floats(-0.5, 1.5), min_size=len(bins), max_size=len(bins)))
    per_tiling = math.prod(tile_shape(bins, tilings)[1:])
    rows = _rows(x, bins, tilings)
    assert [row // per_tiling for row in rows] == list(range(tilings))


@settings(max_examples=200, deadline=None)
@given(bins=st.integers(2, 9), tilings=st.integers(2, 16), position=st.floats(0.0, 0.999))
def test_the_tilings_split_a_bin_into_t_distinct_codes(
    bins: int, tilings: int, position: float
) -> None:
    """Within one bin, the T tilings' boundaries fall at the T fractions k / T of the bin.

    So the tuple of tiles changes exactly at the T - 1 inner fractions: the codes of the
    T sub-intervals of a bin are distinct (the resolution of T tilings is T times finer).
    """
    codes = []
    for k in range(tilings):
        x = (min(bins - 1, int(position * bins)) + (k + 0.5) / tilings) / bins
        codes.append(tuple(_rows([x], [bins], tilings)))
    assert len(set(codes)) == tilings


def test_offsets_are_asymmetric_and_one_bin_dimensions_ignored() -> None:
    """Sutton's (1 + 2k) offsets, k the rank among binned dimensions; by hand."""
    # Two binned dimensions (ranks 0 and 1) behind an ignored one; 4 tilings, 2 bins each.
    # x = 0.3 -> scaled 0.6 -> floor(2.4) = 2; y = 0.1 -> scaled 0.2 -> floor(0.8) = 0.
    rows = np.zeros(4, dtype=np.int64)
    active_tiles([9.0, 0.3, 0.1], [0.0] * 3, [1.0] * 3, [1, 2, 2], 4, rows)
    # tiling t: coord_x = (2 + t % 4) // 4, coord_y = (0 + 3t % 4) // 4; row = t*9 + 3cx + cy
    expected = [t * 9 + 3 * ((2 + t) // 4) + (3 * t % 4) // 4 for t in range(4)]
    assert rows.tolist() == expected == [0, 9, 21, 30]


def test_dyna_and_monte_carlo_are_refused_on_tiles() -> None:
    for algorithm in (
        "dyna_q", "dyna_q_plus", "monte_carlo", "monte_carlo_es", "off_policy_monte_carlo",
    ):  # fmt: skip
        with pytest.raises(ConfigError, match=r"discretization.tilings: tile coding"):
            load_config("mountaincar_tiles", {"agent.algorithm": algorithm})


def test_eval_in_gymnasium_plays_what_the_twin_played() -> None:
    """``cartpole-q eval`` (plain Python, gymnasium.make) sums the tiles as the twin did."""
    config = load_config(
        "mountaincar_tiles", {"train.episodes": 40, "eval.episodes": 5, "engine": "numba"}
    )
    result = train(config)
    assert result.q_table.shape == (16, 13, 13, 3)
    assert result.eval is not None
    again = evaluate(result.q_table, config)
    assert again.returns == result.eval.returns
    assert len(set(again.returns)) > 1  # not one policy that never moves


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed", "at_least"),
    [
        ("cartpole_tiles", 1000, 475.0),
        ("mountaincar_tiles", 1000, -110.0),
        ("acrobot_tiles", 2000, -100.0),
    ],
)
def test_the_shipped_tile_configs_learn(name: str, seed: int, at_least: float) -> None:
    """The acceptance figures' first seeds (README: 100/100, 99/100, 97/100 unseen seeds)."""
    result = train(load_config(name).for_seed(seed))
    assert result.eval is not None
    assert result.eval.mean >= at_least


def test_plot_policy_of_a_tiled_run_draws_the_tiles_sums(tmp_path: Path) -> None:
    """The policy map of tiles: the tiles' sums on the tilings' fine grid (values_on_grid)."""
    run = tmp_path / "run"
    trained = invoke(
        "train", "-c", "mountaincar_tiles", "--set", "train.episodes=30", "--out", run, "-q"
    )
    assert trained.exit_code == 0, trained.output
    out = tmp_path / "policy.png"
    drawn = invoke("plot", run, "--policy", "--out", out)
    assert drawn.exit_code == 0, drawn.output
    assert Image.open(out).size[0] > 1000
    weights = np.load(run / "q_table.npy")
    grid = values_on_grid(weights, [12, 12], [-1.2, -0.07], [0.6, 0.07], (0, 1), (3, 2))
    rows = np.zeros(16, dtype=np.int64)
    active_tiles([-1.2 + 1.5 * 0.6, 0.07 * 0.5], [-1.2, -0.07], [0.6, 0.07], [12, 12], 16, rows)
    assert np.allclose(grid[1, 1], weights.reshape(-1, 3)[rows].sum(axis=0))


def test_on_tiles_alpha_may_reach_the_number_of_tilings() -> None:
    """A tile's step is alpha / T: on tiles agent.alpha goes up to T (S&B's alpha x T)."""
    assert load_config("mountaincar_tiles", {"agent.alpha": 16}).agent.alpha.start == 16.0
    with pytest.raises(ConfigError, match=r"agent.alpha: must be in \(0, 16\], got 16.5"):
        load_config("mountaincar_tiles", {"agent.alpha": 16.5})
    with pytest.raises(ConfigError, match=r"agent.alpha: must be in \(0, 1\], got 1.5"):
        load_config("mountaincar", {"agent.alpha": 1.5})
