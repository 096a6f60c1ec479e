"""A compiled twin of ``cartpole_q/BlackjackES-v0``: Blackjack started in a random state.

``reset`` repeats ``BlackjackExploringStartsEnv.reset`` draw for draw: the player sum
``12 + integers(0, 10)``, the dealer's face-up card ``1 + integers(0, 10)``, the usable ace
``integers(0, 2)``, then the dealer's hidden card (``integers(0, 13)``, the deck's index),
nothing more. The player's cards are ``exploring_hand``'s: with a usable ace an ace and
``sum - 11``, without a 10 and ``sum - 10``; a 21 is three cards (an ace and two 5s, or a
10, a 5 and a 6), never a natural. ``step`` is the Blackjack twin's
(:mod:`cartpole_q.families.blackjack.twin`), and so are the state, the observation and
``params`` (``(sab, natural)``, read from the environment ``gymnasium.make`` builds).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.blackjack.twin import (
    DEALER,
    DEALER_CARD,
    N_ACTIONS,
    OBSERVATION_DTYPE,
    OBSERVATION_KIND,
    OBSERVATION_SIZE,
    PARAM_NAMES,
    PLAYER,
    READS_ENVIRONMENT,
    REFUSED_KWARGS,
    STATE_DTYPE,
    STATE_SIZE,
    add_card,
    draw_card,
    step,
    twin_params,
    write_observation,
)
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

__all__ = [
    "N_ACTIONS", "OBSERVATION_DTYPE", "OBSERVATION_KIND", "OBSERVATION_SIZE", "PARAM_NAMES",
    "READS_ENVIRONMENT", "REFUSED_KWARGS", "STATE_DTYPE", "STATE_SIZE", "reset", "step",
    "twin_params",
]  # fmt: skip

LOWEST_SUM = 12
"""the lowest player sum dealt (10 sums, 12 to 21)"""
SUMS = 10
DEALER_CARDS = 10
"""the dealer's face-up card, 1 (an ace) to 10"""


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: Any
) -> None:
    """Draw the sum, the dealer's card and the usable ace; deal the hidden card and the hand."""
    state[:] = 0
    player_sum = LOWEST_SUM + int(rng.integers(0, SUMS))
    card = 1 + int(rng.integers(0, DEALER_CARDS))
    usable_ace = rng.integers(0, 2) == 1
    add_card(state, DEALER, card)
    add_card(state, DEALER, draw_card(rng))
    state[DEALER_CARD] = card
    if player_sum == 21 and usable_ace:
        add_card(state, PLAYER, 1)
        add_card(state, PLAYER, 5)
        add_card(state, PLAYER, 5)
    elif player_sum == 21:
        add_card(state, PLAYER, 10)
        add_card(state, PLAYER, 5)
        add_card(state, PLAYER, 6)
    elif usable_ace:
        add_card(state, PLAYER, 1)
        add_card(state, PLAYER, player_sum - 11)
    else:
        add_card(state, PLAYER, 10)
        add_card(state, PLAYER, player_sum - 10)
    write_observation(state, observation)
