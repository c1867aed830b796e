"""Medians and quartiles by hand, and the compact letters that mark the box plots."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studyapp.stats.compact_letters import compact_letters
from studyapp.analysis.summary import SUMMARY_COLUMNS, summarise


def test_summary_by_hand():
    table = summarise({"B": np.array([4.0, 1.0, 3.0, 2.0]), "A": np.array([5.0])})
    assert list(table.columns) == SUMMARY_COLUMNS
    assert list(table["condition"]) == ["B", "A"]  # order kept (best first is the caller's)
    # Linear interpolation (type 7): positions 0.75, 1.5, 2.25 of 1, 2, 3, 4.
    assert table.iloc[0][["n", "median", "q1", "q3"]].tolist() == pytest.approx([4, 2.5, 1.75, 3.25])
    assert table.iloc[1][["n", "median", "q1", "q3"]].tolist() == pytest.approx([1, 5, 5, 5])


def test_letters_by_hand():
    assert compact_letters("ABC", []) == {"A": "a", "B": "a", "C": "a"}
    assert compact_letters("ABC", [("A", "C")]) == {"A": "a", "B": "ab", "C": "b"}
    assert compact_letters("ABC", [("A", "B"), ("A", "C"), ("B", "C")]) == {"A": "a", "B": "b", "C": "c"}
    # A differs from C and D; B from D: groups {A, B}, {B, C}, {C, D}.
    assert compact_letters("ABCD", [("A", "C"), ("A", "D"), ("B", "D")]) == {"A": "a", "B": "ab", "C": "bc", "D": "c"}


@settings(max_examples=60, deadline=None)
@given(st.lists(st.booleans(), min_size=15, max_size=15))
def test_letters_shared_exactly_when_not_significant(flags):
    names = list("ABCDEF")
    pairs = list(itertools.combinations(names, 2))
    significant = [pair for pair, flag in zip(pairs, flags) if flag]
    letters = compact_letters(names, significant)
    for a, b in pairs:
        share = bool(set(letters[a]) & set(letters[b]))
        assert share == ((a, b) not in significant)
