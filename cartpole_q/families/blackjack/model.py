"""Blackjack's exact model, from its rules: the input of value iteration.

Blackjack has no transition table, but its rules define one exactly (an infinite deck: each
draw is 1-9 with probability 1/13 each, 10 with 4/13, as Gymnasium's ``draw_card``; the
dealer draws to 17 or more, counting a usable ace as 11). Its model states are the
observations ``(player sum, dealer card, usable ace)`` plus one "natural" start state per
dealer card, which plays as the observation ``(21, card, 1)`` but is paid as a natural.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from cartpole_q.rl.mdp import FiniteMDP

MODEL_KWARGS = (
    "sab", "natural", "render_mode", "max_episode_steps", "player_sum", "usable_ace", "dealer",
)  # fmt: skip
"""what the rules' model covers (the last three: the hand ``BlackjackDealt-v0`` deals)"""
_CARD_PROBABILITIES = {**{card: 1 / 13 for card in range(1, 10)}, 10: 4 / 13}
BLACKJACK_SHAPE = (32, 11, 2)
"""the sizes of Blackjack-v1's observation components (player sum, dealer card, usable ace)"""


def blackjack_row(player_sum: int, dealer_card: int, usable_ace: int) -> int:
    """The Q-table row of a Blackjack observation (C order over :data:`BLACKJACK_SHAPE`)."""
    return (player_sum * BLACKJACK_SHAPE[1] + dealer_card) * BLACKJACK_SHAPE[2] + usable_ace


@cache
def _dealer_outcomes(card: int) -> tuple[tuple[int, bool, float], ...]:
    """The dealer's final ``(score, natural, probability)`` given the face-up card.

    Score 0 is a bust. The dealer draws the hidden card, then hits while the hand's sum
    (an ace counting 11 when that does not bust) is below 17, as Gymnasium's ``step``.
    """
    outcomes: dict[tuple[int, bool], float] = {}

    def play(raw: int, ace: bool, probability: float) -> None:
        total = raw + 10 if ace and raw + 10 <= 21 else raw
        if total < 17:
            for drawn, p in _CARD_PROBABILITIES.items():
                play(raw + drawn, ace or drawn == 1, probability * p)
            return
        key = (0 if total > 21 else total, False)
        outcomes[key] = outcomes.get(key, 0.0) + probability

    for hidden, p in _CARD_PROBABILITIES.items():
        if {card, hidden} == {1, 10}:
            outcomes[(21, True)] = outcomes.get((21, True), 0.0) + p
        else:
            play(card + hidden, card == 1 or hidden == 1, p)
    return tuple((score, natural, p) for (score, natural), p in sorted(outcomes.items()))


def _compare(player: int, dealer: int) -> float:
    return float(player > dealer) - float(player < dealer)


def blackjack_model(sab: bool, natural: bool) -> tuple[FiniteMDP, np.ndarray]:
    """Blackjack-v1's exact model under its ``sab`` and ``natural`` rules.

    Returns:
        The model and, per model state, the Q-table row it plays (see the module's notes).
    """
    n_rows = int(np.prod(BLACKJACK_SHAPE))
    natural_state = {card: n_rows + card - 1 for card in range(1, 11)}
    n_states = n_rows + 10
    transitions: dict[int, dict[int, list[tuple[float, int, float, bool]]]] = {}
    for player_sum in range(BLACKJACK_SHAPE[0]):
        for card in range(BLACKJACK_SHAPE[1]):
            for usable in range(BLACKJACK_SHAPE[2]):
                transitions[blackjack_row(player_sum, card, usable)] = _blackjack_actions(
                    player_sum, card, usable, False, sab, natural
                )
    for card, state in natural_state.items():
        transitions[state] = _blackjack_actions(21, card, 1, True, sab, natural)
    initial = np.zeros(n_states)
    for card, p_card in _CARD_PROBABILITIES.items():
        for first, p_first in _CARD_PROBABILITIES.items():
            for second, p_second in _CARD_PROBABILITIES.items():
                probability = p_card * p_first * p_second
                if {first, second} == {1, 10}:
                    initial[natural_state[card]] += probability
                    continue
                raw, ace = first + second, 1 in (first, second)
                usable = int(ace and raw + 10 <= 21)
                initial[blackjack_row(raw + 10 * usable, card, usable)] += probability
    rows = np.concatenate(
        [np.arange(n_rows), [blackjack_row(21, card, 1) for card in range(1, 11)]]
    )
    model = FiniteMDP.from_transitions(transitions, initial / initial.sum(), n_actions=2)
    return model, rows.astype(np.int64)


def _blackjack_actions(
    player_sum: int, card: int, usable: int, is_natural: bool, sab: bool, natural: bool
) -> dict[int, list[tuple[float, int, float, bool]]]:
    """Outcomes of stick (0) and hit (1) from one state (states never reached included)."""
    if player_sum > 21 or (usable and player_sum < 12) or not 1 <= card <= 10:
        never = [(1.0, 0, 0.0, True)]  # no hand shows this: any outcome will do
        return {0: never, 1: never}
    stick: dict[float, float] = {}
    for dealer, dealer_natural, p in _dealer_outcomes(card):
        reward = _compare(player_sum, dealer)
        if sab and is_natural and not dealer_natural:
            reward = 1.0
        elif not sab and natural and is_natural and reward == 1.0:
            reward = 1.5
        stick[reward] = stick.get(reward, 0.0) + p
    hit: list[tuple[float, int, float, bool]] = []
    raw = player_sum - 10 if usable else player_sum
    for drawn, p in _CARD_PROBABILITIES.items():
        new_raw, ace = raw + drawn, bool(usable) or drawn == 1
        new_usable = int(ace and new_raw + 10 <= 21)
        new_sum = new_raw + 10 * new_usable
        if new_sum > 21 or new_sum >= BLACKJACK_SHAPE[0]:
            hit.append((p, 0, -1.0, True))
        else:
            hit.append((p, blackjack_row(new_sum, card, new_usable), 0.0, False))
    return {0: [(p, 0, reward, True) for reward, p in stick.items()], 1: hit}
