"""docs/breakdown.md's tables hold for the code, within what one rounding moves them (issues 30 item 7, 39).

Each table is headed by "Generated on DATE by `studyapp breakdown ...`"; the
command's settings (rate, gesture, duration) and the table's ``seeds_used``
column say how to redo a row. The summaries (median, min, max) are checked
against the quoted per-seed values.

A few rows are redone on their first seed (a search of 11 trials, or 1 where
the quoted value is the search's bottom: the smallest run that keeps the
table's promise; every seed of every table is ``make figures CHECK=1``) and
held to the quoted value within ``tol``. (Two trials, stable just below and
broken just above, would be cheaper but assume the verdict monotonic in
F_max near the edge: at 48 kHz LVT on seed 0 is broken at 10.5 N and stable
at 11.0 N.) ``tol`` is the search's own precision, sqrt(1.02) - 1
(about 1 %: it returns the geometric middle of a bracket at most 1.02 wide,
which also covers the table's three significant figures), plus the largest
move of one seed's F_max under one rounding step of the initial
state, over the table's sources and seeds 0-9, as docs/reproducibility.md
("Sensitivity to one rounding") measured it on 2026-11-28 with
``PYTHONPATH=. python scripts/sensitivity.py -o OUT --parts breakdown --seeds 10
--tables strokes,hold`` (and ``--tables strokes-48k --sources LVT``). The
loop amplifies one rounding (another BLAS, libm or CPU gives one) into a
few per cent of one seed's breakdown, so a tighter test would hold one
machine's last bits, not the model. The spreads and the tables' parser are
scripts/quoted_figures.py's (``BREAKDOWN_ROUNDING``). The full searches on every quoted seed
are ``make figures CHECK=1`` (scripts/regenerate_figures.py --check).
"""

import datetime
import math
import statistics
import sys
from pathlib import Path

import pytest

from studyapp.model import breakdown

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "breakdown.md"
sys.path.insert(0, str(ROOT / "scripts"))
from quoted_figures import (  # noqa: E402
    breakdown_settings as settings, breakdown_tables as tables, breakdown_tolerance, number, within)

# (gesture, rate, windows) -> the sources checked on the table's first seed
REDONE = {("strokes", 5000.0, "seconds"): ("TRUE", "LVT", "LOWPASS", "KALLEV"),
          ("strokes", 48000.0, "seconds"): ("LVT",),
          ("strokes", 48000.0, "samples"): ("FOAW",),
          ("hold", 5000.0, "seconds"): ("LVT", "KALPOS")}
TABLES = list(REDONE)  # the tables docs/breakdown.md holds, in its order (issue 30: bowing at 5 and 48 kHz)


def seeds_of(row, args):
    """The row's seeds: its ``seeds_used`` or, in a table made before that column, the command's."""
    if "seeds_used" in row:
        return [int(s) for s in row["seeds_used"].split(";")]
    return list(range(args.first_seed, args.first_seed + args.seeds))


def key(args):
    return args.gesture, args.rate, args.windows


def quoted():
    return tables(DOC.read_text())


def test_every_table_is_dated_and_complete():
    found = quoted()
    assert [key(settings(command)) for _, command, _ in found] == TABLES
    for date, command, rows in found:
        args = settings(command)
        assert datetime.date.fromisoformat(date) <= datetime.date.today()
        assert [r["source"] for r in rows] == breakdown.sources()
        for r in rows:
            values = [number(v) for v in r["fmax_per_seed"].split(";")]
            seeds = seeds_of(r, args)
            assert seeds == list(range(args.first_seed, args.first_seed + args.seeds)) and len(values) == len(seeds)
            assert (float(r["rate"]), r["gesture"], int(r["seeds"])) == (args.rate, args.gesture, args.seeds)
            assert r.get("windows", "seconds") == args.windows
            assert int(r.get("first_seed", 0)) == args.first_seed
            # the summaries were rounded from the unrounded values: within rounding of the rounded ones
            assert number(r["fmax_min"]) == min(values) and number(r["fmax_max"]) == max(values)
            assert number(r["fmax_median"]) == pytest.approx(statistics.median(values), rel=0.005)


def test_the_parser_reads_a_table_and_its_command():
    text = ("Generated on 2026-11-27 by `studyapp breakdown --all --seeds 2 --first-seed 3 -o b.md`.\n\nprose\n\n"
            "| source | fmax_per_seed | seeds_used |\n| --- | --- | --- |\n| LVT | 8.29; > 200 | 3; 4 |\n\nafter\n")
    ((date, command, rows),) = tables(text)
    args = settings(command)
    assert (date, args.seeds, args.first_seed, args.gesture, args.rate) == ("2026-11-27", 2, 3, "strokes", 5000.0)
    assert rows == [{"source": "LVT", "fmax_per_seed": "8.29; > 200", "seeds_used": "3; 4"}]
    assert [number(v) for v in rows[0]["fmax_per_seed"].split(";")] == [8.29, math.inf]


def redo_cases():
    cases = []
    for _, command, rows in quoted():
        args = settings(command)
        by_source = {r["source"]: r for r in rows}
        for source in REDONE[key(args)]:
            r = by_source[source]
            seed, value = seeds_of(r, args)[0], r["fmax_per_seed"].split(";")[0]
            cases.append(pytest.param(source, args, int(seed), number(value),
                                      id=f"{args.gesture}-{args.rate:g}-{args.windows}-{source}-seed{seed}"))
    return cases


@pytest.mark.slow
@pytest.mark.parametrize("source, args, seed, value", redo_cases())
def test_a_quoted_row_holds_on_its_seed(source, args, seed, value):
    again = breakdown.breakdown_fmax(source, rate=args.rate, gesture=args.gesture, duration=args.duration, seed=seed,
                                     windows=args.windows)
    assert within(again, value, breakdown_tolerance(args.gesture, args.rate)), (source, seed, again, value)
