"""JSON read with its nesting bounded before it is parsed: ``loads(text)``.

``json.loads`` recurses once per level of nesting, so a line of 100 000 ``[``
(a damaged or hostile events.jsonl line, a session.json, a recording's
metadata) ends in ``RecursionError``, a traceback, not a message. Nothing the
app writes is nested more than a few levels, so text nested deeper than
``MAX_DEPTH`` is refused before ``json.loads`` sees it.

The depth is found by a cheap scan: the brackets ``[ {`` open a level and
``] }`` close one, outside strings (a string is ``"`` to the next unescaped
``"``). Text with at most ``MAX_DEPTH`` opening brackets cannot be deeper, so
the usual line is passed on after one count; only the rest are scanned.
Unbalanced brackets are left to ``json.loads`` to refuse.
"""

import json
import re

MAX_DEPTH = 64  # levels: session.json and events nest 4 at most; Python's recursion limit is 1000
_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)
_BRACKET = re.compile(r"[\[\]{}]")


class NestedTooDeeply(ValueError):
    """The JSON text nests deeper than ``MAX_DEPTH`` (a ``ValueError``, as ``json.loads``'s own errors are)."""


def nesting_depth(text):
    """The deepest nesting of brackets in the JSON ``text`` (str), strings left out."""
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return text.count("[") + text.count("{")  # an upper bound, enough to pass
    depth = deepest = 0
    for bracket in _BRACKET.findall(_STRING.sub("", text)):
        depth += 1 if bracket in "[{" else -1
        deepest = max(deepest, depth)
    return deepest


def loads(text):
    """``json.loads(text)``, ``NestedTooDeeply`` for text nested deeper than ``MAX_DEPTH``."""
    if isinstance(text, (bytes, bytearray)):
        text = text.decode("utf-8")
    if nesting_depth(text) > MAX_DEPTH:
        raise NestedTooDeeply(f"JSON nested more than {MAX_DEPTH} levels deep")
    try:
        return json.loads(text)
    except RecursionError:  # only where the recursion limit is set below MAX_DEPTH
        raise NestedTooDeeply(f"JSON nested more than {MAX_DEPTH} levels deep") from None
