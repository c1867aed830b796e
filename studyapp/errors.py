"""Exception types shared by every layer.

A ``UserError`` is bad input from a person (a file, a field, a value). The
command line prints its message as one line and exits with code 2; it never
shows a traceback. Its message names the file, field or value and says what is
allowed.

An ``EngineError`` is not bad input: the real-time engine's worker could not
start or stopped with an error. The command line prints it as one line and
exits with code 1.
"""


class UserError(Exception):
    """Bad input from the user; the message is shown as one line."""


class ParameterError(UserError, ValueError):
    """A parameter out of range or of the wrong kind (names the parameter)."""


class InputDataError(UserError, ValueError):
    """An input file with a missing column, a bad cell or a wrong shape."""


class EngineError(RuntimeError):
    """The engine's worker could not start, or stopped with an error (one line)."""
