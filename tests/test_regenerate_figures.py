"""scripts/regenerate_figures.py, the one command behind `make figures` (issue 30, item 6): what it runs, lists and writes."""

import datetime
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import regenerate_figures as rf  # noqa: E402


def script(*args):
    return subprocess.run([sys.executable, str(ROOT / "scripts" / "regenerate_figures.py"), *args],
                          capture_output=True, text=True, cwd=ROOT)


def figures_md():
    return (ROOT / "docs" / "figures.md").read_text()


def test_every_generator_is_in_docs_figures_md_and_every_listed_one_exists():
    listed = re.findall(r"^\| ([a-z0-9-]+) \|", figures_md(), re.M)
    assert listed[2:] == [g.name for g in rf.generators()]  # after the header ("generator") and its rule


def test_every_script_docs_name_is_a_generator_or_said_not_to_be():
    text = figures_md()
    named = set()
    for doc in (ROOT / "docs").glob("*.md"):
        named |= set(re.findall(r"scripts/([a-z_]+\.py)", doc.read_text()))
    run = {w for g in rf.generators() for step in g.steps for w in step if w.startswith("scripts/")}
    for name in sorted(named - {"regenerate_figures.py"}):
        assert f"scripts/{name}" in run or f"scripts/{name}" in text, name


def test_the_breakdown_commands_are_docs_breakdown_md_headers_with_their_output_moved():
    headers = re.findall(r"Generated on \d{4}-\d\d-\d\d by `(studyapp breakdown [^`]+)`", (ROOT / "docs" / "breakdown.md").read_text())
    found = rf.breakdown_generators()
    assert len(found) == len(headers) >= 2
    for gen, header in zip(found, headers):
        (words,) = gen.steps
        shown = rf.shown(words, "OUT")
        assert shown.split(" -o ")[0] == header.split(" -o ")[0]
        assert shown.split(" -o ")[1].startswith("OUT/")


def test_a_breakdown_header_at_another_rate_gets_its_own_name():
    text = "Generated on 2026-11-27 by `studyapp breakdown --all --rate 48000 --seeds 5 --gesture strokes`."
    (gen,) = rf.breakdown_generators(text)
    assert gen.name == "breakdown-strokes-48k" and gen.steps[0][-2:] == ("-o", "{out}/breakdown-strokes-48k.md")


def test_list_names_each_generator_and_its_commands_and_runs_nothing(tmp_path):
    done = script("--list", "-o", str(tmp_path / "out"))
    assert done.returncode == 0
    for g in rf.generators():
        assert f"{g.name}: " in done.stdout
    assert "PYTHONPATH=. python scripts/pilot.py --seeds 1-6,7-12 -o OUT/pilot/pilot" in done.stdout
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args, says", [(["--only", "nope"], "--only nope: no such generator"),
                                        (["--only"], "expected at least one argument")])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, args, says):
    done = script(*args, "-o", str(tmp_path / "out"))
    assert done.returncode == 2 and says in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_folder_with_something_in_it_is_refused(tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    done = script("--only", "pilot", "-o", str(tmp_path))
    assert done.returncode == 2 and "not empty" in done.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_a_run_writes_each_output_dated_with_its_command_and_a_summary(tmp_path, monkeypatch, capsys):
    good = rf.Generator("good", "nowhere", ((rf.PY, "-c", "print('figure 1.23')"),))
    bad = rf.Generator("bad", "nowhere", ((rf.PY, "-c", "import sys; sys.exit(3)"),))
    monkeypatch.setattr(rf, "generators", lambda: [good, bad])
    assert rf.main(["-o", str(tmp_path / "out")]) == 1
    today = datetime.date.today().isoformat()
    output = (tmp_path / "out" / "good" / "output.md").read_text()
    assert output.startswith(f"Generated on {today} by `PYTHONPATH=. python -c ") and "figure 1.23" in output
    assert "exit 3" in (tmp_path / "out" / "bad" / "output.md").read_text()
    summary = (tmp_path / "out" / "figures.md").read_text()
    assert f"| good | {today} | ok |" in summary and f"| bad | {today} | FAILED |" in summary
    err = capsys.readouterr().err
    assert "[1/2] good" in err and "[2/2] bad" in err and "failed: bad" in err


def test_check_compares_a_figure_with_docs_within_its_measured_spread(tmp_path, monkeypatch, capsys):
    import quoted_figures as qf
    quoted = qf.quoted_signals(qf.signals_paragraph((ROOT / "docs" / "model.md").read_text()))

    def printed(dvdt):
        return (f"data set at 12.1 N: max |dv/dt| {dvdt:.0f} m/s^2, above 100 Hz 26.5 mm/s RMS, FOAW at its maximum "
                f"window {quoted['foaw_12.1']} % of samples\n"
                f"data set at 7.7 N: max |dv/dt| 46 m/s^2, above 100 Hz {quoted['high_7.7']} mm/s RMS, FOAW at its "
                f"maximum window {quoted['foaw_7.7']} % of samples\n"
                + "".join(f"pitch at {r} Hz, LVT at 2 N on strokes: {p} Hz\n"
                          for r, p in zip((5000, 20000, 48000), quoted["pitch"])))

    today = datetime.date.today().isoformat()
    dvdt = float(quoted["dvdt_12.1"])
    for i, (value, code, status) in enumerate(((dvdt * 1.03, 0, "ok, holds"), (dvdt * 1.2, 1, "MOVED (1)"))):
        gen = rf.Generator("model-signals", "docs/model.md", ((rf.PY, "-c", f"print({printed(value)!r})"),))
        other = rf.Generator("other", "nowhere", ((rf.PY, "-c", "print(1)"),))
        monkeypatch.setattr(rf, "generators", lambda gen=gen, other=other: [gen, other])
        assert rf.main(["-o", str(tmp_path / f"out{i}"), "--check"]) == code
        summary = (tmp_path / f"out{i}" / "figures.md").read_text()
        assert f"| model-signals | {today} | {status} |" in summary
        assert f"| other | {today} | ok, not compared (no measured spread) |" in summary
    err = capsys.readouterr().err
    assert f"moved beyond its spread: dvdt_12.1: {dvdt * 1.2:.0f} against the quoted {quoted['dvdt_12.1']}" in err


def test_check_finds_the_docs_table_by_its_settings_not_its_spelling(tmp_path):
    text = (ROOT / "docs" / "breakdown.md").read_text()
    start = text.index("--gesture hold")
    start = text.rindex("Generated on", 0, start)
    table = text[start:text.index("\n\n", text.index("| source", start))]
    spelled = table.replace("--duration 5 -o", "--duration 5 --windows seconds -o")
    assert spelled != table
    (tmp_path / "x.md").write_text(spelled + "\n")
    gen = rf.Generator("breakdown-hold", "docs/breakdown.md", (("studyapp", "breakdown", "-o", "{out}/x.md"),))
    assert rf.check_breakdown(gen, tmp_path) == []
    (tmp_path / "x.md").write_text(spelled.replace("| LVT | 5000 | hold | 5 | 6.72", "| LVT | 5000 | hold | 5 | 7.5")
                                   .replace("6.72; 6.72; 6.72; 6.72; 6.72", "7.5; 6.72; 6.72; 6.72; 6.72") + "\n")
    assert [p.split(":")[0] for p in rf.check_breakdown(gen, tmp_path)] == ["LVT seed 0"]
