"""Compiled twins of Gymnasium environments, bit-identical to them.

Each module defines ``STATE_SIZE``, ``OBSERVATION_SIZE``, ``N_ACTIONS``, ``ENV_IDS``,
``MAX_EPISODE_STEPS``, the compiled ``reset(state, observation, rng, params)`` and
``step(state, action, observation, params) -> (reward, terminated)``, and the plain function
``twin_params(kwargs)`` that turns ``gymnasium.make`` arguments into ``params`` or says which
one the twin cannot reproduce.
"""
