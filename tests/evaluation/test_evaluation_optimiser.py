"""The optimiser (steps 1-8 with pure adaptive search) on a synthetic objective with a known optimum."""

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from studyapp.errors import UserError
from studyapp.evaluation.executors import InlineExecutor
from studyapp.evaluation.optimiser import Optimiser
from studyapp.evaluation.search import AdaptiveSearch
from studyapp.evaluation.space import Space
from studyapp.estimators.spec import NYQUIST_FRACTION

RATE = 5000.0


def synthetic_objective(name, params):
    """Raw objectives [E_0, D_0, E_1, D_1] with a known minimum for each estimator."""
    if name == "LEVANTLP":  # optimum: c = 50 m/s^2, cut-off 300 Hz
        a = math.log10(params["c"] / 50.0)
        b = math.log10(params["cutoff_hz"] / 300.0)
        e, d = 1.0 + a * a + b * b, 2.0 + 0.5 * b * b
    elif name == "LEASTSQ":  # optimum: order 3, window 40
        o, w = params["order"], params["window"]
        e, d = 1.0 + (o - 3) ** 2 + ((w - 40) / 20.0) ** 2, 1.0 + ((w - 40) / 30.0) ** 2
    else:
        raise AssertionError(name)
    return [e, d, 1.5 * e, 2.0 * d]


def _optimiser(executor, patience=150, seed=3, **kw):
    spaces = {name: Space(name, RATE) for name in ("LEVANTLP", "LEASTSQ")}
    return Optimiser(spaces, synthetic_objective, executor, patience=patience, seed=seed, **kw)


@pytest.fixture(scope="module")
def inline_result():
    return _optimiser(InlineExecutor()).run()


def test_finds_the_known_optimum(inline_result):
    p = inline_result.params
    assert abs(math.log10(p["LEVANTLP"]["c"] / 50.0)) < 0.05
    assert abs(math.log10(p["LEVANTLP"]["cutoff_hz"] / 300.0)) < 0.05
    assert p["LEASTSQ"]["order"] == 3
    assert abs(p["LEASTSQ"]["window"] - 40) <= 1
    assert isinstance(p["LEASTSQ"]["window"], int)
    # The paper's stopping rule ended the run: each estimator's last `patience` sets failed.
    assert all(n >= 150 for n in inline_result.sets.values())


def test_same_seed_same_result_whatever_the_executor(inline_result):
    with ThreadPoolExecutor(2) as pool:
        threaded = _optimiser(pool).run()
    assert threaded.params == inline_result.params
    assert threaded.objectives == inline_result.objectives
    assert threaded.iterations == inline_result.iterations
    other = _optimiser(InlineExecutor(), seed=4).run()
    assert other.iterations != inline_result.iterations or other.params != inline_result.params


def test_resume_from_checkpoint_gives_the_uninterrupted_result(tmp_path, inline_result):
    path = tmp_path / "run.checkpoint.json"

    def interrupt(iteration, *args, **kwargs):
        if iteration == 40:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _optimiser(InlineExecutor(), checkpoint=path, progress=interrupt).run()
    assert path.is_file()
    resumed = _optimiser(InlineExecutor(), checkpoint=path)
    resumed.resume(path)
    assert resumed.sum.iteration == 40
    result = resumed.run()
    assert result.resumed
    assert result.params == inline_result.params
    assert result.objectives == inline_result.objectives
    assert result.iterations == inline_result.iterations
    with pytest.raises(UserError, match="different run.*patience"):
        _optimiser(InlineExecutor(), patience=99).resume(path)


def test_search_stays_in_range_and_in_natural_scale():
    space = Space("FOAW", RATE)
    search = AdaptiveSearch(space, [0, 1], patience=100)
    windows, margins = [], []
    for _ in range(2000):
        p = search.propose()
        windows.append(p["window"])
        margins.append(p["margin"])
        search.report(p, False)
    assert all(isinstance(w, int) and 1 <= w <= 256 for w in windows)
    assert 1e-9 <= min(margins) and max(margins) <= 1e-1
    # After patience / 2 failures the radius has zoomed in to its floor.
    assert search.radius == pytest.approx(1e-4)
    # Local draws sit around the start (1.001e-4 m) in log scale: half above, half below it.
    assert 0.3 < np.mean(np.array(margins) > 1.001e-4) < 0.7


def test_space_follows_table_2_and_keeps_choices_fixed():
    assert Space("KALMAN", RATE).names == ["q", "r_acc"]
    assert Space("KALMAN", RATE).fixed == {"r_pos": 2e-10, "q_convention": "scaled"}  # Table 1's convention
    assert Space("KALLEV", RATE, tune="all").names == ["q", "r_acc", "r_pos", "c"]
    cutoff = Space("LOWPASS", 5000.0).dims[0]
    assert cutoff.log and cutoff.low == 1.0 and cutoff.high == pytest.approx(NYQUIST_FRACTION * 5000.0)
    window = Space("LEASTSQ", RATE).dims[1]
    assert window.integer and not window.log


def test_search_ranges_narrow_foaw_and_follow_range_options():
    foaw = {d.name: d for d in Space("FOAW", RATE).dims}
    assert (foaw["window"].low, foaw["window"].high) == (2.0, 64.0)  # sizes: a line through at least 2 samples
    assert (foaw["margin"].low, foaw["margin"].high) == (1e-7, 1e-2)
    from studyapp.cli.optimise import parse_ranges

    ranges = parse_ranges(["FOAW.window=20:30", "LOWPASS.cutoff_hz=100:400"])
    space = Space("FOAW", RATE, ranges=ranges["FOAW"])
    assert (space.dims[0].low, space.dims[0].high) == (20.0, 30.0)
    assert space.start["window"] == 20  # Table 1's 17 moved into the range
    assert Space("LOWPASS", RATE, ranges=ranges["LOWPASS"]).dims[0].high == 400.0
    with pytest.raises(UserError, match="LOWPASS.cutoff_hz"):
        Space("LOWPASS", RATE, ranges={"cutoff_hz": (0.5, 100.0)})
    with pytest.raises(UserError, match="NAME.PARAM=LOW:HIGH"):
        parse_ranges(["FOAW.window=20"])


def test_progress_shows_best_objective_per_estimator():
    import io

    from studyapp.evaluation.progress import Progress

    stream = io.StringIO()
    result = _optimiser(InlineExecutor(), patience=10, progress=Progress(stream, interval=0.0)).run()
    lines = stream.getvalue().splitlines()
    assert len(lines) == result.iterations + 1  # one per iteration, and the final one
    last = lines[-1]
    assert last.startswith(f"iter {result.iterations} ")
    for name, value in result.objectives.items():
        assert f"{name} {value:.4g}*" in last
    assert "/" in lines[0]  # sets without improvement while searching
