"""The error family the command line reports as bad input (exit code 2).

Kept in its own tiny module so that the command line can catch it without importing
numpy, numba or gymnasium.
"""


class UserError(ValueError):
    """Bad input: a config, a path or a run directory that cannot be used.

    The message is one paragraph naming the file and the field; the command line prints
    it without a traceback and exits with code 2.
    """


class ConfigError(UserError):
    """A configuration that cannot be used.

    The message is one paragraph that names the source (file or command line) and the
    field, so the command line can print it as is and exit with code 2.
    """


class RunError(UserError):
    """A run directory, or a file in it, that cannot be used; the message names it."""


class WriteError(RunError):
    """A file that cannot be written (full disk, no permission, ...); the message names it."""
