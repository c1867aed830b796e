"""``studyapp estimate`` reads and writes in blocks (issue 14, item 8): the output equals one whole-array pass.

The reference is ``Estimator.process`` on the whole columns at once (the
block/stream contract of ``studyapp.estimators``); the command runs with a
block of 7 samples, so every block boundary, and the last short block, is crossed.
"""

import csv

import numpy as np
import pytest

from studyapp import estimators
from studyapp.cli import main
from studyapp.io.recording import Recording, save
from studyapp.synthetic import stick_slip

RATE = 5000.0


@pytest.fixture(scope="module")
def signal():
    return stick_slip(RATE, 0.02, seed=5)  # 100 samples


def _estimates(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return rows, np.array([float(r["velocity_estimate"]) for r in rows])


def _whole(name, sig, velocity="velocity_lvt"):
    return estimators.create(name, RATE).process(sig["position"], sig["acceleration"], sig[velocity])


@pytest.mark.parametrize("name", ["KALLEV", "FOAW", "LOWPASS"])
def test_csv_in_blocks_equals_the_whole_array(name, signal, tmp_path):
    path = tmp_path / "in.csv"
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["position", "acceleration", "velocity"])
        w.writerows(zip(*(signal[k].tolist() for k in ("position", "acceleration", "velocity_lvt"))))
        w.writerow(["1e-3", "0", "0"])  # a cell in the user's own format
    for block in ("7", "100000"):
        out = tmp_path / f"out{block}.csv"
        assert main(["estimate", str(path), "--estimator", name, "--rate", "5000", "--block", block, "-o", str(out)]) == 0
    rows, got = _estimates(tmp_path / "out7.csv")
    whole = {k: np.append(signal[k], v) for k, v in (("position", 1e-3), ("acceleration", 0), ("velocity_lvt", 0))}
    assert np.array_equal(got, _whole(name, whole))
    assert (tmp_path / "out7.csv").read_bytes() == (tmp_path / "out100000.csv").read_bytes()
    assert rows[-1]["position"] == "1e-3"  # the input's cells kept as written


@pytest.mark.parametrize("suffix", [".npz", ".h5"])
def test_recording_in_blocks_equals_the_whole_array_at_its_own_rate(suffix, signal, tmp_path):
    path = tmp_path / f"rec{suffix}"
    save(Recording(RATE, signal, {"fmax": 1.0}), path)
    out = tmp_path / "out.csv"
    assert main(["estimate", str(path), "--estimator", "KALLEV", "--block", "7", "-o", str(out)]) == 0
    rows, got = _estimates(out)
    assert np.array_equal(got, _whole("KALLEV", signal))
    assert sorted(rows[0]) == sorted([*signal, "velocity_estimate"]) and float(rows[99]["t"]) == signal["t"][99]


def test_recording_rate_from_t_when_metadata_lacks_it(signal, tmp_path):
    # an npz written by hand: no __meta__, the rate is (n - 1) / (t[-1] - t[0])
    path = tmp_path / "plain.npz"
    np.savez(path, **signal)
    out = tmp_path / "out.csv"
    assert main(["estimate", str(path), "--estimator", "BDIFF", "--rate", "5000", "-o", str(out)]) == 0
    x = signal["position"]
    np.testing.assert_allclose(_estimates(out)[1][1:], np.diff(x) * RATE, rtol=1e-9)


def test_a_different_rate_is_refused(signal, tmp_path, capsys):
    path = tmp_path / "rec.npz"
    save(Recording(RATE, signal, {}), path)
    assert main(["estimate", str(path), "--estimator", "BDIFF", "--rate", "10000", "-o", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"studyapp: error: --rate 10000: {path} was recorded at 5000 Hz: allowed is to leave out --rate "
                   "or give 5000")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.npz"]


def test_a_byte_order_mark_is_accepted(tmp_path):
    # Excel's "CSV UTF-8" starts with EF BB BF; BDIFF of 0, 1 mm, 3 mm at 1 kHz is 0, 1, 2 m/s
    path = tmp_path / "excel.csv"
    path.write_bytes(b"\xef\xbb\xbfposition\r\n0\r\n0.001\r\n0.003\r\n")
    out = tmp_path / "out.csv"
    assert main(["estimate", str(path), "--estimator", "BDIFF", "--rate", "1000", "-o", str(out)]) == 0
    rows, got = _estimates(out)
    assert list(rows[0]) == ["position", "velocity_estimate"]
    np.testing.assert_allclose(got, [0.0, 1.0, 2.0], rtol=1e-12)
