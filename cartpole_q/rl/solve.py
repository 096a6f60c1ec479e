"""The solve rule's window (no numba here, so figures can import it cheaply).

Episode ``e`` solves a run when ``e >= 99`` and the mean of returns ``e - 99 .. e``
(summed left to right from 0.0) reaches the threshold.
"""

SOLVE_WINDOW = 100
"""episodes in the moving average of training returns compared with the reward threshold"""
