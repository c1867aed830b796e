"""A count with its noun in the right number: "1 participant", "3 participants" (report and figure texts)."""


def counted(n, noun, plural=None):
    """``n`` and ``noun``, singular for exactly one, else ``plural`` (default: noun + "s")."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"
