"""Recordings made ready for evaluation: reference choice, file order, errors naming the file."""

import numpy as np
import pytest

from studyapp.errors import InputDataError, UserError
from studyapp.evaluation.dataset import Dataset, expand_paths, load_takes, take_from_recording
from tests.evaluation.conftest import synthetic_recording


def test_reference_column_is_selectable():
    rec = synthetic_recording(2.2, duration=0.2)
    lvt = take_from_recording(rec, "r", "lvt")
    true = take_from_recording(rec, "r", "true")
    assert np.array_equal(lvt.reference, rec["velocity_lvt"])
    assert np.array_equal(true.reference, rec["velocity_true"])
    assert np.array_equal(true.velocity, rec["velocity_lvt"])  # the LVT estimator still reads the tachometer
    assert lvt.fmax == 2.2
    with pytest.raises(UserError, match="reference"):
        take_from_recording(rec, "r", "accelerometer")
    del rec.columns["acceleration"]
    with pytest.raises(InputDataError, match="'acceleration'"):
        take_from_recording(rec, "r.npz", "lvt")


def test_directories_expand_in_fmax_order_and_files_are_hashed(tmp_path):
    from studyapp.io.recording import save

    for fmax in (12.1, 0.5, 2.2):
        save(synthetic_recording(fmax, duration=0.1), tmp_path / f"fmax_{fmax}.npz")
    (tmp_path / "index.json").write_text("{}")
    paths = expand_paths([tmp_path])
    assert [p.split("/")[-1] for p in paths] == ["fmax_0.5.npz", "fmax_2.2.npz", "fmax_12.1.npz"]
    takes = load_takes(paths)
    assert [t.fmax for t in takes] == [0.5, 2.2, 12.1]
    assert all(len(t.sha256) == 64 for t in takes) and len({t.sha256 for t in takes}) == 3
    with pytest.raises(InputDataError, match="too short"):
        Dataset(takes, max_lag_s=1.0)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputDataError, match="no recordings"):
        expand_paths([empty])


def test_raw_objectives_follow_eq_28(tmp_path):
    takes = [take_from_recording(synthetic_recording(f, duration=0.3, seed=i), f"r{i}")
             for i, f in enumerate((0.5, 4.4))]
    ds = Dataset(takes, 0.02)
    raw = ds.raw_objectives("LOWPASS", {"cutoff_hz": 300.0})
    errors, delays = ds.delays_and_errors("LOWPASS", {"cutoff_hz": 300.0})
    assert raw.tolist() == [errors[0], delays[0], errors[1], delays[1]]
    fast = Dataset(takes, 0.02, fast=True).raw_objectives("LOWPASS", {"cutoff_hz": 300.0})
    assert np.array_equal(fast, raw)
