"""Recordings: round trips through .h5, .npz and .csv; bad files; the simulate and simulate-set commands."""

import json

import numpy as np
import pandas as pd
import pytest

from studyapp.cli import main
from studyapp.errors import InputDataError, UserError
from studyapp.model.data_set import PAPER_FMAX
from studyapp.model.simulate import simulate
from studyapp.io.recording import COLUMNS, Recording, load, save


@pytest.fixture(scope="module")
def rec():
    return simulate(2.2, duration=0.2, source="LVT", seed=5)


def test_simulate_columns_and_metadata(rec):
    assert list(rec.columns) == list(COLUMNS)
    assert len(rec) == 1000 and rec.rate == 5000.0
    np.testing.assert_allclose(np.diff(rec["t"]), 1 / 5000.0)
    for key in ("fmax", "rate", "source", "gesture", "f0", "seed", "duration", "version"):
        assert key in rec.meta
    assert rec.meta["fmax"] == 2.2 and rec.meta["source"] == "LVT" and rec.meta["seed"] == 5
    assert np.std(rec["acceleration"]) > 0.1  # the accelerometer is always simulated for recordings


@pytest.mark.parametrize("suffix", [".h5", ".npz", ".csv"])
def test_round_trip(rec, tmp_path, suffix):
    path = tmp_path / f"r{suffix}"
    save(rec, path)
    back = load(path)
    assert back.rate == rec.rate
    for c in COLUMNS:
        np.testing.assert_array_equal(back[c], rec[c], err_msg=c)
    if suffix == ".csv":
        return  # plain CSV: no metadata, the rate comes from t
    for key in ("fmax", "source", "gesture", "f0", "seed", "duration", "version"):
        assert back.meta[key] == rec.meta[key]


def test_csv_is_plain_for_pandas(rec, tmp_path):
    path = tmp_path / "r.csv"
    save(rec, path)
    table = pd.read_csv(path)
    assert list(table.columns) == list(COLUMNS)
    np.testing.assert_array_equal(table["position"].to_numpy(), rec["position"])


def test_bad_files(tmp_path):
    with pytest.raises(InputDataError, match="no such file"):
        load(tmp_path / "missing.npz")
    with pytest.raises(UserError, match="unknown recording format"):
        load(tmp_path / "x.wav")
    bad = tmp_path / "bad.csv"
    bad.write_text("t,position\n0,1\n")
    with pytest.raises(InputDataError, match="bad.csv.*lacks the column"):
        load(bad)
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5")
    with pytest.raises(InputDataError, match="junk.h5"):
        load(junk)
    cells = tmp_path / "cells.csv"
    cells.write_text(",".join(COLUMNS) + "\n" + ",".join(["1"] * 8 + ["x"]) + "\n")
    with pytest.raises(InputDataError, match="cells.csv"):
        load(cells)


def test_save_is_atomic(tmp_path):
    broken = Recording(5000.0, {"t": np.zeros(3)})  # a CSV needs every column
    with pytest.raises(InputDataError):
        save(broken, tmp_path / "x.csv")
    assert list(tmp_path.iterdir()) == []


def test_cli_simulate_and_bad_input(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["simulate", "--fmax", "1.4", "--duration", "0.1", "--source", "KALLEV", "-o", str(out)]) == 0
    back = load(out)
    assert back.rate == pytest.approx(5000.0) and len(back) == 500
    assert out.read_text().splitlines()[0] == ",".join(COLUMNS)
    assert main(["simulate", "--fmax", "1.4", "--duration", "0.1", "--source", "KALLEV", "-o", str(tmp_path / "s.h5")]) == 0
    assert load(tmp_path / "s.h5").meta["source"] == "KALLEV"
    for args in (["--source", "NOPE"], ["--gesture", "waltz"], ["--rate", "200"], ["--fmax", "-1"]):
        target = tmp_path / "bad.npz"
        assert main(["simulate", "--duration", "0.1", *args, "-o", str(target)]) == 2
        assert not target.exists()
        err = capsys.readouterr().err.strip().splitlines()
        assert err[-1].startswith("studyapp: error:") and "Traceback" not in "".join(err)
    assert main(["simulate", "--duration", "0.1", "-o", str(tmp_path / "x.wav")]) == 2
    assert not (tmp_path / "x.wav").exists()


def test_cli_simulate_set(tmp_path, capsys):
    out = tmp_path / "set"
    assert main(["simulate-set", "-o", str(out), "--duration", "0.05"]) == 0
    index = json.loads((out / "index.json").read_text())
    assert [f["fmax"] for f in index["files"]] == PAPER_FMAX
    assert (out / "fmax_0.3.npz").exists() and (out / "fmax_12.1.npz").exists()
    assert len(list(out.glob("fmax_*.npz"))) == 15
    r = load(out / "fmax_5.5.npz")
    assert r.meta["fmax"] == 5.5 and r.meta["source"] == "LVT" and r.rate == 5000.0
    assert "15/15" in capsys.readouterr().err
    val = tmp_path / "val"
    assert main(["simulate-set", "-o", str(val), "--validation", "--duration", "0.05"]) == 0
    v = load(val / "fmax_5.5.npz")
    assert v.meta["seed"] != r.meta["seed"] and v.meta["gesture"] != r.meta["gesture"]
