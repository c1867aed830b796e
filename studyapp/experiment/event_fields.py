"""Checks of single fields of a logged event, shared by the response check and the task types."""

import math


def integer(value, low):
    """An int (not a bool) >= ``low``."""
    return isinstance(value, int) and not isinstance(value, bool) and value >= low


def number(value):
    """A finite int or float (not a bool) >= 0."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0


def text(value):
    """A non-blank string."""
    return isinstance(value, str) and value.strip() != ""
