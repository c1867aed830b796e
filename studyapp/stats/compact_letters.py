"""Compact letter display: the significance marks drawn over the box plots of Figs. 7-8.

With nine conditions there are 36 pairs; brackets for each would bury the
boxes. A compact letter display gives every condition a few letters such that
two conditions share a letter exactly when the test could not tell them apart
(p >= alpha), the usual way to mark pairwise tests on box plots.

Insert-absorb algorithm (Piepho, J. Comput. Graph. Stat. 13(2), 2004): start
from one letter covering every condition; for each significant pair (i, j),
split every letter that covers both into one without i and one without j; then
drop every letter whose conditions are all covered by another letter. Letters
are named a, b, c, ... in the order of the first condition they cover, so with
conditions ordered best first, "a" marks the best group.
"""

import string

_NAMES = string.ascii_lowercase + string.ascii_uppercase


def compact_letters(conditions, significant_pairs):
    """{condition: letters} for ``conditions`` (ordered) and the set of significantly different pairs."""
    conditions = list(conditions)
    columns = [frozenset(conditions)] if conditions else []
    for a, b in significant_pairs:
        split = []
        for column in columns:
            if a in column and b in column:
                split.extend([column - {b}, column - {a}])
            else:
                split.append(column)
        columns = _absorb(split)
    position = {name: k for k, name in enumerate(conditions)}
    columns.sort(key=lambda column: sorted(position[c] for c in column))
    # Letters are appended in column order, so each label comes out sorted.
    labels = {name: "" for name in conditions}
    for k, column in enumerate(columns):
        letter = _NAMES[k] if k < len(_NAMES) else f"<{k + 1}>"
        for name in column:
            labels[name] += letter
    return labels


def _absorb(columns):
    """Unique columns that are not a proper subset of another column."""
    unique = list(dict.fromkeys(columns))
    return [c for c in unique if not any(c < other for other in unique)]
