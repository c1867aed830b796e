"""docs/experiment.md's in-silico pilot is what the code gives on its quoted seeds (issue 30, item 6).

The pilot's table ("Generated on DATE by `PYTHONPATH=. python scripts/pilot.py
--seeds ...`") quotes, per set of seeds, the Fig. 7 medians, rho against the
paper's order and the share of the spread between participants; every
response behind it is kept in docs/study/pilot.csv. The normal suite checks
the table against the CSV (the figures recomputed by studyapp.analysis.pilot,
to the table's rounding), the CSV's seeds against the command, and the
simulated participant's criterion spread against the paper's share of the
spread between participants (the calibration it documents). The slow test
plays the first participant of the first set again (one headless session on
its seed: the smallest run that replays the pilot's code path) and holds its
adjustment responses to the CSV's within what one rounding moves them: one
rounding step of the initial state (studyapp/model/nudge.py) leaves most of
a participant's responses as they were but moves a few by whole knob steps,
where a staircase heard breakdown one probe sooner or later. So at most the
measured largest share of one participant's responses may differ, and each
condition's median within the measured largest move of one participant's
condition median: docs/reproducibility.md ("Sensitivity to one rounding",
2026-11-28, ``PYTHONPATH=. python scripts/sensitivity.py -o OUT --parts pilot``
over the pilot's 12 participants), kept in scripts/quoted_figures.py
(``RESPONSE_ROUNDING``). The whole pilot against the table is ``make figures
ONLY=pilot CHECK=1``.
"""

import inspect
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from studyapp.analysis.consistency import variance_decomposition
from studyapp.analysis.pilot import pilot_figures, variance_components
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.simulated_participant import SimulatedParticipant
from studyapp.model.fmax_knob import KNOB_MAX

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from quoted_figures import RESPONSE_ROUNDING, pilot_table, within  # noqa: E402

DOC = ROOT / "docs" / "experiment.md"
CSV = ROOT / "docs" / "study" / "pilot.csv"

sys.path.insert(0, str(ROOT / "scripts"))
from pilot import parse_sets  # noqa: E402


def quoted_table(text):
    """(date, seed sets, {row label: [cell per set]}) of the pilot's table in ``text``."""
    date, words, rows = pilot_table(text)
    return date, parse_sets(words[words.index("--seeds") + 1]), rows


def decimals(cell):
    return len(cell.split(".")[1]) if "." in cell else 0


def responses():
    return pd.read_csv(CSV, dtype={"set": str})


def test_the_table_is_dated_and_names_its_sets():
    date, sets, rows = quoted_table(DOC.read_text())
    assert date <= "2026-12-31" and len(sets) >= 2
    data = responses()
    assert list(dict.fromkeys(data["set"])) == [label for label, _ in sets]
    for label, seeds in sets:
        mine = data[data["set"] == label]
        assert sorted(set(mine["seed"])) == seeds
        assert set(mine["participant"]) == {f"SIM{s:02d}" for s in seeds}
    assert all(len(cells) == len(sets) for cells in rows.values())


def test_the_quoted_figures_are_the_csvs():
    _, sets, rows = quoted_table(DOC.read_text())
    data = responses()
    for column, (label, _) in enumerate(sets):
        mine = data[data["set"] == label]
        figures = pilot_figures(mine)
        for condition, median in figures["medians"].items():
            assert float(rows[f"{condition} median (N)"][column]) == pytest.approx(median, rel=0.006), (label, condition)
        rho = rows["rho against the paper's Fig. 7 order"][column]
        assert float(rho) == pytest.approx(figures["rho"], abs=0.5 * 10 ** -decimals(rho))
        within = rows["within lower than total, log10 F_max, random effects (%)"][column]
        assert float(within) == pytest.approx(figures["mean_within_lower_pct"], abs=0.5 * 10 ** -decimals(within))
        analysed = variance_decomposition(mine.rename(columns={"fmax": "value"}), sorted(set(mine["condition"])))
        intra = rows["intra_lower_pct of `studyapp analyse`, F_max in N (%)"][column]
        assert float(intra) == pytest.approx(np.nanmean(analysed["intra_lower_pct"]), abs=0.5 * 10 ** -decimals(intra))


def first_seed():
    _, sets, _ = quoted_table(DOC.read_text())
    label, seeds = sets[0]
    return label, seeds[0]


@pytest.mark.slow
def test_a_quoted_participant_is_what_the_code_plays_on_its_seed(tmp_path):
    label, seed = first_seed()
    who = f"SIM{seed:02d}"
    subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", str(ROOT / "protocols" / "sinclair2014.toml"),
                    "--participant", who, "--simulated-participant", "--headless", "--results", str(tmp_path / "r"),
                    "--seed", str(seed)], check=True, capture_output=True, cwd=ROOT)
    subprocess.run([sys.executable, "-m", "studyapp", "export", str(tmp_path / "r"), "-o", str(tmp_path / "e.csv")],
                   check=True, capture_output=True, cwd=ROOT)
    again = pd.read_csv(tmp_path / "e.csv")
    again = again[(again["task"] == "adjustment") & ~again["practice"].astype(bool)]
    again = again.sort_values(["condition", "trial"])
    quoted = responses()
    quoted = quoted[(quoted["set"] == label) & (quoted["participant"] == who)].sort_values(["condition", "trial"])
    assert list(again["condition"]) == list(quoted["condition"]) and list(again["trial"]) == list(quoted["trial"])
    moved = np.mean(again["fmax"].to_numpy(float) != quoted["fmax"].to_numpy(float))
    assert moved <= RESPONSE_ROUNDING["moved_share"], moved
    for condition, mine in quoted.groupby("condition"):
        median = np.median(again[again["condition"] == condition]["fmax"])
        assert within(median, np.median(mine["fmax"]), RESPONSE_ROUNDING["median"]), (condition, median)


def test_the_criterion_spread_gives_the_papers_between_participant_share():
    """The simulated participant's criterion spread is calibrated to the paper's 61 % (Sec. 9.1):
    spread^2 / (spread^2 + s_w^2), s_w^2 the pilot's within-participant variance in knob positions."""
    task = load_protocol(ROOT / "protocols" / "sinclair2014.toml").task("adjustment")
    step = task.decades / (KNOB_MAX - 1)  # decades per knob position
    data = responses()
    within = [variance_components([np.log10(rows["fmax"][rows["participant"] == p].to_numpy()) / step
                                   for p in sorted(set(rows["participant"]))])[0]
              for _, rows in data.groupby(["set", "condition"])]
    spread = inspect.signature(SimulatedParticipant).parameters["criterion_spread"].default
    share = spread ** 2 / (spread ** 2 + np.mean(within))
    assert share == pytest.approx(0.61, abs=0.03), (np.mean(within), share)
