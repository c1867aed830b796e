"""Seeded balanced Latin squares (Williams designs) for condition order.

A Latin square of n conditions has n rows; each condition appears once in each
row and once in each column (position). It is *balanced* when, in addition,
each condition immediately follows every other condition equally often, so
first-order carry-over effects cancel across participants. Williams (1949):
the first row is 0, 1, n-1, 2, n-2, 3, ...; row i adds i (mod n) to it. For
even n these n rows are balanced; for odd n the n rows plus their n reversals
(2n rows) are.

The seed relabels the conditions (a random permutation of the symbols) and
shuffles the rows; both keep the square balanced, so different studies get
different, equally balanced squares. Participant p (the p-th to enrol, from 0)
gets row p mod (number of rows): a whole number of cycles of participants sees
every order position and every carry-over equally often.

In the rating task the row is the knob assignment (knob j plays condition
row[j]). In the adjustment task, repetition r of the conditions follows row
p + r, so the order also changes from one repetition to the next.
"""

import zlib

import numpy as np


def williams_rows(n):
    """The balanced Latin square of symbols 0..n-1 as a list of rows (n rows, or 2n for odd n)."""
    if n < 1:
        raise ValueError(f"n = {n}: a Latin square needs at least one condition")
    first = [0] + [(j + 1) // 2 if j % 2 == 1 else n - j // 2 for j in range(1, n)]
    rows = [[(s + i) % n for s in first] for i in range(n)]
    if n % 2 == 1 and n > 1:
        rows += [row[::-1] for row in rows]
    return rows


def task_seed(seed, task):
    """The seed of one task's square: the study seed mixed with the task's name."""
    return [int(seed), zlib.crc32(task.encode("utf-8"))]


def balanced_latin_square(conditions, seed):
    """Rows of condition names: a Williams square with seeded relabelling and row order."""
    conditions = list(conditions)
    rng = np.random.default_rng(seed)
    labels = [conditions[i] for i in rng.permutation(len(conditions))]
    rows = williams_rows(len(conditions))
    order = rng.permutation(len(rows))
    return [[labels[s] for s in rows[i]] for i in order]


def participant_row(square, participant_index, repetition=0):
    """The row of the ``participant_index``-th participant (from 0) for ``repetition`` (from 0)."""
    return list(square[(participant_index + repetition) % len(square)])
