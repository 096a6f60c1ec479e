"""A compiled twin of Gymnasium's ``BlackjackEnv`` (``Blackjack-v1``), bit-identical to it.

``reset`` and ``step`` repeat ``gymnasium.envs.toy_text.blackjack`` draw for draw. A card is
``int(np_random.choice(deck))`` with ``deck = [1, 2, ..., 9, 10, 10, 10, 10]``, which NumPy
draws as ``np_random.integers(0, 13)`` (the deck's index); ``reset`` deals the dealer's two
cards, then the player's two, then draws the dealer's face-up card's picture, which changes
no observation but moves the generator: a suit (``choice`` of 4: ``integers(0, 4)``) and,
for a 10, its face (``choice`` of J, Q, K: ``integers(0, 3)``). A hit draws one card; a
stick draws the dealer's cards while the dealer's sum (an ace counting 11 when that does
not bust) is below 17. The rewards follow ``sab`` and ``natural`` as Gymnasium's ``step``.

A hand is kept as its raw sum (aces as 1), whether it holds an ace and its number of cards:
all that the rules look at (a natural is two cards, an ace and a 10: raw sum 11). The state
is the player's hand, the dealer's hand and the dealer's face-up card; the observation is
``(player sum, dealer card, usable ace)``, a ``Tuple`` of three ``Discrete``.

``params`` are ``(sab, natural)`` as 1.0 or 0.0, read from the environment
``gymnasium.make`` builds (``Blackjack-v1`` is registered with ``sab=True``).
``max_episode_steps`` is the caller's time limit; ``render_mode`` is refused.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.families.tables.twin import read_environment
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined

STATE_SIZE = 7
STATE_DTYPE = np.int64
OBSERVATION_SIZE = 3
OBSERVATION_DTYPE = np.int64
OBSERVATION_KIND = "tuple"
READS_ENVIRONMENT = True
N_ACTIONS = 2
PARAM_NAMES = ("sab", "natural")
"""what ``params`` holds, in order (1.0: true, 0.0: false)"""
SAB, NATURAL = range(2)
REFUSED_KWARGS = ("render_mode",)

# The state: each hand's raw sum (aces as 1), whether it holds an ace, its number of cards.
PLAYER, DEALER = 0, 3
RAW_SUM, HAS_ACE, CARDS = 0, 1, 2
DEALER_CARD = 6
"""the dealer's face-up (first) card"""

DECK = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10, 10)
"""``gymnasium.envs.toy_text.blackjack.deck``"""
SUITS = 4
FACES = 3
"""the pictures of a 10 (J, Q, K)"""

_READ: dict[tuple[str, str], tuple[float, ...] | str] = {}
"""the rules already read, by id and arguments"""


def twin_params(kwargs: Mapping[str, Any], env_id: str) -> tuple[float, ...] | str:
    """Return ``params`` for ``gymnasium.make(env_id, **kwargs)``, or why not.

    Returns:
        ``(sab, natural)``, or a sentence saying why the twin cannot reproduce the
        environment.
    """
    for key in REFUSED_KWARGS:
        if key in kwargs:
            return f"env.kwargs key {key!r} is not reproduced by the compiled twin"
    return read_environment(env_id, kwargs, rules, _READ)


def rules(blackjack: Any) -> tuple[float, ...]:
    """``(sab, natural)`` of an unwrapped ``BlackjackEnv``, as its ``step`` tests them."""
    return (1.0 if blackjack.sab else 0.0, 1.0 if blackjack.natural else 0.0)


@njit(cache=True, nogil=True, inline="always")
def draw_card(rng: np.random.Generator) -> int:
    """``int(np_random.choice(deck))``."""
    return DECK[rng.integers(0, len(DECK))]


@njit(cache=True, nogil=True, inline="always")
def add_card(state: np.ndarray, hand: int, card: int) -> None:
    """Put ``card`` into the hand that starts at index ``hand`` of the state."""
    state[hand + RAW_SUM] += card
    if card == 1:
        state[hand + HAS_ACE] = 1
    state[hand + CARDS] += 1


@njit(cache=True, nogil=True, inline="always")
def hand_sum(state: np.ndarray, hand: int) -> tuple[int, int]:
    """``_hand_sum_and_usable_ace``: the sum, an ace counting 11 when that does not bust."""
    raw = state[hand + RAW_SUM]
    if state[hand + HAS_ACE] != 0 and raw + 10 <= 21:
        return raw + 10, 1
    return raw, 0


@njit(cache=True, nogil=True, inline="always")
def score(state: np.ndarray, hand: int) -> int:
    """``score``: the hand's sum, 0 when it is bust."""
    total, _ = hand_sum(state, hand)
    return 0 if total > 21 else total


@njit(cache=True, nogil=True, inline="always")
def is_natural(state: np.ndarray, hand: int) -> bool:
    """``is_natural``: ``sorted(hand) == [1, 10]``."""
    return state[hand + CARDS] == 2 and state[hand + HAS_ACE] != 0 and state[hand + RAW_SUM] == 11  # type: ignore[no-any-return]


@njit(cache=True, nogil=True, inline="always")
def write_observation(state: np.ndarray, observation: np.ndarray) -> None:
    """``_get_obs``: ``(player sum, dealer's face-up card, usable ace)``."""
    total, usable_ace = hand_sum(state, PLAYER)
    observation[0] = total
    observation[1] = state[DEALER_CARD]
    observation[2] = usable_ace


@njit(cache=True, nogil=True, inline="always")
def reset(
    state: np.ndarray, observation: np.ndarray, rng: np.random.Generator, params: Any
) -> None:
    """Deal the dealer's hand, then the player's; draw the face-up card's picture."""
    state[:] = 0
    first = draw_card(rng)
    add_card(state, DEALER, first)
    add_card(state, DEALER, draw_card(rng))
    add_card(state, PLAYER, draw_card(rng))
    add_card(state, PLAYER, draw_card(rng))
    state[DEALER_CARD] = first
    rng.integers(0, SUITS)  # the face-up card's suit
    if first == 10:
        rng.integers(0, FACES)  # and, for a 10, its face
    write_observation(state, observation)


@njit(cache=True, nogil=True, inline="always")
def step(
    state: np.ndarray,
    action: int,
    observation: np.ndarray,
    rng: np.random.Generator,
    params: Any,
) -> tuple[float, bool]:
    """Hit (1: one card) or stick (0: the dealer plays, the hands are scored).

    Returns:
        The reward and whether the hand ended (a bust, or a stick).
    """
    if action != 0:
        add_card(state, PLAYER, draw_card(rng))
        bust = hand_sum(state, PLAYER)[0] > 21
        write_observation(state, observation)
        return (-1.0 if bust else 0.0), bust
    while hand_sum(state, DEALER)[0] < 17:
        add_card(state, DEALER, draw_card(rng))
    player, dealer = score(state, PLAYER), score(state, DEALER)
    # cmp: float(player > dealer) - float(player < dealer)
    reward = (1.0 if player > dealer else 0.0) - (1.0 if player < dealer else 0.0)
    if params[SAB] != 0.0 and is_natural(state, PLAYER) and not is_natural(state, DEALER):
        reward = 1.0
    elif (
        params[SAB] == 0.0 and params[NATURAL] != 0.0 and is_natural(state, PLAYER)
        and reward == 1.0
    ):  # fmt: skip
        reward = 1.5
    write_observation(state, observation)
    return reward, True
