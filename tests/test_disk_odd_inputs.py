"""The "more" of issue 33 (item 6): each refused in one line with exit 2, or doing what the docs say.

On main: one unreadable session made export and analyse refuse the whole study;
``evaluate --params P -o DIR`` crashed with a TypeError when DIR existed (the
README's own command, run twice); ``bench memory --dir SESSION`` wrote and
deleted inside a session folder; a condition named ``$\\frac$`` crashed the
report; ``gui --results FILE``, ``--audio bogus`` and ``--order-row -1`` opened
the console (with ``--screenshot`` it never exited)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.cli import main
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session
from tests.experiment.demo_protocol import trials_only_demo
from tests.experiment.experiment_fake_loop import run_simulated

ROOT = Path(__file__).resolve().parents[1]


def one_line_refusal(capsys, argv, match):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0] and "Traceback" not in err[0], err
    return err[0]


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Two sessions with responses, under one study."""
    folder = tmp_path_factory.mktemp("odd")
    protocol = load_protocol(trials_only_demo(folder))
    for participant in ("U01", "U02"):
        session = Session.create(protocol, participant, folder / "results", seed=1)
        run_simulated(session, trials=2).finish("interrupted")
        session.close()
    return folder / "results"


@pytest.mark.parametrize("make", ["folder", "fifo"])
def test_one_unreadable_session_is_skipped_with_a_warning_naming_the_file(results, tmp_path, capsys, make):
    log = next((results / "demo" / "U02").glob("*/events.jsonl"))
    kept = log.read_bytes()
    log.unlink()
    if make == "folder":
        log.mkdir()
    else:
        os.mkfifo(log)
    try:
        out = tmp_path / "r.csv"
        assert main(["export", str(results), "-o", str(out)]) == 0
        warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
        assert len(warnings) == 1 and f"{log.parent}: skipped" in warnings[0] and str(log) in warnings[0]
        assert "U01" in out.read_text() and "U02" not in out.read_text()
        assert main(["export", str(results), "-o", str(tmp_path / "s.csv"), "--strict"]) == 2
        assert str(log) in capsys.readouterr().err and not (tmp_path / "s.csv").exists()
        assert main(["analyse", str(results), "-o", str(tmp_path / "report")]) == 0
        assert str(log) in capsys.readouterr().err
    finally:
        log.rmdir() if log.is_dir() else log.unlink()
        log.write_bytes(kept)


def test_bench_memory_refuses_a_session_folder(results, capsys):
    session = next((results / "demo" / "U01").glob("*/"))
    before = sorted(os.listdir(session))
    one_line_refusal(capsys, ["bench", "memory", "--dir", str(session), "--rows", "10"], "inside the session folder")
    assert sorted(os.listdir(session)) == before


def test_a_condition_named_like_maths_is_drawn_as_written():
    from studyapp.analysis.figures import FIGURES, render
    from studyapp.analysis.responses import check_responses
    from studyapp.analysis.study import analyse
    from tests.analysis.conftest import synthetic_responses

    frame = synthetic_responses(participants=3, trials=2, seed=0)
    first = sorted(frame["condition"].unique())[0]
    frame["condition"] = frame["condition"].replace(first, r"$\frac$")
    study = analyse(check_responses(frame, "synthetic.csv"))  # names are upper-cased: $\FRAC$, maths all the same
    maths = next(c for c in study.rating.conditions if "$" in c)
    for name in FIGURES:
        figure = render(name, study)
        figure.canvas.draw()  # the mathtext parser ran here and raised
        shown = [t.get_text() for ax in figure.axes for t in ax.get_xticklabels() + ax.texts]
        assert maths.replace("$", r"\$") in shown


@pytest.mark.parametrize("argv, match", [
    (["--results", "README.md"], "--results README.md: not a folder"),
    (["--audio", "bogus"], "--audio 'bogus'"),
    (["--order-row", "-1"], "--order-row -1"),
])
def test_gui_refuses_bad_options_before_the_console_opens(argv, match, tmp_path):
    done = subprocess.run([sys.executable, "-m", "studyapp", "gui", *argv, "--screenshot", str(tmp_path / "s.png")],
                          cwd=ROOT, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "QT_QPA_PLATFORM": "offscreen"})
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and match in lines[0], done.stderr
    assert not (tmp_path / "s.png").exists()
