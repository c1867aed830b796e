"""Issue 22 item 11: simulated participants are kept out of the analysis unless asked for.

The report of a real study listed "P01, SIM01, SIM02, SIM03": the simulated runs were
analysed as participants. ``analyse`` now leaves out rows with ``simulated`` True
(export's column) unless ``--include-simulated``; with nothing else, one line and exit 2.
"""

import contextlib
import io
import re

import pandas as pd

from studyapp.analysis.report_folder import open_study
from studyapp.cli import main
from tests.analysis.conftest import synthetic_responses


def _mixed(tmp_path, real=3, simulated=2):
    frame = synthetic_responses(participants=real + simulated)
    ids = sorted(frame["participant"].unique())
    sims = {pid: f"SIM{k + 1:02d}" for k, pid in enumerate(ids[real:])}
    frame["participant"] = frame["participant"].replace(sims)
    frame["simulated"] = frame["participant"].str.startswith("SIM")
    path = tmp_path / "responses.csv"
    frame.to_csv(path, index=False)
    return path


def _analyse(*args):
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["analyse", *map(str, args)])
    return code, err.getvalue()


def test_simulated_participants_are_left_out_by_default(tmp_path):
    code, err = _analyse(_mixed(tmp_path), "-o", tmp_path / "out")
    assert code == 0, err
    assert "3 participants" in err
    assert "left out 2 simulated participants (SIM01, SIM02): --include-simulated analyses them too" in err
    analysed = pd.read_csv(tmp_path / "out" / "responses_analysed.csv")
    assert set(analysed["participant"]) == {"P01", "P02", "P03"} and not analysed["simulated"].any()
    html = (tmp_path / "out" / "report.html").read_text()
    assert "3 participants: P01, P02, P03" in html and "Left out: 2 simulated participants (SIM01, SIM02)" in html
    assert set(open_study(tmp_path / "out").participants) == {"P01", "P02", "P03"}


def test_include_simulated_keeps_them_and_says_so(tmp_path):
    code, err = _analyse(_mixed(tmp_path), "-o", tmp_path / "out", "--include-simulated")
    assert code == 0, err
    assert "5 participants" in err and "left out" not in err
    html = (tmp_path / "out" / "report.html").read_text()
    assert "Simulated participants included (--include-simulated): SIM01, SIM02" in html
    # the report folder reopens with what it analysed (the GUI's analysis view)
    assert set(open_study(tmp_path / "out").participants) == {"P01", "P02", "P03", "SIM01", "SIM02"}


def test_only_simulated_is_one_line_naming_the_option(tmp_path):
    code, err = _analyse(_mixed(tmp_path, real=0, simulated=3), "-o", tmp_path / "out")
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err
    assert lines[0].startswith("studyapp: error: ") and "--include-simulated" in lines[0]
    assert "every response is from a simulated participant (SIM01, SIM02, SIM03)" in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_bad_simulated_cell_is_named(tmp_path):
    frame = pd.read_csv(_mixed(tmp_path))
    frame["simulated"] = frame["simulated"].astype(object)
    frame.loc[4, "simulated"] = "maybe"
    frame.to_csv(tmp_path / "bad.csv", index=False)
    code, err = _analyse(tmp_path / "bad.csv", "-o", tmp_path / "out")
    assert code == 2 and "column 'simulated' at line 6 is 'maybe'; allowed: True, False" in err


def test_figures_and_report_say_how_many_participants_are_simulated_in_the_singular_too(tmp_path):
    """Issue 31 items 3 and 10: Figs. 7-8 with --include-simulated say how many are simulated; "1 participant"."""
    from studyapp.analysis.figures import simulated_footnote
    from studyapp.analysis.responses import load_responses
    from studyapp.analysis.study import analyse

    responses, label = load_responses(_mixed(tmp_path, real=3, simulated=1), include_simulated=True)
    study = analyse(responses, source=label, include_simulated=True)
    assert simulated_footnote(study, study.adjustment).strip() == "1 of 4 participants simulated (--include-simulated)"
    assert simulated_footnote(analyse(responses, source=label), study.adjustment) == ""
    code, err = _analyse(_mixed(tmp_path, real=1, simulated=1), "-o", tmp_path / "one")
    assert code == 0, err
    assert "1 participant," in err and "left out 1 simulated participant (SIM01)" in err
    html = (tmp_path / "one" / "report.html").read_text()
    assert "1 participant: P01" in html and not re.search(r"(?<!\d)1 participants", html)


def test_no_effect_size_for_one_participant():
    """Issue 31 item 10: with one participant every pair's r is +-1 by construction: not given."""
    import math

    from studyapp.analysis.within_subject import within_subject

    one = pd.DataFrame({"participant": ["P01"] * 3, "condition": ["A", "B", "C"], "value": [1.0, 2.0, 3.0]})
    assert all(math.isnan(r) for r in within_subject(one, ["A", "B", "C"]).signed_rank["effect_size"])
    two = pd.concat([one, one.assign(participant="P02", value=[1.5, 2.5, 3.5])])
    assert list(within_subject(two, ["A", "B", "C"]).signed_rank["effect_size"]) == [-1.0, -1.0, -1.0]
