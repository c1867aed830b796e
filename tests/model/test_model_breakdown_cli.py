"""``studyapp breakdown``: JSON keys and types, progress, the --all CSV and Markdown, --first-seed, bad input."""

import csv
import datetime
import json
import math
import statistics

import pytest

from studyapp.cli import main
from studyapp.model import breakdown

KEYS = ["source", "rate", "gesture", "seeds", "fmax", "fmax_median", "fmax_min", "fmax_max", "first_seed", "seeds_used",
        "windows"]
COLUMNS = ["source", "rate", "gesture", "seeds", "fmax_median", "fmax_min", "fmax_max", "fmax_per_seed", "first_seed",
           "seeds_used", "windows"]  # issue 30: how Table 1 was made for the rate
LINK = ["latency", "packet", "jitter"]  # issue 29: the link the device ran behind, after today's keys and columns


@pytest.fixture
def never_broken(monkeypatch):
    """Every trial stable: each search ends at once with inf (stable up to 200 N)."""
    monkeypatch.setattr(breakdown, "is_broken", lambda *args, **kwargs: False)


def test_json_for_one_source_with_progress(capsys):
    assert main(["breakdown", "--source", "LOWPASS", "--seeds", "2", "--duration", "1.5", "--json"]) == 0
    out, err = capsys.readouterr()
    doc = json.loads(out)
    assert list(doc) == KEYS + LINK + ["provenance"] and [doc[k] for k in LINK] == [0.0, 0.0, 0.0]
    # issue 20: breakdown is judged while bowing by default
    assert (doc["source"], doc["rate"], doc["gesture"], doc["seeds"]) == ("LOWPASS", 5000.0, "strokes", 2)
    assert (doc["first_seed"], doc["seeds_used"], doc["windows"]) == (0, [0, 1], "seconds")
    assert len(doc["fmax"]) == 2 and all(isinstance(v, float) and v > 0 for v in doc["fmax"])
    assert doc["fmax_median"] == pytest.approx(statistics.median(doc["fmax"]))
    assert (doc["fmax_min"], doc["fmax_max"]) == (min(doc["fmax"]), max(doc["fmax"]))
    # progress: every trial of every seed, then each seed's result
    for seed in (1, 2):
        assert f"breakdown LOWPASS: seed {seed}/2, trial 1: 0.05 N stable" in err
        assert f"breakdown LOWPASS: seed {seed}/2: F_max" in err


def test_inf_is_null_in_json_inf_in_csv(never_broken, tmp_path, capsys):
    out_json, out_csv = tmp_path / "b.json", tmp_path / "b.csv"
    assert main(["breakdown", "--source", "TRUE", "--seeds", "3", "--json", "-o", str(out_json)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(out_json.read_text())
    assert printed["fmax"] == [None, None, None] and printed["fmax_median"] is None
    assert main(["breakdown", "--source", "TRUE", "--seeds", "3", "-o", str(out_csv)]) == 0
    (row,) = csv.DictReader(out_csv.open())
    assert float(row["fmax_median"]) == math.inf and row["fmax_per_seed"] == "inf;inf;inf"


def test_all_writes_one_csv_row_per_source(tmp_path, capsys):
    out = tmp_path / "sub" / "breakdown.csv"
    assert main(["breakdown", "--all", "--seeds", "2", "--gesture", "hold", "--duration", "0.5", "-o", str(out)]) == 0
    with out.open() as f:
        reader = csv.DictReader(f)
        rows = list(reader)
    assert reader.fieldnames == COLUMNS + LINK
    assert [r["source"] for r in rows] == breakdown.sources()
    for r in rows:
        assert (float(r["rate"]), r["gesture"], int(r["seeds"])) == (5000.0, "hold", 2)
        values = [float(v) for v in r["fmax_per_seed"].split(";")]
        assert len(values) == 2
        assert float(r["fmax_median"]) == pytest.approx(statistics.median(values))
        assert (float(r["fmax_min"]), float(r["fmax_max"])) == (min(values), max(values))
    err = capsys.readouterr().err
    assert "breakdown [16/16] TRUE: seed 2/2" in err and f"wrote {out}" in err
    assert [p.name for p in out.parent.iterdir()] == ["breakdown.csv"]  # no temporary file left


def test_markdown_is_headed_by_date_and_command(never_broken, tmp_path, capsys):
    out = tmp_path / "breakdown.md"
    assert main(["breakdown", "--all", "--seeds", "2", "-o", str(out)]) == 0
    lines = out.read_text().splitlines()
    header = next(line for line in lines if line.startswith("Generated on"))
    assert datetime.date.today().isoformat() in header
    assert (f"`studyapp breakdown --all --rate 5000 --seeds 2 --first-seed 0 --gesture strokes --duration 5 "
            f"--windows seconds -o {out}`" in header)
    table = [line for line in lines if line.startswith("|")]
    assert table[0] == "| " + " | ".join(COLUMNS) + " |"
    assert [row.split(" | ")[0].strip("| ") for row in table[2:]] == breakdown.sources()
    assert all("> 200" in row for row in table[2:])
    assert all(row.endswith(" | 0 | 0; 1 | seconds |") for row in table[2:])


def test_first_seed_gives_the_same_seeds_the_same_values(tmp_path, capsys):
    """Seeds 1..2 of a run from seed 1 are seeds 1..2 of a run from seed 0: each seed's search is its own."""
    common = ["breakdown", "--source", "LOWPASS", "--duration", "1.5"]
    assert main([*common, "--seeds", "3", "--json"]) == 0
    from_zero = json.loads(capsys.readouterr().out)
    out_json, out_csv, out_md = tmp_path / "b.json", tmp_path / "b.csv", tmp_path / "b.md"
    assert main([*common, "--seeds", "2", "--first-seed", "1", "--json", "-o", str(out_json)]) == 0
    from_one = json.loads(capsys.readouterr().out)
    assert from_one == json.loads(out_json.read_text())
    assert (from_zero["first_seed"], from_zero["seeds_used"]) == (0, [0, 1, 2])
    assert (from_one["first_seed"], from_one["seeds_used"]) == (1, [1, 2])
    assert from_one["fmax"] == from_zero["fmax"][1:] and all(0.05 < v < 200 for v in from_zero["fmax"])
    assert from_one["fmax_median"] == pytest.approx(statistics.median(from_zero["fmax"][1:]))
    assert main([*common, "--seeds", "2", "--first-seed", "1", "-o", str(out_csv)]) == 0
    (row,) = csv.DictReader(out_csv.open())
    assert (row["first_seed"], row["seeds_used"]) == ("1", "1;2")
    assert [float(v) for v in row["fmax_per_seed"].split(";")] == from_one["fmax"]
    assert main([*common, "--seeds", "2", "--first-seed", "1", "-o", str(out_md)]) == 0
    text = out_md.read_text()
    assert "--seeds 2 --first-seed 1 --gesture strokes" in text and text.rstrip().endswith(" | 1 | 1; 2 | seconds |")
    err = capsys.readouterr().err
    assert "seed 2/2: F_max" in err and "seed 3/2" not in err  # progress counts the run's seeds


@pytest.mark.parametrize("argv, words", [
    (["--source", "NOPE"], "--source 'NOPE': allowed are BDIFF"),
    (["--source", "LVT", "--seeds", "0"], "--seeds 0: allowed is a whole number from 1 to 100"),
    (["--source", "LVT", "--seeds", "1000000"], "--seeds 1000000"),
    (["--source", "LVT", "--first-seed", "-1"], "--first-seed -1: allowed is a whole number from 0 to 999995"),
    (["--source", "LVT", "--first-seed", "999996"], "--first-seed 999996: allowed is a whole number from 0 to 999995"),
    (["--source", "LVT", "--seeds", "10", "--first-seed", "999991"], "first seed + seeds at most 1000000"),
    (["--source", "LVT", "--first-seed", "2.5"], "argument --first-seed: invalid int value: '2.5'"),
    (["--source", "LVT", "--first-seed", "two"], "argument --first-seed: invalid int value: 'two'"),
    (["--all", "--rate", "500"], "--rate 500: allowed is a number from 1000 to 96000 Hz"),
    (["--source", "LVT", "--gesture", "wiggle"], "--gesture 'wiggle': allowed are hold, strokes"),
    (["--source", "LVT", "--duration", "0"], "--duration 0.0: allowed is a number of seconds from 0.5 to 60"),
    (["--source", "LVT", "--windows", "ms"], "--windows 'ms': allowed are seconds, samples"),
    (["--source", "LVT", "--all"], "not allowed with argument"),
    (["--source", "LVT", "--latency", "-1"], "--latency -1: allowed is a whole number of samples from 0 to 5000"),
    (["--source", "LVT", "--packet", "0.001"], "--packet 0.001: allowed is a whole number of samples from 0 to 5000 "
                                               "(1 s at 5000 Hz); 0.001 s would be 5"),
    (["--source", "LVT", "--jitter", "nan"], "--jitter nan: allowed is a whole number of samples"),
    (["--source", "LVT", "--latency", "1ms"], "--latency '1ms': allowed is a whole number of samples"),
    ([], "one of the arguments --source --all is required"),
])
def test_bad_input_is_one_line_exit_2_and_no_file(never_broken, tmp_path, capsys, argv, words):
    out = tmp_path / "out.csv"
    assert main(["breakdown", *argv, "-o", str(out)]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("studyapp: error: ") and words in err[0], captured.err
    assert captured.out == "" and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("target, words", [
    ("folder.csv", "is a directory"),
    ("a_file/out.csv", "cannot create a file in"),
    ("out.txt", "allowed suffixes are .csv, .md, .json"),
])
def test_unwritable_output_is_refused_before_the_search(never_broken, tmp_path, capsys, target, words):
    (tmp_path / "folder.csv").mkdir()
    (tmp_path / "a_file").write_text("")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert main(["breakdown", "--source", "LVT", "-o", str(tmp_path / target)]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and words in captured.err and "seed" not in captured.err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before
