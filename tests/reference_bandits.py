"""An independent re-derivation of the bandit contract (docs/algorithms.md, "Bandits").

Written from the text alone: plain Python (lists of floats, ``math``) with NumPy only for
the generators; it imports nothing from ``cartpole_q`` and plays its own testbed from the
environment's stated draws. ``tests/test_bandits.py`` checks that both engines of the package
give its rewards and optimal flags byte for byte, for every rule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Learner:
    """A study curve's method and parameters, as the study file names them."""

    method: str  # epsilon_greedy | ucb | gradient
    epsilon: float = 0.0
    c: float = 0.0
    alpha: float = 0.0  # 0: sample averages
    q_init: float = 0.0
    baseline: bool = False


def _largest_at_random(scores: list[float], rng: np.random.Generator) -> int:
    best = max(scores)
    tied = [arm for arm, score in enumerate(scores) if score == best]
    if len(tied) == 1:
        return tied[0]
    return tied[int(rng.integers(0, len(tied)))]


def reference_run(
    learner: Learner, seed: int, steps: int, k: int = 10, mean: float = 0.0,
    spread: float = 1.0, walk: float = 0.0,
) -> tuple[list[float], list[bool]]:  # fmt: skip
    """One run: each step's reward and whether the arm played was optimal."""
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    env_seed = int(env_seq.generate_state(1, dtype=np.uint32)[0])
    env_rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(env_seed)))
    q_star = [float(env_rng.normal(mean, spread)) for _ in range(k)]
    values = [learner.q_init] * k
    counts = [0] * k
    preferences = [0.0] * k
    average = 0.0
    rewards, optimal = [], []
    for t in range(1, steps + 1):
        probabilities: list[float] = []
        if learner.method == "epsilon_greedy":
            epsilon = learner.epsilon
            if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
                arm = int(rng.integers(0, k))
            else:
                arm = _largest_at_random(values, rng)
        elif learner.method == "ucb":
            untried = [a for a in range(k) if counts[a] == 0]
            if len(untried) == 1:
                arm = untried[0]
            elif untried:
                arm = untried[int(rng.integers(0, len(untried)))]
            else:
                log_t = math.log(float(t))
                scores = [values[a] + learner.c * math.sqrt(log_t / counts[a]) for a in range(k)]
                arm = _largest_at_random(scores, rng)
        else:
            top = max(preferences)
            exps = [math.exp(h - top) for h in preferences]
            total = 0.0
            for e in exps:
                total += e
            probabilities = [e / total for e in exps]
            u = rng.random()
            running, arm = 0.0, k - 1
            for a in range(k - 1):
                running += probabilities[a]
                if u < running:
                    arm = a
                    break
        # the testbed
        optimal.append(q_star[arm] == max(q_star))
        reward = float(env_rng.normal(q_star[arm], 1.0))
        if walk > 0.0:
            for a in range(k):
                q_star[a] += float(env_rng.normal(0.0, walk))
        rewards.append(reward)
        # learning
        counts[arm] += 1
        average += (reward - average) / t
        if learner.method == "gradient":
            b = average if learner.baseline else 0.0
            g = learner.alpha * (reward - b)
            for a in range(k):
                if a == arm:
                    preferences[a] += g * (1.0 - probabilities[a])
                else:
                    preferences[a] -= g * probabilities[a]
        elif learner.alpha > 0.0:
            values[arm] += learner.alpha * (reward - values[arm])
        else:
            values[arm] += (reward - values[arm]) / counts[arm]
    return rewards, optimal
