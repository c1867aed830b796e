"""End to end: simulated participants on the demo protocol, export, analyse, open the report.

Three participants with different seeds each run a headless session
(``studyapp run --simulated-participant --headless``), their results are
exported (``studyapp export``) and analysed (``studyapp analyse``, in this
process to save start-up time), both from the CSV and straight from the
results folder. A copy of the results with one
response cut from a session's log checks that the gap is reported.
"""

import contextlib
import io
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import matplotlib.image
import pandas as pd
import pytest

from studyapp.cli import main
from tests.analysis.conftest import FIGURES, TABLES

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
PARTICIPANTS = {"SIM1": 11, "SIM2": 22, "SIM3": 33}


def analyse(*args):
    """(exit code, stderr) of ``studyapp analyse ARGS``."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["analyse", *map(str, args)])
    return code, err.getvalue()


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """Results of three simulated participants on the demo protocol, and their export."""
    folder = tmp_path_factory.mktemp("e2e")
    runs = [
        subprocess.Popen([sys.executable, "-m", "studyapp", "run", "--protocol", str(DEMO), "--participant", pid,
                          "--simulated-participant", "--headless", "--seed", str(seed),
                          "--results", str(folder / "results")],
                         cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for pid, seed in PARTICIPANTS.items()
    ]
    for run in runs:
        _, err = run.communicate(timeout=600)
        assert run.returncode == 0, err
    export = subprocess.run([sys.executable, "-m", "studyapp", "export", str(folder / "results"), "-o",
                             str(folder / "responses.csv")], cwd=folder, capture_output=True, text=True, timeout=600)
    assert export.returncode == 0, export.stderr
    return folder


@pytest.fixture(scope="module")
def conditions():
    import tomllib

    protocol = tomllib.loads(DEMO.read_text())
    return set(protocol["rating"]["conditions"]), set(protocol["adjustment"]["conditions"])


@pytest.mark.parametrize("source", ["responses.csv", "results"])
def test_every_output_present_and_the_report_opens(study, conditions, source):
    rating_conditions, adjustment_conditions = conditions
    out = study / f"report_{source}"
    code, err = analyse(study / source, "-o", out, "--include-simulated")  # every participant here is simulated
    assert code == 0, err
    for name, columns in TABLES.items():
        table = pd.read_csv(out / name)
        assert list(table.columns) == columns and len(table) > 0, name
    assert set(pd.read_csv(out / "spearman_participants.csv")["participant"]) == set(PARTICIPANTS)
    summary = pd.read_csv(out / "summary_adjustment.csv")
    assert set(summary["condition"]) == adjustment_conditions and (summary["n"] == len(PARTICIPANTS)).all()
    summary = pd.read_csv(out / "summary_rating.csv")
    assert set(summary["condition"]) == rating_conditions and (summary["n"] == len(PARTICIPANTS)).all()
    assert summary["median"].between(0, 1).all()
    k = len(adjustment_conditions)
    assert len(pd.read_csv(out / "wilcoxon_adjustment.csv")) == k * (k - 1) // 2
    assert pd.read_csv(out / "missing_trials.csv").empty
    for name in FIGURES:
        image = matplotlib.image.imread(io.BytesIO((out / f"{name}.png").read_bytes()), format="png")
        assert image.shape[0] > 200 and image.shape[1] > 200 and image.std() > 0
        assert (out / f"{name}.svg").read_text().lstrip().startswith("<?xml")

    page = _Page()
    page.feed((out / "report.html").read_text(encoding="utf-8"))
    page.close()
    assert page.open_tags == [] and page.titles == ["studyapp analysis"]
    assert len(page.images) == len(FIGURES)
    for src in page.images:
        assert src.startswith("data:image/png;base64,")
    assert set(PARTICIPANTS) <= set(page.text.split())


@pytest.mark.parametrize("source", ["responses.csv", "results"])
def test_only_simulated_participants_are_refused_in_one_line_naming_the_option(study, source):
    assert pd.read_csv(study / "responses.csv")["simulated"].all()  # export's column (issue 22 item 11)
    out = study / f"refused_{source}"
    code, err = analyse(study / source, "-o", out)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "every response is from a simulated participant (SIM1, SIM2, SIM3)" in err
    assert "--include-simulated" in err and not out.exists()


def test_a_session_short_of_a_response_is_reported(study):
    results = study / "results_short"
    shutil.copytree(study / "results", results)
    (events,) = results.glob("*/SIM2/*/events.jsonl")
    lines = events.read_text().splitlines(keepends=True)
    last_response = max(i for i, line in enumerate(lines) if '"response"' in line and '"adjustment"' in line)
    events.write_text("".join(lines[:last_response]))
    code, err = analyse(results, "-o", study / "report_short", "--include-simulated")
    assert code == 0, err
    missing = pd.read_csv(study / "report_short" / "missing_trials.csv")
    assert missing["participant"].tolist() == ["SIM2"] and missing["present"].tolist() == [0]
    assert "warning: participant SIM2 has 0 of 1 adjustment responses" in err
    assert "SIM2 has 0 of 1 adjustment responses" in (study / "report_short" / "report.html").read_text()


class _Page(HTMLParser):
    """Checks that every element closes, and collects the title, images and text."""

    VOID = {"meta", "img", "br", "hr", "link", "input"}

    def __init__(self):
        super().__init__()
        self.open_tags, self.titles, self.images, self.text = [], [], [], ""

    def handle_starttag(self, tag, attrs):
        if tag == "img":
            self.images.append(dict(attrs)["src"])
        if tag not in self.VOID:
            self.open_tags.append(tag)

    def handle_endtag(self, tag):
        assert self.open_tags and self.open_tags[-1] == tag, f"</{tag}> closes <{self.open_tags[-1:]}>"
        self.open_tags.pop()

    def handle_data(self, data):
        if self.open_tags and self.open_tags[-1] == "title":
            self.titles.append(data)
        self.text += " " + data
