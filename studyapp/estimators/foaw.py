"""FOAW: first-order adaptive windowing, best-fit method (paper Sec. 5.3).

Janabi-Sharifi, Hayward and Chen (2000) choose, at every sample, the longest
window over which a straight line explains the newest samples to within a
noise margin d, and output that line's slope. Long windows when the signal is
smooth (low noise), short ones at transients (low delay).

Size. The parameter ``window`` is the paper's "Size" (Table 1: 17): the most
samples a line is fitted to, the newest included, as in the authors' code. A
fit over n + 1 samples spans n sample intervals, so the longest window spans
N = ``window`` - 1 intervals (before 2026-11-25 ``window`` counted intervals:
our old window W was the authors' size W + 1, one sample longer than Table 1
meant).

Best-fit rule (DESIGN.md "Numerical conventions"). With y_{k-i} the sample of
age i and n = 1 .. N (N = ``window`` - 1):

    b_n = least-squares slope of y_k .. y_{k-n} (the n+1 newest samples)
    window n passes if |y_{k-j} - (y_k - b_n j T)| <= d  for every interior j = 1 .. n-1

Windows are tried in increasing n; the search stops at the first window that
fails, and the output is b_n of the last window that passed. Window 1 has no
interior sample, so it always passes and its slope (y_k - y_{k-1}) / T is the
backward difference: ``window = 2`` is exactly BDIFF with one step.
History before the first sample is taken equal to the first sample (at rest).

Arithmetic. Time is counted in samples (i = age) and the slope scaled by the
rate at the end; samples are taken relative to the newest, d_i = y_{k-i} - y_k,
so a large position offset cancels exactly before any sum is formed (accurate
at 96 kHz). With S0 = sum d_i and S1 = sum i d_i over i = 0 .. n (updated
incrementally as n grows), the least-squares slope per sample is

    b_n = 6 (n S0 - 2 S1) / (n (n+1) (n+2)),

and the test for interior j is |d_j + b_n j| <= d.

Cost. Checked sample by sample, every window costs O(n) and a step O(N^2).
But the test is linear in b: |d_j + b j| <= d for every interior j is

    L_n = max_{1<=j<n} (-d - d_j) / j  <=  b_n  <=  min_{1<=j<n} (d - d_j) / j = U_n,

and growing the window adds one interior sample, j = n-1, so L_n and U_n are
running extremes updated in O(1). A step is O(N) whatever the signal, and the
search also stops once L_n > U_n (no later window can pass). The decision is
the rule's own; it can differ from a sample-by-sample check only when a
residual equals the margin to within rounding.

``foaw_core`` is the reusable compiled step, its argument ``longest`` = N the
longest window in intervals; the hybrids KALFOAW and KALFOAWACC chain it
twice, F(F(x)), the second time on velocity with a margin in m/s: the margin
is in the units of x and the output in units of x per second.

Bad input: handled centrally by ``dispatch.step_guarded`` (a NaN, inf or
out-of-bounds sample, ``bounds.py``, is replaced by the last good one and
counted), so the kernel only ever sees finite input within the bounds.

State (``foaw_state_size(N)`` = 3 + 4 (N + 1) slots, N = ``window`` - 1):
``[started, head, chosen n, ring of N+1 samples stored twice, 1/j table, 6/(n(n+1)(n+2)) table]``
(the tables are filled at the first sample); slot
``CHOSEN`` (= 2) holds the window n chosen at the last step. The ring is
written at ``head`` and ``head + N + 1`` so that the samples of ages 0 .. N
are contiguous from ``head`` (no modulo in the inner loop).
Parameters: ``[N, d, rate]``.

``window_sizes(position, window, margin)`` returns the size chosen at every
sample (n + 1 samples, 2 .. ``window``), read from that slot while the kernel
runs over the whole input
(the paper's Sec. 7.4 counts the steps at which FOAW's window is at its
maximum). The rate is not an argument: the decision is made in samples and
in the units of x, only the output slope is scaled by the rate.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.bounds import POSITION_BOUND, good
from studyapp.estimators.spec import EstimatorSpec, Param

CHOSEN = 2  # state slot holding the window n chosen at the last step
_RING = 3  # first slot of the ring


@njit(cache=True, inline="always")
def foaw_state_size(longest):
    """Number of state slots ``foaw_core`` needs for a longest window of ``longest`` intervals (compiled or not)."""
    return _RING + 4 * (int(longest) + 1)


def longest(window):
    """N, the longest window in sample intervals, of a FOAW of size ``window`` (the paper's Size)."""
    return int(window) - 1


def build(rate, params):
    n = longest(params["window"])
    return np.array([float(n), params["margin"], rate]), int(foaw_state_size(n))


@njit(cache=True, inline="always")
def foaw_core(s, at, longest, margin, rate, x):
    """One FOAW best-fit step on the state that starts at ``s[at]``; returns the slope in units of x per second.

    The state is indexed in place rather than sliced: slicing it into views
    on every sample (ring, 1/j table, fit table) cost 30-40 ns per call,
    measured, more than the whole search at the default window.
    """
    big = int(longest)
    m = big + 1
    ring = at + _RING
    inv = ring + 2 * m  # 1 / j: the inner loop multiplies, never divides
    fit = ring + 3 * m  # 6 / (n (n+1) (n+2))
    if s[at] == 0.0:
        s[at] = 1.0
        s[at + 1] = 0.0
        for i in range(2 * m):
            s[ring + i] = x
        for j in range(1, m):
            s[inv + j] = 1.0 / j
            s[fit + j] = 6.0 / (j * (j + 1.0) * (j + 2.0))
    head = int(s[at + 1]) - 1
    if head < 0:
        head = m - 1
    s[at + 1] = head
    newest = ring + head
    s[newest] = x
    s[newest + m] = x
    s0 = 0.0
    s1 = 0.0
    best = 0.0
    chosen = 1
    low = -np.inf  # L_n: the slope must be at least this for every interior sample to pass
    high = np.inf  # U_n: ... and at most this
    for n in range(1, big + 1):
        d = s[newest + n] - x
        s0 += d
        s1 += n * d
        b = (n * s0 - 2.0 * s1) * s[fit + n]
        if n > 1:
            j = n - 1
            dj = s[newest + j] - x
            low = max(low, (-margin - dj) * s[inv + j])
            high = min(high, (margin - dj) * s[inv + j])
            if b < low or b > high:
                break
        best = b
        chosen = n
    s[at + CHOSEN] = chosen
    return best * rate


@njit(cache=True, error_model="numpy")
def _window_loop(xs, longest, margin, out):
    s = np.zeros(foaw_state_size(longest))
    last = 0.0  # the guard's rule (dispatch.step_guarded): a bad sample repeats the last good one
    for i in range(xs.shape[0]):
        x = xs[i]
        if good(x, POSITION_BOUND):
            last = x
        else:
            x = last
        foaw_core(s, 0, longest, margin, 1.0, x)
        out[i] = int(s[CHOSEN]) + 1


def window_sizes(position, window, margin):
    """The size (samples in the fit, 2 .. ``window``) FOAW chooses at each sample of ``position``, from rest.

    The same kernel as the estimator's, so the same decision: the output of
    ``create("FOAW", rate, window=window, margin=margin).process(position)``
    is, at every sample, the least-squares slope over the newest samples, as
    many as given here.
    """
    window = SPEC.param("window").validate(SPEC.name, window, None)
    margin = SPEC.param("margin").validate(SPEC.name, margin, None)
    xs = np.ascontiguousarray(position, dtype=np.float64)
    if xs.ndim != 1:
        raise ValueError(f"position: expected one dimension, got shape {xs.shape}")
    out = np.empty(xs.shape[0], dtype=np.int64)
    _window_loop(xs, longest(window), margin, out)
    return out


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    return foaw_core(s, 0, p[0], p[1], p[2], x)


SPEC = EstimatorSpec(
    name="FOAW", kind=kinds.FOAW, description="First-order adaptive windowing, best-fit method.",
    inputs=("position",),
    params=(
        Param("window", 17, "samples", 2, 256, kind="int", scale="linear",
              doc="the paper's Size: the most samples a line is fitted to (the newest included)"),
        Param("margin", 1.001e-4, "m", 1e-9, 1e-1, doc="noise margin d"),
    ),
    build=build,
    reference="paper Sec. 5.3; Janabi-Sharifi, Hayward, Chen 2000 (best-fit); Table 1 (size 17, margin 1.001e-4)",
    extra={"conventions": {"window": "size"}},
)
