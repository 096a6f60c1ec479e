"""Blackjack dealt one hand, or a random state, every episode (Sutton & Barto chapter 5).

``cartpole_q/BlackjackDealt-v0`` is Gymnasium's ``Blackjack-v1`` (the book's rules,
``sab=True``) whose every episode starts from one state: the player holds ``player_sum``
(with a usable ace or not) and the dealer shows ``dealer``; the dealer's hidden card is
drawn as Gymnasium draws a card (``np_random.choice`` of the deck). Everything after the deal
is ``BlackjackEnv.step``'s. The book evaluates this state's value under the policy that
sticks on 20 or 21 from a random policy's play (off-policy, Figure 5.3): its prediction runs
measure the error on the dealt state alone (:attr:`measured_states`).

The player's two cards: an ace and ``player_sum - 11`` with a usable ace (12 to 21), else
two cards summing to ``player_sum`` without an ace (4 to 20: a 10 and the rest above 12).

``cartpole_q/BlackjackES-v0`` (:class:`BlackjackExploringStartsEnv`) deals every episode a
uniformly random one of the 200 states of player sum 12-21, dealer's card and usable ace:
the exploring starts of Monte Carlo ES (``agent.algorithm: monte_carlo_es``, which also
takes a uniformly random first action), whose greedy policy the book draws in Figure 5.2.
"""

from __future__ import annotations

from typing import Any

from gymnasium.envs.toy_text.blackjack import BlackjackEnv, draw_card


class BlackjackDealtEnv(BlackjackEnv):
    """Blackjack whose every episode is dealt ``player_sum`` (``usable_ace``) against ``dealer``.

    Args:
        player_sum: the player's sum (12-21 with a usable ace, 4-20 without).
        usable_ace: whether the player's ace counts 11.
        dealer: the dealer's face-up card (1 for an ace, to 10).
        sab: Sutton & Barto's rules (``Blackjack-v1``'s registration, the default).
        natural: a natural pays 1.5 (ignored with ``sab``).
    """

    def __init__(
        self, player_sum: int = 13, usable_ace: bool = True, dealer: int = 2,
        sab: bool = True, natural: bool = False, render_mode: str | None = None,
    ) -> None:  # fmt: skip
        if usable_ace and not 12 <= player_sum <= 21:
            raise ValueError(f"a sum with a usable ace is 12 to 21, got {player_sum}")
        if not usable_ace and not 4 <= player_sum <= 20:
            raise ValueError(f"a two-card sum without a usable ace is 4 to 20, got {player_sum}")
        if not 1 <= dealer <= 10:
            raise ValueError(f"the dealer's card is 1 (an ace) to 10, got {dealer}")
        super().__init__(render_mode=render_mode, natural=natural, sab=sab)
        self.dealt = (int(player_sum), bool(usable_ace), int(dealer))
        if usable_ace:
            self.hand = [1, player_sum - 11]
        else:
            low = max(2, player_sum - 10)
            self.hand = [low, player_sum - low]
        # The table row of (player sum, dealer card, usable ace), C order over (32, 11, 2).
        self.measured_states = ((player_sum * 11 + dealer) * 2 + int(usable_ace),)
        """the model states a prediction run's error is measured on: the dealt one"""

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[tuple[int, int, int], dict[str, Any]]:
        """Deal the hand: the dealer's face-up card, then one card drawn, the player's two."""
        super(BlackjackEnv, self).reset(seed=seed)
        self.dealer = [self.dealt[2], int(draw_card(self.np_random))]  # type: ignore[no-untyped-call]
        self.player = list(self.hand)
        # The face-up card's picture (rendering only): no draw, unlike Blackjack-v1's.
        self.dealer_top_card_suit = "S"
        card = self.dealt[2]
        self.dealer_top_card_value_str = "A" if card == 1 else "K" if card == 10 else str(card)
        return self._get_obs(), {}  # type: ignore[no-untyped-call]


ES_PLAYER_SUMS = range(12, 22)
"""the player sums an exploring start deals (below 12 a hit cannot bust: no decision)"""
ES_DEALER_CARDS = range(1, 11)
"""the dealer's face-up cards (1 an ace)"""


def exploring_hand(player_sum: int, usable_ace: bool) -> list[int]:
    """The player's cards of an exploring start: ``player_sum``, with a usable ace or not.

    With a usable ace an ace and ``player_sum - 11``, without a 10 and ``player_sum - 10``;
    a 21 takes three cards (an ace and two 5s, or a 10, a 5 and a 6), never a natural.

    >>> exploring_hand(12, True), exploring_hand(21, True), exploring_hand(20, False)
    ([1, 1], [1, 5, 5], [10, 10])
    >>> exploring_hand(21, False)
    [10, 5, 6]
    """
    if player_sum == 21:
        return [1, 5, 5] if usable_ace else [10, 5, 6]
    return [1, player_sum - 11] if usable_ace else [10, player_sum - 10]


class BlackjackExploringStartsEnv(BlackjackEnv):
    """Blackjack whose every episode starts in a uniformly random one of 200 states (ES).

    Sutton & Barto's Monte Carlo ES (section 5.3, Example 5.3, Figure 5.2) starts each
    episode from a random state: a player sum 12-21, the dealer's face-up card 1-10 (an ace
    is 1), a usable ace or not, each of the 200 equally likely. ``reset`` draws, from
    ``np_random`` in this order: the player sum ``12 + np_random.integers(0, 10)``, the
    dealer's card ``1 + np_random.integers(0, 10)``, the usable ace
    ``np_random.integers(0, 2)`` (1: usable), then the dealer's hidden card as Gymnasium
    draws a card (``np_random.choice`` of the deck: ``integers(0, 13)``); nothing else (no
    picture of the face-up card). The player's cards: :func:`exploring_hand` (never a
    natural). Everything after the deal is ``BlackjackEnv.step``'s, under ``sab`` and
    ``natural`` (which change nothing here: they pay only a player's natural).

    Args:
        sab: Sutton & Barto's rules (the default, as ``Blackjack-v1``'s registration).
        natural: a natural pays 1.5 (ignored with ``sab``).
    """

    def __init__(
        self, sab: bool = True, natural: bool = False, render_mode: str | None = None
    ) -> None:
        super().__init__(render_mode=render_mode, natural=natural, sab=sab)
        # The table rows of (player sum, dealer card, usable ace), C order over (32, 11, 2).
        self.measured_states = tuple(
            (player_sum * 11 + dealer) * 2 + usable
            for player_sum in ES_PLAYER_SUMS
            for dealer in ES_DEALER_CARDS
            for usable in (0, 1)
        )
        """the 200 states an episode starts in, equally likely (the model's start
        distribution), and those a prediction run's error is measured on"""

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[tuple[int, int, int], dict[str, Any]]:
        """Draw the state (sum, dealer's card, usable ace), then the dealer's hidden card."""
        super(BlackjackEnv, self).reset(seed=seed)
        player_sum = ES_PLAYER_SUMS[0] + int(self.np_random.integers(0, len(ES_PLAYER_SUMS)))
        card = ES_DEALER_CARDS[0] + int(self.np_random.integers(0, len(ES_DEALER_CARDS)))
        usable_ace = int(self.np_random.integers(0, 2)) == 1
        self.dealer = [card, int(draw_card(self.np_random))]  # type: ignore[no-untyped-call]
        self.player = exploring_hand(player_sum, usable_ace)
        # The face-up card's picture (rendering only): no draw, unlike Blackjack-v1's.
        self.dealer_top_card_suit = "S"
        self.dealer_top_card_value_str = "A" if card == 1 else "K" if card == 10 else str(card)
        return self._get_obs(), {}  # type: ignore[no-untyped-call]
