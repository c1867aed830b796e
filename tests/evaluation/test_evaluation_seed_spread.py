"""``evaluate --params A.toml B.toml ...``: every file's F_g under one common scale, and its spread."""

import csv

import numpy as np

from studyapp.cli import main
from studyapp.evaluation import params_file
from studyapp.evaluation.dataset import Dataset, load_takes
from studyapp.evaluation.normalisation import bounds, global_objective


def _write(path, seed, lowpass_hz):
    params = {"LOWPASS": {"cutoff_hz": lowpass_hz}, "LEVANT": {"c": 500.0}}
    params_file.write(path, params, provenance={"seed": seed})


def test_seed_spread_scores_every_file_under_one_scale(tmp_path, short_recording, capsys):
    _write(tmp_path / "a.toml", 0, 256.0)
    _write(tmp_path / "b.toml", 1, 400.0)
    _write(tmp_path / "c.toml", 2, 256.0)
    out = tmp_path / "out"
    assert main(["evaluate", str(short_recording), "--params", str(tmp_path / "a.toml"), str(tmp_path / "b.toml"),
                 str(tmp_path / "c.toml"), "-o", str(out)]) == 0
    assert "spread" in capsys.readouterr().out
    with open(out / "seed_spread.csv", newline="") as f:
        rows = {r["estimator"]: r for r in csv.DictReader(f)}
    assert set(rows) == {"LOWPASS", "LEVANT"}
    assert float(rows["LEVANT"]["spread_pct"]) == 0.0  # the same parameters in every file
    # LOWPASS: recomputed by hand from the raw objectives of the six (file, estimator) pairs
    data = Dataset(load_takes([short_recording]), 0.02)
    raws = [data.raw_objectives(n, {"cutoff_hz": hz} if n == "LOWPASS" else {"c": 500.0})
            for hz in (256.0, 400.0, 256.0) for n in ("LOWPASS", "LEVANT")]
    offsets, scales = bounds(np.array(raws))
    f = [global_objective(raws[i], offsets, scales) for i in (0, 2, 4)]
    assert np.allclose([float(rows["LOWPASS"][f"F_g seed {s}"]) for s in (0, 1, 2)], f, rtol=1e-12)
    assert np.isclose(float(rows["LOWPASS"]["spread"]), max(f) - min(f), rtol=1e-12)
    lowpass = np.array([raws[i] for i in (0, 2, 4)])
    gaps = lowpass[:, 1::2].max(axis=0) - lowpass[:, 1::2].min(axis=0)
    assert int(rows["LOWPASS"]["delays_apart"]) == np.count_nonzero(gaps)
    assert int(rows["LOWPASS"]["max_delay_apart"]) == gaps.max()
    errors = lowpass[:, 0::2]
    assert np.isclose(float(rows["LOWPASS"]["error_spread_pct"]),
                      100 * np.max((errors.max(axis=0) - errors.min(axis=0)) / errors.min(axis=0)), rtol=1e-12)
    assert rows["LEVANT"]["delays_apart"] == "0" and float(rows["LEVANT"]["error_spread_pct"]) == 0.0
    if min(f) != 0:
        assert np.isclose(float(rows["LOWPASS"]["spread_pct"]), 100 * (max(f) - min(f)) / abs(min(f)), rtol=1e-12)
    else:  # the best pair on every objective scores 0: no relative spread
        assert rows["LOWPASS"]["spread_pct"] == ""


def test_one_params_file_writes_no_spread(tmp_path, short_recording):
    _write(tmp_path / "a.toml", 0, 256.0)
    out = tmp_path / "out"
    assert main(["evaluate", str(short_recording), "--params", str(tmp_path / "a.toml"), "-o", str(out)]) == 0
    assert not (out / "seed_spread.csv").exists()
