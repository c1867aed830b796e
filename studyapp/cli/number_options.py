"""Numbers on the command line: finite floats and non-negative seeds, for every command at once.

argparse's ``float`` takes ``nan`` and ``inf``, and ``int`` takes ``-1``; no
option of ours means anything by them (an open-ended option is left out
instead). The command line's parser (``studyapp.cli.Parser``) reads every
``type=float`` option with ``finite_float`` and every ``type=int`` one with
``integer``, on every sub-command; a ``--seed`` says ``type=seed`` (0 to 2**63 - 1).
Both also take ``5_000`` (Python's digit grouping), which is refused too
(``studyapp.number_text``).
The error then goes through argparse, naming the option:
``argument --max-lag: 'nan' is not a finite number``.
"""

import argparse
import math

from studyapp.number_text import to_float, to_int

SEED_MAX = 2**63 - 1  # numpy's generators take any non-negative integer; run stores seeds as int64


def finite_float(text):
    try:
        value = to_float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid float value: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def integer(text):
    try:
        return to_int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None


def seed(text):
    try:
        value = to_int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
    if not 0 <= value <= SEED_MAX:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed is an integer from 0 to 2**63 - 1")
    return value
