"""The scope's buffer and peak decimation (no Qt), against plain NumPy slicing."""

import numpy as np
import pytest

from studyapp.live.scope_buffer import ScopeBuffer, envelope


def reference_envelope(x, k):
    bins = x.reshape(-1, k)
    out = []
    for b in bins:
        lo, hi = int(np.argmin(b)), int(np.argmax(b))
        out += [b[min(lo, hi)], b[max(lo, hi)]]
    return np.array(out)


@pytest.mark.parametrize("k", [2, 3, 25, 64])
def test_envelope_is_min_and_max_of_each_bin_in_time_order(k):
    rng = np.random.default_rng(k)
    x = rng.standard_normal(40 * k)
    np.testing.assert_array_equal(envelope(x, k), reference_envelope(x, k))
    rows = rng.standard_normal((3, 10 * k))
    out = envelope(rows, k)
    assert out.shape == (3, 20)
    for row, reduced in zip(rows, out):
        np.testing.assert_array_equal(reduced, reference_envelope(row, k))


def test_envelope_keeps_a_single_sample_spike():
    x = np.zeros(5000)
    x[1234] = 7.0
    x[4321] = -3.0
    out = envelope(x, 50)
    assert out.max() == 7.0 and out.min() == -3.0
    np.testing.assert_array_equal(envelope(x, 1), x)


def test_buffer_keeps_the_newest_samples_across_wraps():
    rate = 1000.0
    buf = ScopeBuffer(rate, ["a", "b"], seconds=0.5)  # 500 samples
    rng = np.random.default_rng(1)
    stream = []
    for m in rng.integers(1, 180, size=40):
        block = rng.standard_normal((2, int(m)))
        stream.append(block)
        buf.append(block)
    whole = np.concatenate(stream, axis=1)
    assert buf.end == whole.shape[1] and buf.count == 500
    np.testing.assert_array_equal(buf.latest(500), whole[:, -500:])
    np.testing.assert_array_equal(buf.latest(37), whole[:, -37:])
    big = rng.standard_normal((2, 1300))  # longer than the buffer
    buf.append(big)
    np.testing.assert_array_equal(buf.latest(600), big[:, -500:])


def test_buffer_starts_over_after_lost_samples():
    buf = ScopeBuffer(100.0, ["a"], seconds=1.0)
    buf.append(np.ones((1, 50)), end=50)
    buf.append(np.full((1, 10), 2.0), end=80)  # samples 50..69 never arrived
    assert buf.count == 10
    np.testing.assert_array_equal(buf.latest(100), np.full((1, 10), 2.0))


def test_window_is_the_envelope_of_the_last_seconds_on_fixed_bins():
    rate = 1000.0
    buf = ScopeBuffer(rate, ["a"], seconds=5.0)
    rng = np.random.default_rng(2)
    whole = rng.standard_normal(4321)
    buf.append(whole[None, :3000])
    t1, y1 = buf.window(2.0, 100)  # 2000 samples -> bins of 20
    k = 20
    first = 3000 - 2000  # already a multiple of 20
    np.testing.assert_array_equal(y1["a"], reference_envelope(whole[first:3000], k))
    assert t1[0] == pytest.approx(-2.0) and t1[-1] == pytest.approx(-1 / rate)
    buf.append(whole[None, 3000:])
    t2, y2 = buf.window(2.0, 100)
    # bins sit on absolute sample numbers: a bin seen before has the same points now
    first2 = 4321 - 2000
    first2 += (-first2) % k
    shared = (3000 - first2) // k
    np.testing.assert_array_equal(y2["a"][:2 * shared], y1["a"][-2 * shared:])
    assert np.all(np.diff(t2) >= 0) and t2[0] >= -2.0 and t2[-1] <= 0.0


def test_window_without_data_is_empty():
    t, y = ScopeBuffer(5000.0, ["a"]).window(1.0, 500)
    assert t.size == 0 and y["a"].size == 0
