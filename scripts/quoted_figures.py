"""The figures docs/ quotes, read from docs/, and how far one rounding may move them (issue 39, item 2).

One owner for what the quoted-figure tests (tests/test_quoted_*.py) and
``make figures CHECK=1`` (scripts/regenerate_figures.py --check) compare: the
parsers of docs/' tables and paragraphs, and the measured one-rounding spread
of each figure. The spread is the largest |move| of one seed's figure when
the initial state is nudged by one rounding step (studyapp/model/nudge.py),
over 10 seeds (the pilot: its 12 participants; the study: its one data set),
as docs/reproducibility.md ("Sensitivity to one rounding") measured it on
2026-11-28 with ``PYTHONPATH=. python scripts/sensitivity.py`` (the command of
each part is beside its table there). The loop's stick-slip amplifies one
rounding (another BLAS kernel, libm, CPU or numpy gives one) into a few per
cent of one seed's figure; within the spread a figure is a fact about the
model, beyond it a change of the model.

A figure holds when |new - quoted| <= spread x |quoted| + the quoted
rounding (half a unit of its last digit; a breakdown F_max: the search's
precision, sqrt(1.02) - 1, which covers its three significant figures).
"""

import argparse
import math
import re
import shlex

# breakdown F_max, (gesture, rate) -> largest |F' / F - 1| of one seed over sources and seeds 0-9
BREAKDOWN_PRECISION = math.sqrt(1.02) - 1.0
# (measured: at 5 kHz bowing 5 of 160 seed-searches moved, LVT's 4 by 1.6-3.2 % and KALFOAWACC's seed 7 from
# "> 200" to 4.48 N, the search's flaw at its top that docs/reproducibility.md describes, left out here; holding 7
# of 160, by 1.6 %; LVT at 48 kHz 8 of 10, by 1.6 % and once 6.7 %: one of the search's last decisions flipping)
BREAKDOWN_ROUNDING = {("strokes", 5000.0): 0.032, ("hold", 5000.0): 0.017, ("strokes", 48000.0): 0.067}
# docs/model.md's paper's signals: figure -> largest relative move over seeds 1014.. / 1012.. (pitch: 0..9)
SIGNAL_ROUNDING = {"dvdt_12.1": 0.043, "high_7.7": 0.18, "foaw_7.7": 0.00003, "foaw_12.1": 0.0038, "pitch": 1e-9}
# the pilot: a median (relative), rho and the between-participant share (absolute, % points) per set of six
# (measured: LVT's median at seeds 1-6 moved 1.8 %, no other; rho did not move; the shares by 2 and 4 points)
PILOT_ROUNDING = {"median": 0.018, "rho": 0.0, "share": 4.0}
# one participant's responses: the largest share of them that moved (4 of 54), and the largest relative move of
# its median in one condition (29 of the pilot's 648 responses moved, by whole knob steps)
RESPONSE_ROUNDING = {"moved_share": 0.074, "median": 0.12}
# docs/study: the objective of params.toml on simulate-set's training set, relative (the largest over estimators:
# KALLEVACC's; KALMAN and KALLEV 11-12 %, the others 0.2-7.4 %; one data set, plain and nudged)
OBJECTIVE_ROUNDING = 0.29
# docs/study/findings.csv: the findings whose verdict one rounding step was measured to change
FLIPPING_FINDINGS = ("KALMAN best on the objective (F_max 0 to 7.7 N)",)


def within(value, quoted, spread, rounding=0.0):
    """Whether ``value`` is ``quoted`` within ``spread`` (relative) plus ``rounding`` (absolute)."""
    if value == quoted:
        return True
    if math.isinf(value) or math.isinf(quoted):
        return False
    return abs(value - quoted) <= spread * abs(quoted) + rounding


def half_unit(text):
    """Half a unit of the last digit of a quoted number."""
    return 0.5 * 10.0 ** -len(text.split(".")[1]) if "." in text else 0.5


# --- docs/breakdown.md --------------------------------------------------------------------------------

def number(cell):
    """A Markdown cell's F_max: "> 200" is inf, "<= 0.05" the search's bottom."""
    cell = cell.strip()
    if cell.startswith(">"):
        return math.inf
    return float(cell.lstrip("<= "))


def breakdown_settings(command):
    """The settings of a quoted ``studyapp breakdown`` command, the CLI's defaults where it leaves them out."""
    words = shlex.split(command)
    assert words[:2] == ["studyapp", "breakdown"], command
    p = argparse.ArgumentParser()
    p.add_argument("--all", action="store_true")
    p.add_argument("--source")
    p.add_argument("--rate", type=float, default=5000.0)
    p.add_argument("--seeds", type=int, default=5)
    p.add_argument("--first-seed", type=int, default=0)
    p.add_argument("--gesture", default="strokes")
    p.add_argument("--duration", type=float, default=5.0)
    p.add_argument("--windows", default="seconds")
    p.add_argument("-o", "--output")
    return p.parse_args(words[2:])


def breakdown_tables(text):
    """[(date, command, [row dict])] for each "Generated on DATE by `COMMAND`" and the table after it."""
    found = []
    for match in re.finditer(r"Generated on (\d{4}-\d\d-\d\d) by `([^`]+)`", text):
        lines = text[match.end():].splitlines()
        start = next(i for i, line in enumerate(lines) if line.startswith("|"))
        block = []
        for line in lines[start:]:
            if not line.startswith("|"):
                break
            block.append([cell.strip() for cell in line.strip().strip("|").split("|")])
        header, rows = block[0], block[2:]
        found.append((match.group(1), match.group(2), [dict(zip(header, row)) for row in rows]))
    return found


def bowing_breakdowns(text, rate):
    """{source: median F_max} of ``text``'s (docs/breakdown.md's) bowing table at ``rate`` (strokes, windows in
    seconds): read, not copied, since the table is regenerated whenever the world changes and copies went stale."""
    for _, command, rows in breakdown_tables(text):
        args = breakdown_settings(command)
        if (args.gesture, args.rate, args.windows) == ("strokes", rate, "seconds"):
            return {row["source"]: float(row["fmax_median"]) for row in rows}
    raise ValueError(f"docs/breakdown.md has no bowing table at {rate:g} Hz")


def breakdown_tolerance(gesture, rate):
    return BREAKDOWN_PRECISION + BREAKDOWN_ROUNDING[(gesture, float(rate))]


def compare_breakdown(quoted_rows, new_rows, gesture, rate):
    """Problems (one line each) where a regenerated table's per-seed F_max leaves the quoted one's spread."""
    tol, problems = breakdown_tolerance(gesture, rate), []
    new = {r["source"]: r for r in new_rows}
    for row in quoted_rows:
        if row["source"] not in new:
            problems.append(f"{row['source']}: not regenerated")
            continue
        for seed, a, b in zip(row["seeds_used"].split(";"), row["fmax_per_seed"].split(";"),
                              new[row["source"]]["fmax_per_seed"].split(";")):
            if not within(number(b), number(a), tol) and not (number(a) == number(b)):
                problems.append(f"{row['source']} seed {seed.strip()}: {b.strip()} N against the quoted {a.strip()} N "
                                f"(allowed {100 * tol:.1f} %)")
    return problems


# --- docs/model.md, the paper's signals ---------------------------------------------------------------

SIGNALS_COMMAND = "PYTHONPATH=. python scripts/model_figures.py --only-signals"


def signals_paragraph(text):
    start = text.index("**The paper's signals**")
    return " ".join(text[start:text.index("\n\n", start)].split())


def quoted_signals(paragraph):
    """{figure: quoted number as text} of docs/model.md's paragraph (``pitch``: the three, 5, 20, 48 kHz)."""
    def figure(pattern):
        match = re.search(pattern, paragraph)
        assert match, pattern
        return match.groups() if len(match.groups()) > 1 else match.group(1)
    return {
        "dvdt_12.1": figure(r"max \|dv/dt\| of `velocity_lvt` at 12\.1 N ([\d.]+) m/s\^2"),
        "high_7.7": figure(r"([\d.]+) mm/s RMS at 7\.7 N"),
        "foaw_7.7": figure(r"maximum window on ([\d.]+) % of the 7\.7 N recording's samples"),
        "foaw_12.1": figure(r"\(([\d.]+) % at 12\.1 N"),
        "pitch": figure(r"Pitch with LVT at 2 N on strokes: ([\d.]+), ([\d.]+) and ([\d.]+) Hz at 5, 20 and 48 kHz"),
    }


def signal_holds(name, value, quoted_text):
    return within(value, float(quoted_text), SIGNAL_ROUNDING[name], 2 * half_unit(quoted_text))


def printed_signals(text):
    """The figures scripts/model_figures.py --only-signals printed, named as ``quoted_signals``'s."""
    found = {}
    for fmax, dvdt, high, at_max in re.findall(r"data set at ([\d.]+) N: max \|dv/dt\| ([\d.]+) m/s\^2, above 100 Hz "
                                               r"([\d.]+) mm/s RMS, FOAW at its maximum window ([\d.]+) %", text):
        found.update({f"dvdt_{fmax}": dvdt, f"high_{fmax}": high, f"foaw_{fmax}": at_max})
    found["pitch"] = tuple(re.findall(r"pitch at [\d.]+ Hz, LVT at 2 N on strokes: ([\d.]+) Hz", text))
    return found


def compare_signals(quoted, printed):
    problems = []
    for name, text in quoted.items():
        pairs = zip(text, printed.get(name, ())) if name == "pitch" else [(text, printed.get(name))]
        for q, new in pairs:
            if new is None or not signal_holds(name, float(new), q):
                problems.append(f"{name}: {new} against the quoted {q} (allowed {100 * SIGNAL_ROUNDING[name]:.2g} %)")
    return problems


# --- docs/experiment.md, the in-silico pilot ----------------------------------------------------------

PILOT_HEADER = r"Generated on (\d{4}-\d\d-\d\d) by `PYTHONPATH=\. python scripts/pilot\.py ([^`]+)`"


def pilot_table(text):
    """(date, command's words, {row label: [cell per set]}) of the pilot's table in ``text``."""
    match = re.search(PILOT_HEADER, text)
    assert match, "no dated pilot table"
    lines = text[match.end():].splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("|"))
    rows = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        rows[cells[0]] = cells[1:]
    return match.group(1), shlex.split(match.group(2)), rows


def pilot_row_holds(label, quoted, new):
    if label.endswith("median (N)"):
        return within(float(new), float(quoted), PILOT_ROUNDING["median"], half_unit(quoted))
    if label.startswith("rho"):
        return within(float(new), float(quoted), 0.0, PILOT_ROUNDING["rho"] + half_unit(quoted))
    return within(float(new), float(quoted), 0.0, PILOT_ROUNDING["share"] + half_unit(quoted))


def compare_pilot(quoted_rows, new_rows):
    problems = []
    for label, cells in quoted_rows.items():
        for i, (q, new) in enumerate(zip(cells, new_rows.get(label, []))):
            if not pilot_row_holds(label, q, new):
                problems.append(f"{label}, set {i + 1}: {new} against the quoted {q}")
    return problems
