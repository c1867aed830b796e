"""Numbers written as text by a person (an option, a CSV cell, a ``--set`` value), read strictly.

Python's ``float`` and ``int`` accept digit grouping: ``float("5_000")`` is
5000 and ``float("1_0")`` is 10. No file format or person here means that, and
a ``1_0`` cell read as 10 m is a wrong sample, not a number (issue 21, item 15),
so a text holding ``_`` is refused like any other text that is not a number.
"""


def to_float(text):
    """``float(text)`` for a str (``ValueError`` if it holds an underscore); other values as ``float`` does."""
    if isinstance(text, str) and "_" in text:
        raise ValueError(f"could not convert string to float: {text!r} (write numbers without '_')")
    return float(text)


def shown(value):
    """``value`` as short text that reads back as the same float: ``{:g}`` unless it rounds (96000.0001)."""
    short = f"{value:g}"
    return short if float(short) == value else repr(float(value))


def to_int(text):
    """``int(text)`` for a str (``ValueError`` if it holds an underscore)."""
    if isinstance(text, str) and "_" in text:
        raise ValueError(f"invalid literal for int(): {text!r} (write numbers without '_')")
    return int(text)
