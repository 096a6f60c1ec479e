"""Blackjack dealt one hand every episode (Sutton & Barto Example 5.4, Figure 5.3).

``cartpole_q/BlackjackDealt-v0`` is Gymnasium's ``Blackjack-v1`` (the book's rules,
``sab=True``) whose every episode starts from one state: the player holds ``player_sum``
(with a usable ace or not) and the dealer shows ``dealer``; the dealer's hidden card is
drawn as Gymnasium draws a card (``np_random.choice`` of the deck). Everything after the deal
is ``BlackjackEnv.step``'s. The book evaluates this state's value under the policy that
sticks on 20 or 21 from a random policy's play (off-policy, Figure 5.3): its prediction runs
measure the error on the dealt state alone (:attr:`measured_states`).

The player's two cards: an ace and ``player_sum - 11`` with a usable ace (12 to 21), else
two cards summing to ``player_sum`` without an ace (4 to 20: a 10 and the rest above 12).
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
