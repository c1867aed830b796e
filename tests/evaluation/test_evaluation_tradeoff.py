"""``studyapp tradeoff``: re-tuning per rate, rates 1-96 kHz, error and delay beside cost, labels that never overlap.

Short runs on real ``studyapp.model.simulate`` output (a few tenths of a
second per short_recording, tiny patience, two or three estimators where the test
allows); the figures are checked on the command's own output for all thirteen
estimators with matplotlib's renderer (tests/figure_checks.py).
"""

import csv
import json
import warnings

import numpy as np
import pytest

from studyapp.cli import main
from tests.evaluation.conftest import fails_with_one_line
from tests.figure_checks import text_overlaps, texts_outside


def _csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _rows(path):
    """The rows of tradeoff.json, with JSON's null (a non-finite number) back as NaN."""
    rows = json.loads((path / "tradeoff.json").read_text())["rows"]
    return [{k: float("nan") if v is None else v for k, v in r.items()} for r in rows]




# -- the label layout ---------------------------------------------------------------------------


def _crowded_axes():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rng = np.random.default_rng(3)
    # Thirteen points: three coincident pairs and a tight cluster, as tuned estimators often give.
    x = np.concatenate([[10.0, 10.0, 40.0, 40.0, 100.0, 100.0], 20.0 + rng.uniform(0, 2, 7)])
    y = np.concatenate([[0.6, 0.6, 0.3, 0.3, 0.2, 0.2], 0.5 + rng.uniform(0, 0.03, 7)])
    names = ["LOWPASS", "COMP2", "KALFOAW", "KALFOAWACC", "KALLEV", "KALLEVACC", "LEASTSQ", "FOAW", "LEVANT",
             "LEVANTLP", "KALPOS", "KALMAN", "COMP1"]
    fig, ax = plt.subplots(figsize=(4.0, 3.5))
    ax.scatter(x, y)
    ax.set_xscale("log")
    legend = ax.plot(x[:2], y[:2], label="Pareto front")[0].axes.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig, ax, list(zip(x, y)), names, legend


def test_labels_never_overlap_stay_inside_and_are_deterministic():
    from studyapp.evaluation.labels import place_labels

    boxes = []
    for _ in range(2):
        fig, ax, xy, names, legend = _crowded_axes()
        labels = place_labels(ax, xy, names, avoid=[legend])
        assert all(label is not None for label in labels)
        assert [label.get_text() for label in labels] == names
        assert text_overlaps(fig) == []
        assert texts_outside(fig) == []
        renderer = fig.canvas.get_renderer()
        inside = ax.get_window_extent(renderer)
        for label in labels:
            b = label.get_window_extent(renderer)
            assert inside.x0 <= b.x0 and b.x1 <= inside.x1 and inside.y0 <= b.y0 and b.y1 <= inside.y1
        boxes.append([tuple(label.get_window_extent(renderer).bounds) for label in labels])
        import matplotlib.pyplot as plt

        plt.close(fig)
    assert boxes[0] == boxes[1]


def test_plain_annotations_of_the_same_points_do_overlap():
    """The check above is not vacuous: labels at a fixed offset (the old tradeoff.png) collide."""
    fig, ax, xy, names, _ = _crowded_axes()
    for (x, y), name in zip(xy, names):
        ax.annotate(name, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    assert text_overlaps(fig) != []


# -- search spaces and starts -------------------------------------------------------------------


def test_narrowed_window_ranges_keep_their_duration():
    from studyapp.evaluation.retune import search_spaces

    def foaw_window(rate, windows="seconds"):
        dims = {d.name: d for d in search_spaces(["FOAW"], rate, windows)["FOAW"].dims}
        return dims["window"].low, dims["window"].high

    assert foaw_window(5000.0) == (2, 64)  # sizes: a line through at least 2 samples
    assert foaw_window(10000.0) == (2, 128)
    assert foaw_window(1000.0) == (2, 13)  # 64 / 5 = 12.8
    assert foaw_window(40000.0) == (2, 256)  # 512, capped at FOAW's own range
    assert foaw_window(40000.0, "samples") == (2, 64)


def test_optimiser_starts_from_the_given_sets():
    from studyapp.evaluation.executors import InlineExecutor
    from studyapp.evaluation.optimiser import Optimiser
    from studyapp.evaluation.space import Space

    seen = []

    def objective(name, params):
        seen.append((name, dict(params)))
        return [abs(np.log(params["cutoff_hz"] / 300.0))]

    spaces = {"LOWPASS": Space("LOWPASS", 5000.0), "COMP1": Space("COMP1", 5000.0)}
    starts = {"LOWPASS": {"cutoff_hz": 1000.0}}
    Optimiser(spaces, objective, InlineExecutor(), patience=2, seed=0, starts=starts).run()
    first = {name: params for name, params in seen[:2]}
    assert first == {"LOWPASS": {"cutoff_hz": 1000.0}, "COMP1": {"cutoff_hz": 317.0}}  # COMP1: Table 1


def test_make_dataset_passes_the_delay_method():
    from studyapp.evaluation import simulated

    for method in ("paper", "normalised"):
        recipe = simulated.SimulatedSet(rate=5000.0, fmax_values=(2.2,), duration=0.1, delay_method=method)
        assert recipe.load().delay_method == method


# -- the command --------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def extremes(tmp_path_factory):
    """A tuned run at 3 kHz (the lowest the 440 Hz string plays, playable.py) and 96 kHz, with warnings turned into errors."""
    out = tmp_path_factory.mktemp("tradeoff_extremes") / "trade"
    argv = ["tradeoff", "--tune", "--patience", "2", "--rates", "3000", "96000", "--fmax", "2.2",
            "--duration", "0.1", "--estimators", "LOWPASS,COMP2,LEASTSQ", "--cost-samples", "1000",
            "--workers", "1", "-o", str(out)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code = main(argv)
    return code, out


def test_3khz_and_96khz_run_and_report_what_is_not_available(extremes, capsys):
    code, out = extremes
    assert code == 0
    document = json.loads((out / "tradeoff.json").read_text())
    assert document["not_available"] == [{
        "rate": 3000.0, "estimator": "COMP2",
        "reason": "COMP2 parameter 'hpf_hz' = 2254.0: allowed is a number from 1 to 1470 Hz"}]
    rows = _csv(out / "tradeoff.csv")
    assert [(r["rate"], r["estimator"], r["available"]) for r in rows] == [
        ("3000.0", "LOWPASS", "True"), ("3000.0", "COMP2", "False"), ("3000.0", "LEASTSQ", "True"),
        ("96000.0", "LOWPASS", "True"), ("96000.0", "COMP2", "True"), ("96000.0", "LEASTSQ", "True")]
    missing = rows[1]
    assert "1470 Hz" in missing["reason"] and missing["cost_ns_per_sample"] == "" and missing["parameters"] == ""
    assert set(document["tuning"]) == {"3000", "96000"}
    assert all(run["iterations"] >= 2 for run in document["tuning"].values())
    prov = document["provenance"]
    assert prov["tune"] is True and prov["patience"] == 2 and prov["parameters"] == "tuned at each rate"
    for stem in ("tradeoff", "tradeoff_rates", "pareto_3000Hz", "pareto_96000Hz"):
        assert (out / f"{stem}.png").stat().st_size > 1000 and "<svg" in (out / f"{stem}.svg").read_text()


def test_delay_is_reported_in_samples_and_microseconds_and_matches_the_metric(extremes):
    """The 3 kHz LOWPASS row, recomputed independently: simulate, run the estimator, measure."""
    from studyapp.estimators import create
    from studyapp.evaluation import delay_and_error
    from studyapp.model.simulate import simulate

    _, out = extremes
    rows = {(r["rate"], r["estimator"]): r for r in _rows(out)}
    for r in rows.values():
        if r["available"]:
            assert r["delay_median_us"] == pytest.approx(r["delay_median"] / r["rate"] * 1e6)
            assert r["parameters_source"] == "tuned"
    row = rows[(3000.0, "LOWPASS")]
    assert row["parameters"] != {"cutoff_hz": 256.0}  # moved off Table 1
    rec = simulate(2.2, rate=3000.0, duration=0.1, seed=0)
    est = create("LOWPASS", 3000.0, **row["parameters"]).process(
        rec["position"], rec["acceleration"], rec["velocity_lvt"])
    method = json.loads((out / "tradeoff.json").read_text())["provenance"]["delay_method"]
    assert method == "normalised"

    d, e = delay_and_error(rec["velocity_lvt"], est, 60, method=method)  # max_lag: 0.02 s at 3 kHz
    assert row["delay_median"] == d and row["error_median"] == pytest.approx(e, rel=1e-12)


def test_progress_and_unavailable_estimators_on_screen(tmp_path, capsys):
    code = main(["tradeoff", "--tune", "--patience", "1", "--rates", "3000", "--fmax", "2.2", "--duration", "0.05",
                 "--estimators", "LOWPASS,COMP2", "--cost-samples", "1000", "--workers", "1",
                 "-o", str(tmp_path / "t")])
    captured = capsys.readouterr()
    assert code == 0
    assert "3000 Hz: COMP2 not available: COMP2 parameter 'hpf_hz' = 2254.0" in captured.out
    assert "tradeoff: 3000 Hz (1/1): tuning 1 estimators (patience 1)" in captured.err
    assert "tradeoff: 3000 Hz: tuning: iter" in captured.err
    assert "Traceback" not in captured.err


@pytest.mark.filterwarnings("error")
def test_a_rate_where_no_estimator_is_available_still_gets_its_outputs(tmp_path, monkeypatch):
    from studyapp.evaluation import figures

    made = {}
    monkeypatch.setattr(figures, "written", lambda fig, stem: made.setdefault(stem.name, fig))
    out = tmp_path / "t"
    assert main(["tradeoff", "--rates", "3000", "5000", "--estimators", "COMP2", "--fmax", "1", "--duration", "0.1",
                 "--cost-samples", "1000", "-o", str(out)]) == 0
    rows = _csv(out / "tradeoff.csv")
    assert [(r["rate"], r["available"]) for r in rows] == [("3000.0", "False"), ("5000.0", "True")]
    assert sorted(made) == ["pareto_3000Hz", "pareto_5000Hz", "tradeoff", "tradeoff_rates"]
    for fig in made.values():
        assert text_overlaps(fig) == [] and texts_outside(fig) == []


def test_tune_gives_the_parameters_of_optimise_on_the_same_recordings(tmp_path):
    """Re-tuning at a rate is the paper's optimiser on that rate's data: same result as simulate + optimise."""
    import tomllib

    names = "LOWPASS,COMP1"  # no windows, so the start is Table 1 for both commands
    out = tmp_path / "trade"
    assert main(["tradeoff", "--tune", "--patience", "3", "--seed", "0", "--rates", "10000", "--fmax", "0.5", "2.2",
                 "--duration", "0.3", "--estimators", names, "--cost-samples", "1000", "--workers", "1",
                 "-o", str(out)]) == 0
    for i, fmax in enumerate((0.5, 2.2)):
        assert main(["simulate", "--fmax", str(fmax), "--rate", "10000", "--duration", "0.3", "--seed", str(i),
                     "-o", str(tmp_path / f"fmax_{fmax}.npz")]) == 0
    params = tmp_path / "P.toml"
    assert main(["optimise", str(tmp_path / "fmax_0.5.npz"), str(tmp_path / "fmax_2.2.npz"), "-o", str(params),
                 "--estimators", names, "--patience", "3", "--seed", "0", "--workers", "1", "--restarts", "0",
                 "--ridge", "0", "--quiet"]) == 0  # tradeoff --tune: no restarts (patience 20: lanes of 5 sets), no ridge
    tuned = tomllib.loads(params.read_text())
    rows = {r["estimator"]: r for r in _rows(out)}
    assert {n: rows[n]["parameters"] for n in ("LOWPASS", "COMP1")} == {n: tuned[n] for n in ("LOWPASS", "COMP1")}


def test_figures_of_all_estimators_have_no_overlapping_text(tmp_path, monkeypatch):
    """The figures exactly as the command makes them (caught before saving), for the paper's thirteen."""
    import matplotlib.pyplot as plt

    from studyapp.evaluation import figures

    made = {}
    monkeypatch.setattr(figures, "written", lambda fig, stem: made.setdefault(stem.name, fig))
    out = tmp_path / "trade"
    assert main(["tradeoff", "--rates", "5000", "20000", "--fmax", "0.5", "2.2", "--duration", "0.2",
                 "--cost-samples", "1000", "--delay", "paper", "-o", str(out)]) == 0
    assert json.loads((out / "tradeoff.json").read_text())["provenance"]["delay_method"] == "paper"
    rows = _rows(out)
    names = {r["estimator"] for r in rows}
    assert len(names) == 13 and all(r["parameters_source"] == "table1" for r in rows)
    assert sorted(made) == ["pareto_20000Hz", "pareto_5000Hz", "tradeoff", "tradeoff_rates"]
    labelled = {"tradeoff": 2, "pareto_5000Hz": 1, "pareto_20000Hz": 1, "tradeoff_rates": 0}
    for stem, fig in made.items():
        assert text_overlaps(fig) == [], stem
        assert texts_outside(fig) == [], stem
        for ax in fig.axes[:labelled[stem]]:
            assert sorted(t.get_text() for t in ax.texts) == sorted(names)  # every estimator labelled once
        plt.close(fig)


def test_bad_options(tmp_path, capsys):
    out = tmp_path / "t"
    params = tmp_path / "P.toml"
    params.write_text("[LOWPASS]\ncutoff_hz = 300\n")
    fails_with_one_line(capsys, ["tradeoff", "--tune", "--params", str(params), "-o", str(out)], "--params")
    fails_with_one_line(capsys, ["tradeoff", "--tune", "--patience", "0", "-o", str(out)], "--patience 0")
    fails_with_one_line(capsys, ["tradeoff", "--patience", "5", "-o", str(out)], "only with --tune")
    fails_with_one_line(capsys, ["tradeoff", "--workers", "2", "-o", str(out)], "only with --tune")
    fails_with_one_line(capsys, ["tradeoff", "--delay", "late", "-o", str(out)], "--delay")
    fails_with_one_line(capsys, ["tradeoff", "--rates", "3000", "4000", "--estimators", "COMP2", "-o", str(out)],
           "no estimator is available at 3000, 4000 Hz: COMP2 parameter 'hpf_hz'")
    fails_with_one_line(capsys, ["tradeoff", "--rates", "1000", "-o", str(out)], "rate 1000 Hz with f0 440 Hz")
    assert not out.exists()
