"""Figures 8.7 and 8.8 re-derived from docs/algorithms.md ("Planning updates") alone.

Imports nothing from cartpole_q: plain Python floats and lists, NumPy only for the
generators. ``tests/test_planning_updates.py`` checks the package against it, byte for byte.
"""

from __future__ import annotations

import math

import numpy as np


def rms_curve(seeds: list[int], b: int, initial_error: float = 1.0) -> list[float]:
    """Figure 8.7: the sample updates' RMS error after t = 0 .. 2b computations."""
    per_problem = []
    for seed in seeds:
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, b])))
        successors = [float(v) for v in rng.standard_normal(b)]
        picks = [int(j) for j in rng.integers(0, b, size=2 * b)]
        total = 0.0
        for v in successors:
            total += v
        true_value = total / b
        estimate = true_value + initial_error
        errors = [initial_error]
        for t in range(1, 2 * b + 1):
            estimate = estimate + (1.0 / t) * (successors[picks[t - 1]] - estimate)
            errors.append(estimate - true_value)
        per_problem.append(errors)
    curve = []
    for t in range(2 * b + 1):
        squares = 0.0
        for errors in per_problem:
            squares += errors[t] * errors[t]
        curve.append(math.sqrt(squares / len(seeds)))
    return curve


def start_values(
    seed: int, n: int, actions: int, b: int, updates: int, every: int, termination: float,
    epsilon: float, tolerance: float, on_policy: bool,
) -> list[float]:  # fmt: skip
    """Figure 8.8: one task's start-state greedy values after 0, every, 2 every, ... updates."""
    task_seq, run_seq = np.random.SeedSequence(seed).spawn(2)
    task = np.random.Generator(np.random.PCG64(task_seq))
    successor = task.integers(0, n, size=(n, actions, b)).tolist()
    reward = task.standard_normal((n, actions, b)).tolist()
    rng = np.random.Generator(np.random.PCG64(run_seq))
    go_on = 1.0 - termination
    q = [[0.0] * actions for _ in range(n)]
    v = [0.0] * n

    def best(s: int) -> int:
        a_best = 0
        for a in range(1, actions):
            if q[s][a] > q[s][a_best]:
                a_best = a
        return a_best

    def update(s: int, a: int) -> None:
        total = 0.0
        for j in range(b):
            s2 = successor[s][a][j]
            total += reward[s][a][j] + q[s2][best(s2)]
        q[s][a] = go_on * (total / b)

    def evaluate() -> float:
        nonlocal v
        pi = [best(s) for s in range(n)]
        while True:
            new = []
            for s in range(n):
                total = 0.0
                for j in range(b):
                    total += reward[s][pi[s]][j] + v[successor[s][pi[s]][j]]
                new.append(go_on * (total / b))
            largest = max(abs(new[s] - v[s]) for s in range(n))
            v = new
            if largest < tolerance:
                return v[0]

    curve = [evaluate()]
    s = 0
    for k in range(1, updates + 1):
        if on_policy:
            a = int(rng.integers(0, actions)) if rng.random() < epsilon else best(s)
            update(s, a)
            s = 0 if rng.random() < termination else successor[s][a][int(rng.integers(0, b))]
        else:
            pair = (k - 1) % (n * actions)
            update(pair // actions, pair % actions)
        if k % every == 0:
            curve.append(evaluate())
    return curve
