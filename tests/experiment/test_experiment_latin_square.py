"""Balanced Latin squares and per-participant schedules."""

import collections
import itertools
from pathlib import Path

import pytest

from studyapp.experiment.latin_square import balanced_latin_square, participant_row, williams_rows
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.schedule import Trial, build_schedule

ROOT = Path(__file__).resolve().parents[2]


def check_balanced(rows, symbols):
    n = len(symbols)
    assert len(rows) == (n if n % 2 == 0 or n == 1 else 2 * n)
    for row in rows:
        assert sorted(row) == sorted(symbols)
    for j in range(n):
        column = collections.Counter(row[j] for row in rows)
        assert set(column) == set(symbols) and len(set(column.values())) == 1
    carry = collections.Counter((row[j], row[j + 1]) for row in rows for j in range(n - 1))
    assert set(carry) == set(itertools.permutations(symbols, 2))
    assert len(set(carry.values())) <= 1


@pytest.mark.parametrize("n", range(1, 11))
def test_williams_rows_are_balanced(n):
    check_balanced(williams_rows(n), list(range(n)))


@pytest.mark.parametrize("conditions", [list("ABCDEFGH"), list("ABCDEFGHI"), list("ABC")])
def test_seeded_square_is_balanced_reproducible_and_seed_dependent(conditions):
    square = balanced_latin_square(conditions, 11)
    check_balanced(square, conditions)
    assert square == balanced_latin_square(conditions, 11)
    assert any(balanced_latin_square(conditions, s) != square for s in range(12, 16))


def test_participants_cycle_through_rows():
    square = balanced_latin_square("ABCD", 3)
    assert [participant_row(square, p) for p in range(4)] == square
    assert participant_row(square, 5) == square[1]
    assert participant_row(square, 1, repetition=2) == square[3]


def test_schedule_of_the_paper_study():
    protocol = load_protocol(ROOT / "protocols" / "sinclair2014.toml")
    steps, squares = build_schedule(protocol, participant_index=4)
    assert [t.step for t in steps] == list(range(len(steps)))
    # the paper's procedure around them: pages, and 1 rating and 2 adjustment practice trials
    assert [t.task for t in steps if t.practice] == ["rating", "adjustment", "adjustment"]
    assert [t.page.kind for t in steps if t.page][:3] == ["welcome", "calibration", "instructions"]
    trials = [t for t in steps if t.phase == "trial"]
    assert len(trials) == 1 + 9 * 6
    rating = trials[0]
    assert rating.task == "rating" and sorted(rating.conditions) == sorted(protocol.task("rating").conditions)
    adjustment = trials[1:]
    counts = collections.Counter((t.condition, t.trial) for t in adjustment)
    assert set(counts.values()) == {1} and len(counts) == 54
    for r in range(6):
        block = [t.condition for t in adjustment[9 * r: 9 * r + 9]]
        assert sorted(block) == sorted(protocol.task("adjustment").conditions) and all(t.trial == r + 1 for t in adjustment[9 * r: 9 * r + 9])
    assert squares["rating"]["rows"] == 8 and squares["adjustment"]["rows"] == 18
    assert squares["adjustment"]["rows_used"] == [4, 5, 6, 7, 8, 9]
    other, _ = build_schedule(protocol, participant_index=5)
    assert next(t for t in other if t.phase == "trial").conditions != rating.conditions
    assert Trial.from_dict(adjustment[3].to_dict()) == adjustment[3]
