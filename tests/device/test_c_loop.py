"""The loop in C (firmware/studyapp_loop.c, through studyapp/device/c_loop.py) equals the numba loop bit for bit.

The numba side is the host's shadow of a device loop run as the model (device/shadow.py run_rows, MODEL):
control.sample for every sample of a block and every other estimator on it, the path of a device without
truth (tests/device/test_shadow_rows.py holds it equal to Control.sample called sample by sample). Both run on a recorded sensor stream of the simulated device (bad
samples put in: NaN, inf, values beyond the estimators' bounds), cut into blocks at control events
(source, F_max, force scale, bowing, string reset); after every block every output, every estimate and
every state array (fault, string, motor limits, estimators) must have the same bits. Rates 1-96 kHz, any
pitch the rate plays, F_max 0-20 N, each estimator's parameters at Table 1's values or at the ends of
their ranges.

Equal, not close: on one machine the C (-ffp-contract=off, IEEE double) and numba (no fast-math) do the
same operations on the same operands in the same order. The loop calls no maths function but fabs and
isfinite, and the estimators only sqrt, fabs and copysign (firmware/studyapp_estimators.h), all exact in
IEEE 754, so another platform's maths library cannot change a bit either; what can is listed in that
header (x87's 80-bit intermediates, fused multiply-add, flushed subnormals).

The numba loop has no "bridge velocity" output: its audio row is the bridge velocity through the body
filter plus the contact microphone. The reference runs with no body section (audio=False builds none),
the audio switched on and the microphone's coefficients zeroed, so its audio row is v_bridge + 0.0: the
same value, compared as values (-0.0 + 0.0 is +0.0).
"""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studyapp import estimators
from studyapp.device import shadow
from studyapp.device.loop_benchmark import sensor_rows
from studyapp.errors import ParameterError
from studyapp.estimators.spec import NYQUIST_FRACTION
from studyapp.model import control
from studyapp.model.limits import RATE_PER_F0_MIN
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import LVT_SENSOR, TRUE

c_loop = pytest.importorskip("studyapp.device.c_loop")

NAMES = estimators.names()
PROTOCOL = Path(__file__).resolve().parents[2] / "protocols" / "sinclair2014.toml"
ADJUSTMENT = tomllib.loads(PROTOCOL.read_text())["adjustment"]["conditions"]  # the paper's nine
# the C output rows and the numba rows they equal bit for bit
SAME_BITS = {"force": "force", "source_velocity": "source_velocity", "string_velocity": "string_velocity",
             "v_delta": "v_delta", "stick": "stick", "friction": "friction"}
# the state both loops advance: ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut
STATE = range(11)


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def corner(name, end, rate):
    """Estimator ``name``'s parameters at Table 1 (``end`` "table1") or all at the low or high end of their
    ranges, cut-offs capped below Nyquist; None where the ends clash (LEASTSQ's window must exceed its order)."""
    chosen = {}
    for p in estimators.describe(name)["parameters"]:
        if p["kind"] == "choice":
            value = {"table1": p["default"], "low": p["choices"][0], "high": p["choices"][-1]}[end]
        else:
            value = {"table1": p["default"], "low": p["low"], "high": p["high"]}[end]
        if p.get("below_nyquist"):
            value = min(value, NYQUIST_FRACTION * rate)
        chosen[p["name"]] = value
    try:
        estimators.create(name, rate, **chosen)
    except ParameterError:
        return None
    return chosen


def make_loop(rate, f0, bank, source, fmax, seed=0):
    return ClosedLoop(LoopConfig(rate=rate, f0=f0, estimators=bank, source=source, fmax=fmax, seed=seed,
                                 audio=False, accelerometer=True), judge=False)


def record(rate, f0, fmax, seed, skip, n):
    """n sensor samples (x, a, v) of the simulated device bowed on the strokes with the LVT, after ``skip``."""
    loop = make_loop(rate, f0, {}, LVT_SENSOR, fmax, seed)
    if skip:
        loop.run(skip)
    out = loop.run(n)
    return [np.array(out[k]) for k in ("position", "acceleration", "velocity_lvt")]


BAD = [np.nan, np.inf, -np.inf, 2.0, -1e6, 500.0, 1e300]  # non-finite faults; finite beyond a bound is guarded


@st.composite
def scenarios(draw):
    rate = draw(st.sampled_from([1000.0, 5000.0, 48000.0, 96000.0]) | st.floats(1000.0, 96000.0))
    f0 = draw(st.floats(20.0, min(2000.0, rate / RATE_PER_F0_MIN)))
    bank = {}
    for name in draw(st.sets(st.sampled_from(NAMES))):
        params = corner(name, draw(st.sampled_from(["table1", "low", "high"])), rate)
        bank[name] = params if params is not None else corner(name, "table1", rate)
    sources = sorted(bank) + [LVT_SENSOR, TRUE]
    n = draw(st.integers(50, 1500))
    cuts = sorted(draw(st.sets(st.integers(1, n - 1), max_size=6)))
    events = [draw(st.one_of(
        st.tuples(st.just("source"), st.sampled_from(sources)),
        st.tuples(st.just("fmax"), st.floats(0.0, 20.0)),
        st.tuples(st.just("force_scale"), st.floats(0.0, 1.0)),
        st.tuples(st.just("bowing"), st.booleans()),
        st.tuples(st.just("reset_string"), st.none()))) for _ in cuts]
    return {
        "rate": rate, "f0": f0, "bank": bank, "n": n,
        "source": draw(st.sampled_from(sources[:-1] if draw(st.integers(0, 9)) else sources)),
        "fmax": draw(st.floats(0.0, 20.0)), "seed": draw(st.integers(0, 3)),
        "skip": draw(st.integers(0, int(0.05 * rate))),
        "bad": draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, 2), st.sampled_from(BAD)),
                             max_size=3)),
        "blocks": list(zip([0] + cuts, cuts + [n], [None] + events)),
    }


def apply(event, loop, c):
    kind, value = event
    if kind == "source":
        loop.set_source(value)
    elif kind == "fmax":
        loop.set_fmax(value)
    elif kind == "force_scale":
        loop.set_force_scale(value)
    elif kind == "bowing":
        loop.set_bowing(value)
    elif c is None:
        loop.reset_string()
    else:
        c.reset_string()  # the C's own reset, held to the loop's


def run_both(s):
    """Run the scenario through both loops; returns (numba rows, C rows, numba estimates, C estimates)."""
    x, a, v = record(s["rate"], s["f0"], max(s["fmax"], 1.0), s["seed"], s["skip"], s["n"])
    for i, channel, value in s["bad"]:
        (x, a, v)[channel][i] = value
    ref = make_loop(s["rate"], s["f0"], s["bank"], s["source"], s["fmax"])
    mine = make_loop(s["rate"], s["f0"], s["bank"], s["source"], s["fmax"])
    for loop in (ref, mine):  # the audio row carries the bridge velocity (the C reads no C_USE_AUDIO)
        loop.control.arrays[0][control.C_USE_AUDIO] = 1.0
    ref.control.arrays[15][:] = 0.0  # the contact microphone, silent
    c = c_loop.CLoop(mine.control.arrays)
    n_est = len(ref.names)
    out = np.zeros((len(control.OUTPUTS), s["n"]))
    est = np.zeros((n_est, s["n"]))
    c_out = np.zeros((len(c_loop.OUT_ROWS), s["n"]))
    c_est = np.zeros((n_est, s["n"]))
    for start, stop, event in s["blocks"]:
        if event is not None:
            apply(event, ref, None)
            apply(event, mine, c)
        block = slice(start, stop)
        o = np.zeros((len(control.OUTPUTS), stop - start))
        e = np.zeros((n_est, stop - start))
        shadow.run_rows(ref.control.arrays, 0, sensor_rows(x[block], a[block], v[block]), 0.0, shadow.MODEL, o, e,
                        np.zeros(2))
        out[:, block], est[:, block] = o, e
        c_out[:, block], c_est[:, block] = c.run(x[block], a[block], v[block])
        for i in STATE:
            assert np.array_equal(bits(ref.control.arrays[i]), bits(mine.control.arrays[i])), \
                f"state array {i} differs after samples {start}-{stop}"
    return out, c_out, est, c_est


def assert_same(out, c_out, est, c_est):
    for c_name, name in SAME_BITS.items():
        mine, ref = c_out[c_loop.OUT_ROWS.index(c_name)], out[control.OUTPUTS.index(name)]
        diff = np.flatnonzero(bits(mine) != bits(ref))
        assert diff.size == 0, f"{c_name} differs first at sample {diff[:1]}: {mine[diff[:1]]} vs {ref[diff[:1]]}"
    assert np.array_equal(c_out[c_loop.OUT_ROWS.index("bridge_velocity")], out[control.O_AUDIO])
    assert np.array_equal(bits(c_est), bits(est))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenarios())
def test_the_c_loop_equals_the_numba_loop_bit_for_bit(s):
    assert_same(*run_both(s))


def test_the_comparison_sees_bowing():
    """One scenario checked for content: the bow sticks and slips, the force reaches F_max, every estimator
    moves, a NaN latches the sensor fault and the force is 0 after it (the equality above is not vacuous)."""
    n, fmax = 1500, 4.0
    s = {"rate": 5000.0, "f0": 220.0, "bank": {name: {} for name in NAMES}, "n": n, "source": "KALLEV",
         "fmax": fmax, "seed": 1, "skip": 150, "bad": [(1200, 1, np.nan)],
         "blocks": [(0, 700, None), (700, n, ("source", LVT_SENSOR))]}
    out, c_out, est, c_est = run_both(s)
    assert_same(out, c_out, est, c_est)
    stick = c_out[c_loop.OUT_ROWS.index("stick")][:1200]
    force = c_out[c_loop.OUT_ROWS.index("force")]
    assert 0.1 < stick.mean() < 0.9
    assert np.abs(force[:1200]).max() > 0.9 * fmax
    assert np.all(force[1200:] == 0.0)
    assert np.all(np.abs(c_est[:, 200:1200]).max(axis=1) > 0.0)


@pytest.mark.parametrize("fmax", [0.5, 20.0])
@pytest.mark.parametrize("source", ADJUSTMENT)
def test_every_adjustment_condition_at_both_ends_of_f_max(source, fmax):
    """Each of the paper's nine conditions in the loop, every estimator beside it, through a string reset and
    bowing off and on, every run (the hypothesis test above draws its sources)."""
    n = 1200
    s = {"rate": 5000.0, "f0": 440.0, "bank": {name: {} for name in NAMES}, "n": n, "source": source,
         "fmax": fmax, "seed": 2, "skip": 100, "bad": [],
         "blocks": [(0, 400, None), (400, 700, ("reset_string", None)), (700, 900, ("bowing", False)),
                    (900, n, ("bowing", True))]}
    out, c_out, est, c_est = run_both(s)
    assert_same(out, c_out, est, c_est)
    assert np.any(c_out[c_loop.OUT_ROWS.index("force")] != 0.0)


def test_one_sample_at_a_time_equals_the_block():
    """sl_sample (the firmware's call) and sl_run (the block) give the same bits and leave the same state."""
    rate, f0, fmax = 20000.0, 440.0, 6.0
    bank = {name: {} for name in NAMES}
    x, a, v = record(rate, f0, fmax, 0, 200, 400)
    block = make_loop(rate, f0, bank, "FOAW", fmax)
    single = make_loop(rate, f0, bank, "FOAW", fmax)
    b = c_loop.CLoop(block.control.arrays)
    s = c_loop.CLoop(single.control.arrays)
    out, est = b.run(x, a, v)
    for k in range(x.size):
        f = s.sample(k, x[k], a[k], v[k])
        assert bits(f) == bits(out[0, k])
        assert [bits(getattr(s.out, r)) for r in c_loop.OUT_ROWS] == [bits(out[i, k]) for i in range(len(out))]
        assert np.array_equal(bits(s.est), bits(est[:, k]))
    for i in STATE:
        assert np.array_equal(bits(block.control.arrays[i]), bits(single.control.arrays[i]))


def test_arrays_the_c_cannot_run_are_refused():
    loop = make_loop(5000.0, 440.0, {"LOWPASS": {}}, LVT_SENSOR, 1.0)
    arrays = list(loop.control.arrays)
    c_loop.CLoop(tuple(arrays))
    for i, bad in ((7, lambda sp: sp.__setitem__(0, 1e6)),  # a line delay beyond the line
                   (8, lambda ss: ss.__setitem__(0, 2.5)),  # a write index that is no index
                   (4, lambda kinds: kinds.__setitem__(0, 99))):  # no such estimator
        broken = list(arrays)
        broken[i] = arrays[i].copy()
        bad(broken[i])
        with pytest.raises(ParameterError, match="sl_check"):
            c_loop.CLoop(tuple(broken))
    broken = list(arrays)
    broken[0] = arrays[0].astype(np.float32)
    with pytest.raises(ParameterError, match="ctl must be a C-contiguous float64"):
        c_loop.CLoop(tuple(broken))


def test_a_c_layout_out_of_step_with_the_python_one_is_refused(monkeypatch):
    monkeypatch.setattr(c_loop, "LAYOUT", c_loop.LAYOUT[:-1] + (c_loop.LAYOUT[-1] + 1,))
    with pytest.raises(c_loop.BuildError, match="layout"):
        c_loop._load(c_loop.build())


def test_reset_puts_the_loop_as_built_so_a_fresh_loop_runs_on_with_the_same_bits():
    """sl_reset (a device loop's START): string, estimators, mean square force and fault as a new loop's."""
    rate, f0, fmax = 5000.0, 220.0, 4.0
    bank = {name: {} for name in NAMES}
    x, a, v = record(rate, f0, fmax, 1, 200, 300)
    used = make_loop(rate, f0, bank, "KALLEV", fmax)
    fresh = make_loop(rate, f0, bank, "KALLEV", fmax)
    c_used, c_fresh = c_loop.CLoop(used.control.arrays), c_loop.CLoop(fresh.control.arrays)
    c_used.run(x, a, v)
    c_used.sample(x.size, np.nan, 0.0, 0.0)  # a fault latched too
    assert used.control.arrays[1][control.L_FAULT] != 0.0
    c_used.reset()
    for i in STATE:
        assert np.array_equal(bits(used.control.arrays[i]), bits(fresh.control.arrays[i])), i
    out_used, est_used = c_used.run(x, a, v)
    out_fresh, est_fresh = c_fresh.run(x, a, v)
    assert np.array_equal(bits(out_used), bits(out_fresh)) and np.array_equal(bits(est_used), bits(est_fresh))
