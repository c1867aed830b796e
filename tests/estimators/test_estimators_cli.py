"""`studyapp estimators`, `estimate`, `bench estimators` and `demo` from the command line."""

import csv
import json

import numpy as np
import pytest
from scipy import signal

from studyapp.cli import main
from studyapp.synthetic import stick_slip

RATE = 5000.0


@pytest.fixture(scope="module")
def samples(tmp_path_factory):
    sig = stick_slip(RATE, 0.2, seed=3)
    path = tmp_path_factory.mktemp("in") / "samples.csv"
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "position", "acceleration", "velocity"])
        for row in zip(sig["t"], sig["position"], sig["acceleration"], sig["velocity_lvt"]):
            w.writerow([repr(float(c)) for c in row])
    return path, sig


def one_line_error(capsys, argv):
    code = main(argv)
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("studyapp: error: ") and "Traceback" not in err
    return err


def test_estimators_json_is_the_table(capsys):
    assert main(["estimators", "--json"]) == 0
    table = json.loads(capsys.readouterr().out)
    assert [d["name"] for d in table][:3] == ["BDIFF", "LOWPASS", "LEASTSQ"] and table[-1]["name"] == "LVT"
    lowpass = table[1]
    assert lowpass["inputs"] == ["position"]
    assert lowpass["parameters"][0]["name"] == "cutoff_hz" and lowpass["parameters"][0]["default"] == 256.0


def test_estimate_appends_velocity_estimate(samples, tmp_path, capsys):
    path, sig = samples
    out = tmp_path / "out.csv"
    assert main(["estimate", str(path), "--estimator", "LOWPASS", "--rate", "5000", "--set", "cutoff_hz=300",
                 "-o", str(out)]) == 0
    with open(out) as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["t", "position", "acceleration", "velocity", "velocity_estimate"]
    got = np.array([float(r["velocity_estimate"]) for r in rows])
    x = sig["position"]
    expected = signal.sosfilt(signal.butter(2, 300.0, fs=RATE, output="sos"), np.diff(x, prepend=x[0]) * RATE)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)
    # the input's cells are kept as written
    assert rows[5]["position"] == repr(float(x[5]))


def test_estimate_to_stdout(samples, capsys):
    path, sig = samples
    assert main(["estimate", str(path), "--estimator", "LVT", "--rate", "5000"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith(",velocity_estimate") and len(lines) == len(sig["t"]) + 1
    assert float(lines[1].split(",")[-1]) == pytest.approx(sig["velocity_lvt"][0])


def test_estimate_reads_a_recording(tmp_path, capsys):
    out = tmp_path / "rec.npz"
    assert main(["simulate", "--fmax", "1", "--rate", "5000", "--duration", "0.1", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["estimate", str(out), "--estimator", "KALLEV", "--rate", "5000", "-o", str(tmp_path / "e.csv")]) == 0
    with open(tmp_path / "e.csv") as f:
        rows = list(csv.DictReader(f))
    assert "velocity_lvt" in rows[0] and "velocity_estimate" in rows[0] and len(rows) == 500
    assert all(np.isfinite(float(r["velocity_estimate"])) for r in rows)


@pytest.mark.parametrize(
    "content, argv, fragment",
    [
        ("speed\n1\n", ["--estimator", "LOWPASS"], "column 'position' missing"),
        ("position\n0.1\nabc\n", ["--estimator", "LOWPASS"], "line 3, column 'position': 'abc' is not a number"),
        ("position\n0.1\n0.2\n", ["--estimator", "KALMAN"], "column 'acceleration' missing"),
        ("position\n0.1\n", ["--estimator", "NOPE"], "unknown estimator 'NOPE'"),
        ("position\n0.1\n", ["--estimator", "LOWPASS", "--set", "cutof=3"], "has no parameter 'cutof'"),
        ("position\n0.1\n", ["--estimator", "LOWPASS", "--set", "cutoff_hz=9000"], "'cutoff_hz' = 9000"),
        ("position\n0.1\n", ["--estimator", "LOWPASS", "--set", "oops"], "expected KEY=VALUE"),
        ("position\n", ["--estimator", "LOWPASS"], "no samples below the header"),
    ],
)
def test_estimate_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys, content, argv, fragment):
    path = tmp_path / "in.csv"
    path.write_text(content)
    out = tmp_path / "out.csv"
    err = one_line_error(capsys, ["estimate", str(path), "--rate", "5000", *argv, "-o", str(out)])
    assert fragment in err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def test_estimate_rate_out_of_range(samples, capsys):
    err = one_line_error(capsys, ["estimate", str(samples[0]), "--estimator", "BDIFF", "--rate", "200000"])
    assert "--rate 200000: allowed is a number from 1000 to 96000 Hz" in err


def test_missing_input_file(tmp_path, capsys):
    err = one_line_error(capsys, ["estimate", str(tmp_path / "none.csv"), "--estimator", "BDIFF", "--rate", "5000"])
    assert "none.csv: no such file" in err


def test_bench_json_shape(capsys):
    # the shape only: the figures themselves are measured by `studyapp bench`, never asserted
    assert main(["bench", "estimators", "--rate", "5000", "--json", "--samples", "2000"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["rate"] == 5000.0 and result["samples"] == 2000 and result["bank_ns_per_sample"] > 0
    assert len(result["estimators"]) == 15 and result["unavailable"] == {}
    assert result["bank"] == [name for name in result["estimators"] if name != "LVT"]
    for figures in result["estimators"].values():
        assert set(figures) == {"block_ns_per_sample", "stream_ns_per_sample"}
        assert all(v > 0 for v in figures.values())


def test_demo_prints_error_and_delay_for_every_estimator(capsys):
    assert main(["demo", "--seconds", "0.5"]) == 0
    out = capsys.readouterr().out
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines()[3:-1]}
    assert len(rows) == 15
    assert float(rows["LVT"][1]) < float(rows["BDIFF"][1])  # the tachometer beats a raw difference
