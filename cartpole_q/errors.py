"""The one error family the command line reports as bad input (exit code 2).

Kept in its own tiny module so that the command line can catch it without importing
numpy, numba or gymnasium.
"""


class UserError(ValueError):
    """Bad input: a config, a path or a run directory that cannot be used.

    The message is one paragraph naming the file and the field; the command line prints
    it without a traceback and exits with code 2.
    """
