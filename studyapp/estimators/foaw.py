"""FOAW: first-order adaptive windowing, best-fit method (paper Sec. 5.3).

Janabi-Sharifi, Hayward and Chen (2000) choose, at every sample, the longest
window over which a straight line explains the newest samples to within a
noise margin d, and output that line's slope. Long windows when the signal is
smooth (low noise), short ones at transients (low delay).

Best-fit rule (DESIGN.md "Numerical conventions"). With y_{k-i} the sample of
age i and n = 1 .. N (N = ``window``):

    b_n = least-squares slope of y_k .. y_{k-n} (the n+1 newest samples)
    window n passes if |y_{k-j} - (y_k - b_n j T)| <= d  for every interior j = 1 .. n-1

Windows are tried in increasing n; the search stops at the first window that
fails, and the output is b_n of the last window that passed. Window 1 has no
interior sample, so it always passes and its slope (y_k - y_{k-1}) / T is the
backward difference: ``window = 1`` is exactly BDIFF with one step.
History before the first sample is taken equal to the first sample (at rest).

Arithmetic. Time is counted in samples (i = age) and the slope scaled by the
rate at the end; samples are taken relative to the newest, d_i = y_{k-i} - y_k,
so a large position offset cancels exactly before any sum is formed (accurate
at 96 kHz). With S0 = sum d_i and S1 = sum i d_i over i = 0 .. n (updated
incrementally as n grows), the least-squares slope per sample is

    b_n = 6 (n S0 - 2 S1) / (n (n+1) (n+2)),

and the test for interior j is |d_j + b_n j| <= d.

Cost. Checking every interior sample of every window is O(N^2) per sample. A
bound skips most of it: if R >= max_j |d_j + b_{n-1} j| over j = 1 .. n-2
(the previous window's interior), then for the new slope

    max_j |d_j + b_n j| <= R + |b_n - b_{n-1}| (n - 2)   over j = 1 .. n-2,

so with the new interior sample j = n-1 checked directly, window n certainly
passes while this bound is within the margin, at O(1) cost. Only when the
bound exceeds the margin are the interior samples checked one by one (which
also makes R exact again). The decision is the rule's own, not an
approximation (it can differ from a sample-by-sample check only when a
residual equals the margin to within rounding). Smooth or clean stretches cost O(N) per sample; noise right at
the margin costs up to O(N^2).

``foaw_core`` is the reusable compiled step; the hybrids KALFOAW and KALFOAWACC
chain it twice, F(F(x)), the second time on velocity with a margin in m/s: the
margin is in the units of x and the output in units of x per second.

Bad input: handled centrally by ``dispatch.step_guarded`` (a non-finite sample
is replaced by the last finite one and counted), so the kernel only ever sees
finite input.

State (``foaw_state_size(N)`` = 3 + 2 (N + 1) slots):
``[started, head, chosen n, ring of N+1 samples stored twice]``; slot
``CHOSEN`` (= 2) holds the window n chosen at the last step. The ring is
written at ``head`` and ``head + N + 1`` so that the samples of ages 0 .. N
are contiguous from ``head`` (no modulo in the inner loop).
Parameters: ``[N, d, rate]``.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec, Param

CHOSEN = 2  # state slot holding the window n chosen at the last step
_RING = 3  # first slot of the ring


@njit(cache=True)
def foaw_state_size(window):
    """Number of state slots ``foaw_core`` needs for a largest window ``window`` (callable compiled or not)."""
    return _RING + 2 * (int(window) + 1)


def build(rate, params):
    window = params["window"]
    return np.array([float(window), params["margin"], rate]), int(foaw_state_size(window))


@njit(cache=True)
def foaw_core(s, window, margin, rate, x):
    """One FOAW best-fit step on the state view ``s``; returns the slope in units of x per second."""
    big = int(window)
    m = big + 1
    ring = s[_RING:_RING + 2 * m]
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = 0.0
        ring[:] = x
    head = int(s[1]) - 1
    if head < 0:
        head = m - 1
    s[1] = head
    ring[head] = x
    ring[head + m] = x
    s0 = 0.0
    s1 = 0.0
    best = 0.0
    chosen = 1
    bound = 0.0  # >= max |d_j + best j| over the interior of the last window that passed
    for n in range(1, big + 1):
        d = ring[head + n] - x
        s0 += d
        s1 += n * d
        b = 6.0 * (n * s0 - 2.0 * s1) / (n * (n + 1.0) * (n + 2.0))
        if n > 1:
            bound = max(bound + abs(b - best) * (n - 2), abs(ring[head + n - 1] - x + b * (n - 1)))
            if bound > margin:
                bound = 0.0
                r = 0.0
                for j in range(1, n):
                    r = abs(ring[head + j] - x + b * j)
                    if r > margin:
                        break
                    bound = max(bound, r)
                if r > margin:
                    break
        best = b
        chosen = n
    s[CHOSEN] = chosen
    return best * rate


@njit(cache=True)
def step(s, p, x, a, v):
    return foaw_core(s, p[0], p[1], p[2], x)


SPEC = EstimatorSpec(
    name="FOAW", kind=kinds.FOAW, description="First-order adaptive windowing, best-fit method.",
    inputs=("position",),
    params=(
        Param("window", 17, "samples", 1, 256, kind="int", scale="linear", doc="largest window n"),
        Param("margin", 1.001e-4, "m", 1e-9, 1e-1, doc="noise margin d"),
    ),
    build=build,
    reference="paper Sec. 5.3; Janabi-Sharifi, Hayward, Chen 2000 (best-fit); Table 1 (size 17, margin 1.001e-4)",
)
