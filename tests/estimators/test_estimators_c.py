"""The estimators in C (firmware/studyapp_estimators.*, through studyapp/device/c_estimators.py) equal the numba
kernels bit for bit on this machine: every sample's estimate and the whole final state vector, for every kind,
over rates of 1-96 kHz, each parameter at its bounds, its default and between (hypothesis, derandomised), and
sensor streams of many shapes with bad samples (NaN, inf, beyond the bounds) and edge values (-0.0, subnormal,
exactly at a bound).

The reference is the numba code run in the same process: the block form (``run_block``, what a Bank runs) and
the streaming form (``step_guarded``, what the closed loop runs), never a stored result. Bits are compared as
int64 views, so -0.0 against 0.0 or two NaNs of different payloads would fail.

Portability. The kernels use sqrt, fabs and copysign from <math.h> and nothing else (LEVANT's sqrt|e|, the
guard's |x|; test_only_exact_maths_functions holds that): IEEE 754 makes the three exact (sqrt correctly
rounded), so another IEEE platform's libm cannot change a bit. What can is in studyapp_estimators.h (x87
80-bit intermediates, FMA contraction, flush-to-zero); this test holds the bits only on the machine it runs on.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from studyapp import estimators
from studyapp.device import c_estimators
from studyapp.estimators import Bank, Estimator, kinds
from studyapp.estimators.bounds import ACCELERATION_BOUND, POSITION_BOUND, VELOCITY_BOUND
from studyapp.estimators.dispatch import GUARD
from studyapp.estimators.registry import KERNELS, SPECS
from studyapp.estimators.spec import RATE_MAX, RATE_MIN
from studyapp.synthetic import stick_slip

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
SETTINGS = settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
PREFIX = 200  # samples also stepped one at a time through the C binding (a ctypes call costs microseconds)


def bits(values):
    return np.ascontiguousarray(values, dtype=np.float64).view(np.int64)


def assert_same_bits(c, numba, what):
    c, numba = np.asarray(c, dtype=np.float64), np.asarray(numba, dtype=np.float64)
    assert c.shape == numba.shape, what
    differ = np.flatnonzero(bits(c) != bits(numba))
    assert differ.size == 0, (f"{what}: {differ.size} of {c.size} differ, first at {differ[0]}: "
                              f"C {c.flat[differ[0]]!r}, numba {numba.flat[differ[0]]!r}")


# --- parameters: each at its bounds, its default, or drawn between (log or linear as its scale says)

def param_values(param, rate):
    if param.kind == "choice":
        return st.sampled_from(param.choices)
    low, high = param.low, param.high_at(rate)
    corners = [low, high] + ([param.default] if low <= param.default <= high else [])
    if param.kind == "int":
        return st.one_of(st.sampled_from(corners), st.integers(int(low), int(high)))
    if param.scale == "log":
        between = st.floats(math.log10(low), math.log10(high)).map(lambda e: min(max(10.0 ** e, low), high))
    else:
        between = st.floats(low, high)
    return st.one_of(st.sampled_from(corners), between)


rates = st.one_of(st.sampled_from([RATE_MIN, 5000.0, 44100.0, RATE_MAX]), st.floats(RATE_MIN, RATE_MAX))


@st.composite
def estimator(draw, name):
    """An Estimator of ``name`` at a drawn rate with drawn parameters (LEASTSQ's window kept above its order)."""
    rate = draw(rates)
    params = {p.name: draw(param_values(p, rate)) for p in SPECS[name].params}
    if name == "LEASTSQ" and params["window"] <= params["order"]:
        params["window"] = params["order"] + 1
    return Estimator(name, rate, **params)


# --- sensor streams: a shape, a scale, bad samples and edge values, from a drawn seed

SHAPES = ("smooth", "ramps", "quantised", "constant", "white")


def shaped(rng, n, shape, scale):
    """``n`` samples of one ``shape``, of magnitude about ``scale``."""
    k = np.arange(n)
    if shape == "smooth":
        f = 10.0 ** rng.uniform(-4, -1)  # cycles per sample
        return scale * np.sin(2 * np.pi * f * k + rng.uniform(0, 6.3)) + scale * 10.0 ** rng.uniform(-7, -1) * \
            rng.standard_normal(n)
    if shape == "ramps":  # stick-slip like: straight stretches of random slopes, sometimes a jump
        slopes = np.repeat(rng.standard_normal(n // 16 + 1), 16)[:n] * scale / 64
        jumps = np.where(rng.random(n) < 0.01, rng.standard_normal(n) * scale, 0.0)
        return np.cumsum(slopes + jumps)
    if shape == "quantised":  # an ADC's steps: many samples exactly equal, differences exactly 0
        step = scale * 10.0 ** rng.uniform(-4, -1)
        return np.round(shaped(rng, n, "smooth", scale) / step) * step
    if shape == "constant":
        return np.full(n, scale * rng.choice([0.0, -0.0, 1.0, -1.0]))
    return scale * rng.uniform(-1.0, 1.0, n)


def with_bad(rng, values, bound, fraction):
    """``values`` with a ``fraction`` of bad samples and a few good edge values (at the bound, -0.0, subnormal)."""
    out = values.copy()
    n = out.shape[0]
    bad = [np.nan, np.inf, -np.inf, np.nextafter(bound, np.inf), -1.5 * bound, 1e30, -1e300]
    edge = [bound, -bound, -0.0, 0.0, 5e-324, -2.2e-308]
    hit = rng.random(n) < fraction
    out[hit] = rng.choice(bad, hit.sum())
    near = rng.random(n) < 0.01
    out[near] = rng.choice(edge, near.sum())
    return out


@st.composite
def streams(draw, max_n=1200):
    n = draw(st.integers(1, max_n))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    fraction = draw(st.sampled_from([0.0, 0.001, 0.02, 0.2]))
    shape = draw(st.sampled_from(SHAPES))
    x = shaped(rng, n, shape, 10.0 ** rng.uniform(-6, 0)).clip(-POSITION_BOUND, POSITION_BOUND)
    a = shaped(rng, n, draw(st.sampled_from(SHAPES)), 10.0 ** rng.uniform(-3, 5)).clip(-ACCELERATION_BOUND,
                                                                                         ACCELERATION_BOUND)
    v = shaped(rng, n, draw(st.sampled_from(SHAPES)), 10.0 ** rng.uniform(-4, 2)).clip(-VELOCITY_BOUND,
                                                                                        VELOCITY_BOUND)
    return (with_bad(rng, x, POSITION_BOUND, fraction), with_bad(rng, a, ACCELERATION_BOUND, fraction),
            with_bad(rng, v, VELOCITY_BOUND, fraction))


# --- the tests

@pytest.mark.parametrize("name", estimators.names())
@SETTINGS
@given(data=st.data())
def test_c_equals_numba_bit_for_bit(name, data):
    est = data.draw(estimator(name), label="estimator")
    x, a, v = data.draw(streams(), label="stream")
    n = x.shape[0]

    block = est.process(x, a, v)  # numba run_block
    block_state = est.state.copy()
    est.reset()
    streamed = np.array([est.step(x[i], a[i], v[i]) for i in range(n)])  # numba step_guarded
    assert_same_bits(block, streamed, f"{est!r}: numba's block and streaming forms")  # the premise

    s = np.zeros(GUARD + est.state_size)
    assert_same_bits(c_estimators.run(est.kind, s, est.p, x, a, v), block, f"{est!r}: estimates")
    assert_same_bits(s, block_state, f"{est!r}: final state")

    s = np.zeros(GUARD + est.state_size)
    one = [c_estimators.step_guarded(est.kind, s, est.p, x[i], a[i], v[i]) for i in range(min(n, PREFIX))]
    assert_same_bits(one, block[:PREFIX], f"{est!r}: se_step_guarded one sample at a time")


@pytest.mark.parametrize("name", estimators.names())
@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_c_kernel_without_guard_equals_the_numba_kernel(name, data):
    """se_step (dispatch.step_any) against the registered kernel called directly, on input the guard would pass."""
    est = data.draw(estimator(name), label="estimator")
    x, a, v = data.draw(streams(max_n=300), label="stream")
    x = np.where(np.abs(x) <= POSITION_BOUND, x, 0.0)
    a = np.where(np.abs(a) <= ACCELERATION_BOUND, a, 0.0)
    v = np.where(np.abs(v) <= VELOCITY_BOUND, v, 0.0)
    kernel = KERNELS[name]
    s_numba, s_c = np.zeros(est.state_size), np.zeros(est.state_size)
    numba = [kernel(s_numba, est.p, x[i], a[i], v[i]) for i in range(x.shape[0])]
    c = [c_estimators.step(est.kind, s_c, est.p, x[i], a[i], v[i]) for i in range(x.shape[0])]
    assert_same_bits(c, numba, f"{est!r}: estimates")
    assert_same_bits(s_c, s_numba, f"{est!r}: final state")


@settings(max_examples=8, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_bank_of_every_estimator_in_c_equals_the_numba_bank(data):
    """The packed rows of a Bank (zero-padded parameters and states), as the closed loop in C will hold them."""
    rate = data.draw(rates, label="rate")
    params = {}
    for name in estimators.names():
        drawn = {p.name: data.draw(param_values(p, rate), label=f"{name}.{p.name}") for p in SPECS[name].params}
        if name == "LEASTSQ" and drawn["window"] <= drawn["order"]:
            drawn["window"] = drawn["order"] + 1
        params[name] = drawn
    x, a, v = data.draw(streams(max_n=600), label="stream")
    numba, c = Bank(rate, params), Bank(rate, params)
    cut = x.shape[0] // 3  # two blocks: the state carries across
    expected = np.concatenate([numba.process(x[:cut], a[:cut], v[:cut]), numba.process(x[cut:], a[cut:], v[cut:])],
                              axis=1)
    got = np.concatenate([c_estimators.run_bank(c, x[:cut], a[:cut], v[:cut]),
                          c_estimators.run_bank(c, x[cut:], a[cut:], v[cut:])], axis=1)
    assert_same_bits(got, expected, "bank estimates")
    assert_same_bits(c.states, numba.states, "bank states")


@pytest.mark.parametrize("rate", [5000.0, RATE_MAX])
def test_the_papers_bank_on_seconds_of_stick_slip_in_c_equals_the_numba_bank(rate):
    """Every estimator at Table 1's values (those a rate allows) on 4 s of the synthetic stick-slip stream."""
    signal = stick_slip(rate, 4.0, seed=7)
    x, a, v = signal["position"], signal["acceleration"], signal["velocity_lvt"]
    names = [name for name in estimators.names() if SPECS[name].not_available(rate) is None]
    numba, c = Bank(rate, names), Bank(rate, names)
    assert_same_bits(c_estimators.run_bank(c, x, a, v), numba.process(x, a, v), "bank estimates")
    assert_same_bits(c.states, numba.states, "bank states")


def test_every_kind_is_known_and_an_unknown_kind_touches_nothing():
    for name in estimators.names():
        assert c_estimators.known(getattr(kinds, name))
    for kind in (-1, len(estimators.names()), 99):
        assert not c_estimators.known(kind)
        s = np.arange(8, dtype=np.float64)
        assert math.isnan(c_estimators.step_guarded(kind, s, np.zeros(4), 0.1, 0.0, 0.0))
        assert math.isnan(c_estimators.step(kind, s, np.zeros(4), 0.1, 0.0, 0.0))
        assert np.array_equal(s, np.arange(8))


def test_the_header_has_the_ids_and_the_guard_of_the_python_side():
    header = (FIRMWARE / "studyapp_estimators.h").read_text()
    ids = {m[0]: int(m[1]) for m in re.findall(r"\bSE_([A-Z0-9]+) = (\d+)", header)}
    assert ids.pop("KINDS") == len(estimators.names())
    assert ids == {name: getattr(kinds, name) for name in estimators.names()}
    assert re.search(rf"#define SE_GUARD {GUARD}\b", header)
    for macro, bound in (("POSITION", POSITION_BOUND), ("ACCELERATION", ACCELERATION_BOUND),
                         ("VELOCITY", VELOCITY_BOUND)):
        assert float(re.search(rf"#define SE_{macro}_BOUND (\S+)", header)[1]) == bound


MATHS = ("acos asin atan atan2 cos sin tan cosh sinh tanh exp exp2 expm1 log log10 log1p log2 pow sqrt cbrt hypot "
         "erf erfc tgamma lgamma ceil floor trunc round lround nearbyint rint fmod remainder fabs copysign fmin fmax "
         "fma frexp ldexp modf scalbn").split()


def test_only_exact_maths_functions_and_the_header_names_them():
    """The C files call only maths functions IEEE 754 makes exact, and the header lists each one they call."""
    sources = [FIRMWARE / s for s in c_estimators.SOURCES]
    text = "\n".join(re.sub(r"/\*.*?\*/", "", p.read_text(), flags=re.S) for p in sources)
    used = {f for f in MATHS if re.search(rf"\b{f}\s*\(", text)}
    assert used == {"sqrt", "fabs", "copysign"}
    named = re.search(r"The kernels use ([a-z, ]+) from <math\.h>", (FIRMWARE / "studyapp_estimators.h").read_text())
    assert set(re.split(r",\s*|\s+and\s+", named[1])) == used
    includes = set(re.findall(r"#include <([^>]+)>", text))
    assert includes <= {"stdint.h", "string.h", "math.h"}
