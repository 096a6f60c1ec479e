"""The reinforcement-learning core: pure functions, most of them compiled with numba.

- :mod:`~cartpole_q.rl.binning`: the binning rule (plain Python, no numba);
- :mod:`~cartpole_q.rl.schedules`: learning and exploration rates per episode;
- :mod:`~cartpole_q.rl.policy`: greedy and epsilon-greedy choices;
- :mod:`~cartpole_q.rl.algorithms`: Q-learning, SARSA, Expected SARSA, Double Q-learning.
"""
