"""Text of the exact figures: ``cartpole-q optimum`` and the lines ``eval`` adds.

>>> exact_lines({"optimum": {"return": 0.7442, "horizon": 100, "discounted": 0.542,
...     "gamma": 0.99}, "note": "success probability, undiscounted, within its time limit of 100 steps",
...     "greedy": {"return": 0.7401, "discounted": 0.538},
...     "gap": {"return": 0.0041, "discounted": 0.004}})
['exact (success probability, undiscounted, within its time limit of 100 steps): greedy 0.7401, optimum 0.7442, gap 0.0041', 'exact, discounted (gamma 0.99, no time limit): greedy 0.538, optimum 0.542, gap 0.004']
"""

from __future__ import annotations

from typing import Any


def exact_lines(exact: dict[str, Any]) -> list[str]:
    """Lines for one table's exact figures (or the optimum alone)."""
    optimum = exact["optimum"]
    greedy, gap = exact.get("greedy"), exact.get("gap")
    if greedy is None or gap is None:
        lines = [f"optimum ({exact['note']}): {optimum['return']:.6g}"]
        if "discounted" in optimum:
            lines.append(
                f"optimum, discounted (gamma {optimum['gamma']:g}, no time limit): "
                f"{optimum['discounted']:.6g}"
            )
        return lines
    lines = [
        f"exact ({exact['note']}): greedy {greedy['return']:.6g}, optimum "
        f"{optimum['return']:.6g}, gap {_gap(gap['return'])}"
    ]
    if "discounted" in greedy:
        lines.append(
            f"exact, discounted (gamma {optimum['gamma']:g}, no time limit): greedy "
            f"{greedy['discounted']:.6g}, optimum {optimum['discounted']:.6g}, gap "
            f"{_gap(gap['discounted'])}"
        )
    return lines


def _gap(value: float) -> str:
    """A gap as text: rounding noise (a greedy value 1e-11 above the optimum) shows as 0.

    >>> _gap(-1.641e-11), _gap(0.0041), _gap(2e-12)
    ('0', '0.0041', '0')
    """
    return "0" if abs(value) < 1e-9 else f"{value:.4g}"


def exact_seeds_line(summary: dict[str, Any]) -> str:
    """One line on a multi-seed run's exact greedy returns against the optimum.

    >>> exact_seeds_line({"note": "expected return, undiscounted, within 200 steps",
    ...     "optimum": 7.93, "greedy_median": 7.93, "greedy_min": 7.5, "gap_max": 0.43,
    ...     "within_0.01": 9, "within_1%": 9, "optimal": 8, "seeds": 10})
    'exact (expected return, undiscounted, within 200 steps): optimum 7.93; greedy median 7.93, lowest 7.5; optimal on 8/10 seeds, within 0.01 on 9/10, within 1% on 9/10'
    """
    seeds = summary["seeds"]
    return (
        f"exact ({summary['note']}): optimum {summary['optimum']:.6g}; greedy median "
        f"{summary['greedy_median']:.6g}, lowest {summary['greedy_min']:.6g}; optimal on "
        f"{summary['optimal']}/{seeds} seeds, within 0.01 on {summary['within_0.01']}/{seeds}, "
        f"within 1% on {summary['within_1%']}/{seeds}"
    )


def policy_grid(
    policy: list[int], rows: int, columns: int, arrows: str, marks: dict[int, str]
) -> str:
    """A grid world's policy as text: one arrow per cell, ``marks`` in place of some cells.

    >>> print(policy_grid([1, 2, 0, 3], 2, 2, "<v>^", {3: "G"}))
    v >
    < G
    """
    lines = []
    for row in range(rows):
        cells = []
        for column in range(columns):
            state = row * columns + column
            cells.append(marks.get(state, arrows[policy[state]]))
        lines.append(" ".join(cells))
    return "\n".join(lines)


def state_label(blackjack: bool, state: int) -> str:
    """A model state as ``optimum --policy`` lists it: its number, Blackjack's in words.

    Blackjack's model states are its table rows (player sum, dealer's card, usable ace, in C
    order over (32, 11, 2)), then one natural 21 per dealer card (704 + card - 1).

    >>> state_label(True, (13 * 11 + 2) * 2 + 1), state_label(True, 704), state_label(False, 7)
    ('13 with a usable ace, dealer 2', 'a natural 21, dealer A', '7')
    """
    if not blackjack:
        return str(state)
    cards = ["A", *map(str, range(2, 11))]
    rows = 32 * 11 * 2
    if state >= rows:
        return f"a natural 21, dealer {cards[state - rows]}"
    player, rest = divmod(state, 11 * 2)
    dealer, usable = divmod(rest, 2)
    ace = "with a usable ace" if usable else "without a usable ace"
    return f"{player} {ace}, dealer {cards[dealer - 1] if dealer else '0'}"
