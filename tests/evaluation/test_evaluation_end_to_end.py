"""A short end-to-end run on real ``studyapp simulate`` output: optimise, evaluate, tradeoff.

Three recordings (1 s at 5 kHz) and a validation set of the same gains; low
patience; every output file is opened and its content checked.
"""

import csv
import hashlib
import json
import tomllib

import numpy as np
import pytest

from studyapp.cli import main

FMAX = (0.5, 2.2, 7.7)
ESTIMATORS = ["LOWPASS", "LEASTSQ", "KALMAN", "COMP1"]


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    root = tmp_path_factory.mktemp("evaluation_e2e")
    for folder, gesture, seed in (("train", "strokes", 0), ("validation", "strokes-validation", 100)):
        (root / folder).mkdir()
        for i, fmax in enumerate(FMAX):
            out = root / folder / f"fmax_{fmax}.npz"
            assert main(["simulate", "--fmax", str(fmax), "--rate", "5000", "--duration", "1",
                         "--gesture", gesture, "--seed", str(seed + i), "-o", str(out)]) == 0
    return root


@pytest.fixture(scope="module")
def optimised(recordings):
    params = recordings / "PARAMS.toml"
    code = main(["optimise", str(recordings / "train"), "-o", str(params), "--patience", "6", "--seed", "1",
                 "--estimators", ",".join(ESTIMATORS), "--workers", "2", "--quiet"])
    assert code == 0
    return params


def _csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_optimise_writes_params_with_provenance(recordings, optimised):
    data = tomllib.loads(optimised.read_text())
    assert [k for k in data if k not in ("provenance", "objective", "conventions")] == ESTIMATORS
    prov = data["provenance"]
    files = sorted((recordings / "train").glob("*.npz"), key=lambda p: float(p.stem[5:]))
    assert prov["recordings"] == [str(p) for p in files]
    assert prov["recording_sha256"] == [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]
    assert prov["seed"] == 1 and prov["patience"] == 6 and prov["reference"] == "lvt"
    assert prov["restarts"] == 2  # the default
    assert prov["studyapp_version"] and prov["numpy_version"] and prov["iterations"] >= 6
    assert 1.0 <= data["LOWPASS"]["cutoff_hz"] <= 2450.0
    assert data["KALMAN"]["q_convention"] == "scaled" and data["KALMAN"]["r_pos"] == 2e-10  # Table 1's convention
    assert data["conventions"]["KALMAN"].startswith("q_convention = scaled: Q = q T Gamma Gamma^T")
    assert isinstance(data["LEASTSQ"]["window"], int) and data["LEASTSQ"]["window"] > data["LEASTSQ"]["order"]
    assert set(data["objective"]) == set(ESTIMATORS)
    checkpoint = json.loads(optimised.with_name("PARAMS.toml.checkpoint.json").read_text())
    assert checkpoint["format"].startswith("studyapp-optimise-checkpoint")
    assert set(checkpoint["searches"]) == set(ESTIMATORS)


def test_resume_of_a_finished_run_gives_the_same_parameters(recordings, optimised, tmp_path):
    again = tmp_path / "again.toml"
    code = main(["optimise", str(recordings / "train"), "-o", str(again), "--patience", "6", "--seed", "1",
                 "--estimators", ",".join(ESTIMATORS), "--workers", "1", "--quiet",
                 "--checkpoint", str(optimised.with_name("PARAMS.toml.checkpoint.json")), "--resume"])
    assert code == 0
    first, second = tomllib.loads(optimised.read_text()), tomllib.loads(again.read_text())
    assert all(first[n] == second[n] for n in ESTIMATORS)
    assert second["provenance"]["resumed"] is True


def test_evaluate_writes_every_output(recordings, optimised, tmp_path, capsys):
    out = tmp_path / "eval"
    code = main(["evaluate", str(recordings / "train"), "--params", str(optimised), "--json", "-o", str(out),
                 "--validation", str(recordings / "validation")])
    assert code == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads((out / "evaluation.json").read_text())
    assert printed == written
    assert set(written["ranking"]) == set(ESTIMATORS)
    objectives = [written["estimators"][n]["objective"] for n in written["ranking"]]
    assert objectives == sorted(objectives)
    for name in ESTIMATORS:
        entry = written["estimators"][name]
        assert len(entry["error"]) == len(entry["delay"]) == len(FMAX)
        assert all(e > 0 for e in entry["error"]) and all(-100 <= d <= 100 for d in entry["delay"])
    assert written["estimators"]["LOWPASS"]["error_pct_lowpass"] == [100.0] * len(FMAX)

    # The numbers are the metric's own on the recording (independent re-computation).
    from studyapp.estimators import create
    from studyapp.evaluation import delay_and_error
    from studyapp.io.recording import load

    params = tomllib.loads(optimised.read_text())["KALMAN"]
    rec = load(recordings / "train" / "fmax_2.2.npz")
    est = create("KALMAN", rec.rate, **params).process(rec["position"], rec["acceleration"], rec["velocity_lvt"])
    d, e = delay_and_error(rec["velocity_lvt"], est, 100)
    assert written["estimators"]["KALMAN"]["delay"][1] == d
    assert written["estimators"]["KALMAN"]["error"][1] == pytest.approx(e)

    rows = _csv(out / "evaluation.csv")
    assert len(rows) == len(ESTIMATORS) * len(FMAX)
    assert {r["estimator"] for r in rows} == set(ESTIMATORS)
    assert {float(r["fmax"]) for r in rows} == set(FMAX)

    tests = _csv(out / "wilcoxon.csv")
    pairs = len(ESTIMATORS) * (len(ESTIMATORS) - 1) // 2
    assert len(tests) == 2 * 3 * pairs  # groups a and b, three measures
    # Every test against scipy's rank-sum on the per-recording values of evaluation.json (group a: all three).
    from scipy import stats

    for t in (t for t in tests if t["group"] == "a" and t["measure"] == "error_pct_lowpass"):
        a, b = (written["estimators"][n]["error_pct_lowpass"] for n in (t["a"], t["b"]))
        if np.ptp(a + b) == 0:
            assert (float(t["statistic"]), float(t["p"])) == (0.0, 1.0)
            continue
        assert float(t["p"]) == pytest.approx(stats.mannwhitneyu(a, b, use_continuity=False).pvalue, rel=1e-9)
        # z, tie-corrected: |z| from the asymptotic p, its sign from U - n_a n_b / 2.
        asymptotic = stats.mannwhitneyu(a, b, method="asymptotic", use_continuity=False)
        z = np.sign(asymptotic.statistic - len(a) * len(b) / 2) * stats.norm.isf(asymptotic.pvalue / 2)
        assert float(t["statistic"]) == pytest.approx(z, rel=1e-6)
    assert {t["group"] for t in tests} == {"a", "b"}

    import matplotlib.image

    for stem in ("fig5a", "fig5b"):
        image = matplotlib.image.imread(out / f"{stem}.png")
        assert image.shape[0] > 200 and image.shape[1] > 400 and np.ptp(image) > 0
        svg = (out / f"{stem}.svg").read_text()
        assert "<svg" in svg and "LOWPASS" in svg

    summary = json.loads((out / "validation.json").read_text())
    assert summary["matched_recordings"] == len(FMAX)
    assert set(summary["estimators"]) == set(ESTIMATORS)
    assert written["validation"] == summary
    rows = _csv(out / "validation.csv")
    assert len(rows) == len(ESTIMATORS) * len(FMAX)
    # Sec. 7.3's differences from the raw E and D of each pair (closed forms), and one pair's raw
    # values from the metric run on the two recordings directly.
    e_train = np.array([float(r["error"]) for r in rows])
    e_valid = np.array([float(r["error_validation"]) for r in rows])
    d_train = np.array([int(r["delay"]) for r in rows])
    d_valid = np.array([int(r["delay_validation"]) for r in rows])
    assert summary["error_difference_pct_mean"] == pytest.approx(np.mean(100 * np.abs(e_valid - e_train) / e_train))
    assert summary["delay_difference_mean"] == pytest.approx(np.mean(np.abs(d_valid - d_train)))
    rec_v = load(recordings / "validation" / "fmax_2.2.npz")
    est_v = create("KALMAN", rec_v.rate, **params).process(rec_v["position"], rec_v["acceleration"],
                                                            rec_v["velocity_lvt"])
    d_v, e_v = delay_and_error(rec_v["velocity_lvt"], est_v, 100)
    (kalman,) = [r for r in rows if r["estimator"] == "KALMAN" and float(r["fmax"]) == 2.2]
    assert float(kalman["error"]) == pytest.approx(e) and float(kalman["error_validation"]) == pytest.approx(e_v)
    assert int(kalman["delay_difference"]) == abs(d_v - d)


def test_tradeoff_writes_table_and_plots(optimised, tmp_path):
    out = tmp_path / "trade"
    code = main(["tradeoff", "--rates", "5000", "10000", "--fmax", "0.5", "2.2", "--duration", "0.5",
                 "--params", str(optimised), "--estimators", "LOWPASS", "LEASTSQ", "--cost-samples", "5000",
                 "-o", str(out)])
    assert code == 0
    rows = _csv(out / "tradeoff.csv")
    assert [(float(r["rate"]), r["estimator"]) for r in rows] == [
        (5000.0, "LOWPASS"), (5000.0, "LEASTSQ"), (10000.0, "LOWPASS"), (10000.0, "LEASTSQ")]
    for r in rows:
        assert float(r["cost_ns_per_sample"]) > 0 and float(r["error_median"]) > 0
        assert float(r["delay_median_us"]) == pytest.approx(1e6 * float(r["delay_median"]) / float(r["rate"]))
        assert r["available"] == "True" and r["parameters_source"] == "params"
    for rate in ("5000.0", "10000.0"):
        assert any(r["pareto"] == "True" for r in rows if r["rate"] == rate)
    # Windows keep their duration: LEASTSQ's window doubles from 5 to 10 kHz.
    w5, w10 = (int(r["parameters"].split("window=")[1]) for r in rows if r["estimator"] == "LEASTSQ")
    assert abs(w10 - 2 * w5) <= 1
    for stem in ("tradeoff", "tradeoff_rates"):
        assert (out / f"{stem}.png").stat().st_size > 1000
        assert "<svg" in (out / f"{stem}.svg").read_text()
