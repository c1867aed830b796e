"""``studyapp bench memory``: its generated inputs read back exactly, and its report's shape (figures never asserted)."""

import json

import numpy as np

from studyapp.cli import main
from studyapp.cli.memory_benchmark import COLUMNS, write_csv, write_npz
from studyapp.io.recording_blocks import RecordingBlocks


def test_generated_npz_is_a_recording_numpy_reads(tmp_path):
    # written a block at a time as a ZIP64 archive; numpy's own reader is the reference
    path = tmp_path / "r.npz"
    write_npz(path, 1000, 5000.0)
    with np.load(path) as data:
        whole = {name: data[name] for name in COLUMNS}
        assert json.loads(str(data["__meta__"]))["rate"] == 5000.0
    np.testing.assert_array_equal(whole["t"], np.arange(1000) / 5000.0)
    with RecordingBlocks(path) as rec:
        assert rec.rate == 5000.0 and rec.length == 1000 and rec.names == list(COLUMNS)
        blocks = list(rec.blocks(300))
    assert [len(b["t"]) for b in blocks] == [300, 300, 300, 100]
    for name in COLUMNS:
        np.testing.assert_array_equal(np.concatenate([b[name] for b in blocks]), whole[name])


def test_generated_csv_has_the_rows_asked_for(tmp_path):
    path = tmp_path / "s.csv"
    write_csv(path, 1000, 5000.0)
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    assert table.shape == (1000, 3) and np.isfinite(table).all()


def test_bench_memory_reports_both_inputs(tmp_path, capsys):
    assert main(["bench", "memory", "--rows", "200", "--dir", str(tmp_path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["rows"] == 200 and [r["input"] for r in report["results"]] == ["csv", "npz"]
    for r in report["results"]:
        assert r["input_bytes"] > 200 * 3 * 10 and r["peak_rss_bytes"] > 0
        assert r["peak_over_input"] == round(r["peak_rss_bytes"] / r["input_bytes"], 3)
    assert list(tmp_path.iterdir()) == []  # the temporary inputs are gone


def test_bench_memory_simulate_reports_each_duration(tmp_path, capsys):
    argv = ["bench", "memory", "--command", "simulate", "--rate", "5000", "--duration", "0.05", "0.1",
            "--dir", str(tmp_path), "--json"]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["command"] == "simulate" and report["rate"] == 5000.0 and report["format"] == "npz"
    assert [r["duration"] for r in report["results"]] == [0.05, 0.1]
    for r in report["results"]:
        assert r["output_bytes"] > r["duration"] * 5000 * 9 * 8 and r["peak_rss_bytes"] > 0
    assert list(tmp_path.iterdir()) == []


def test_bench_memory_simulate_refuses_a_bad_duration_before_work(tmp_path, capsys):
    argv = ["bench", "memory", "--command", "simulate", "--duration", "1", "0", "--dir", str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--duration 0: allowed" in err
    assert list(tmp_path.iterdir()) == []
