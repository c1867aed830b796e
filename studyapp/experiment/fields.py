"""The fields of one TOML table of a protocol, read with checks: each problem is one line naming file and field.

``Fields(source, table, values)`` wraps the table's dict; its readers
(``string``, ``integer``, ``number``, ``conditions``, ``get``) return a field's
value or raise ``UserError``: "<file>: [<table>] <field> = <value>: allowed is
<what>". ``finish()`` refuses a field no reader asked for (a typo must not be
silently ignored). The protocol (protocol.py), its pages (pages.py) and every
task type's ``parse`` (task_type.py) read their tables through it.
"""

from studyapp.errors import UserError


class Fields:
    """Reads one TOML table, turning each problem into one line naming file and field."""

    def __init__(self, source, table, values, label=None):
        self.source = source
        self.table = table
        self.label = label or f"[{table}]"  # how messages name it, e.g. "[[pages]] #2"
        self.values = values
        self.used = set()

    def fail(self, key, problem, allowed):
        where = f"{self.label} {key}" if key else self.label
        raise UserError(f"{self.source}: {where} {problem}: allowed is {allowed}")

    def get(self, key, allowed, default=...):
        self.used.add(key)
        if key not in self.values:
            if default is ...:
                self.fail(key, "is missing", allowed)
            return default
        return self.values[key]

    def string(self, key, allowed="a non-empty string", default=..., pattern=None):
        value = self.get(key, allowed, default)
        if not isinstance(value, str) or not value.strip() or (pattern and not pattern.fullmatch(value)):
            self.fail(key, f"= {value!r}", allowed)
        return value

    def integer(self, key, low, high, default=...):
        allowed = f"an integer from {low} to {high}"
        value = self.get(key, allowed, default)
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            self.fail(key, f"= {value!r}", allowed)
        return value

    def number(self, key, low, high, unit="", default=..., low_open=False):
        """A finite number in [low, high] (``low_open``: above ``low``); NaN and infinities fail the test."""
        lower = f"above {low:g} and up" if low_open else f"from {low:g}"
        allowed = f"a number {lower} to {high:g} {unit}".strip()
        value = self.get(key, allowed, default)
        bad = isinstance(value, bool) or not isinstance(value, (int, float))
        if not bad:
            value = float(value)
            bad = not ((low < value if low_open else low <= value) and value <= high)
        if bad:
            self.fail(key, f"= {value!r}", allowed)
        return value

    def conditions(self, key, known, at_least, at_most):
        allowed = (f"a list of {at_least} to {at_most} different estimator names from: {', '.join(known)}")
        value = self.get(key, allowed)
        if (not isinstance(value, list) or not at_least <= len(value) <= at_most
                or not all(isinstance(name, str) for name in value)):
            self.fail(key, f"= {value!r}", allowed)
        for name in value:
            if name not in known:
                self.fail(key, f"has unknown condition {name!r}", allowed)
        if len(set(value)) != len(value):
            self.fail(key, "names a condition twice", allowed)
        return tuple(value)

    def finish(self):
        unknown = sorted(set(self.values) - self.used)
        if unknown:
            self.fail(unknown[0], "is not a known field", "one of " + ", ".join(sorted(self.used)))


def table_fields(source, document, name, required=True):
    """The ``Fields`` of table ``name`` of the TOML ``document``; None if it is absent and not ``required``."""
    if name not in document:
        if required:
            raise UserError(f"{source}: table [{name}] is missing: allowed is a [{name}] table (see docs/experiment.md)")
        return None
    value = document[name]
    if not isinstance(value, dict):
        raise UserError(f"{source}: [{name}] = {value!r}: allowed is a table")
    return Fields(source, name, value)
