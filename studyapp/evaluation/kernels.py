"""Fast whole-recording runs for the optimiser: each estimator's own compiled step in a compiled loop.

The optimiser runs every candidate set over every recording, so the cost per
sample is its budget. ``Estimator.process`` goes through the dispatch's
streaming form (a switch on the estimator kind and the bad input guard at
every sample); here the kernel itself is passed to a compiled loop,
which numba specialises for that kernel. The output is the same: the kernel
sees the same state and samples, and recordings with a bad sample (NaN, inf
or beyond ``estimators.bounds``), or estimators without a registered kernel,
take ``Estimator.process`` instead (tests check the equality for every
estimator).

Side by side. A kernel's step is a chain of dependent floating-point
operations (a filter's state feeds its next output), so a run over one
recording mostly waits for the previous result. The optimiser runs each
candidate on every recording from rest, and those runs are independent:
``run_side_by_side`` interleaves them, sample i of every recording before
sample i + 1, and the processor overlaps the chains. Each recording's
arithmetic is unchanged, so its estimate equals ``run``'s bit for bit.
Measured on 15 recordings of 35,000 samples (2026-11-25, CPU time, loaded
machine): LOWPASS 26 -> 4 ns per sample, LEVANT 14 -> 4, KALPOS 22 -> 8,
KALMAN 40 -> 27, LEASTSQ 43 -> 31, FOAW 53 -> 48 (its window search is
branch-bound, not latency-bound).

LEASTSQ's step is an FIR filter whose taps are summed one by one, newest
sample first, over a ring buffer: a window of M costs M dependent additions
per sample (up to 512). ``fir_side_by_side`` computes the same sums in the
same order for a block of outputs at once (the additions of different
outputs are independent, so the loop over outputs vectorises); measured at
M = 257: 234 -> 27 ns per sample.

The loops are compiled once per process and kernel (numba cannot cache a
function compiled for another compiled function as argument), so they pay
off in long runs: the optimiser's worker processes warm them up at start.
"""

import numpy as np
from numba import njit

from studyapp.estimators.bounds import all_good
from studyapp.estimators.dispatch import GUARD


@njit
def run_kernel(step, s, p, xs, acc, vel, out):
    for i in range(xs.shape[0]):
        out[i] = step(s, p, xs[i], acc[i], vel[i])


@njit
def run_side_by_side(step, states, p, xs, acc, vel, out):
    """``out[r, i]`` = step of recording r's own state ``states[r]`` on sample ``xs[i, r]`` (and acc, vel)."""
    for i in range(xs.shape[0]):
        for r in range(xs.shape[1]):
            out[r, i] = step(states[r], p, xs[i, r], acc[i, r], vel[i, r])


@njit(error_model="numpy")
def fir_side_by_side(taps, xs, out):
    """``out[r, k] = sum_i taps[i] * xs[k - i, r]`` summed in increasing i, from 0.0, with
    ``xs[j, r] = xs[0, r]`` for j < 0 (history at rest): LEASTSQ's step at every sample.

    Written with slices and non-negative loop indices so that numba drops its negative-index
    checks and the loop over outputs vectorises (indexing ``history[k - i + m - 1]`` ran 4x slower).
    """
    n, count = xs.shape
    m = taps.shape[0]
    block = 1024
    history = np.empty(n + m - 1)
    for r in range(count):
        history[:m - 1] = xs[0, r]
        history[m - 1:] = xs[:, r]
        for start in range(0, n, block):
            stop = min(n, start + block)
            acc = np.zeros(stop - start)
            for i in range(m):
                tap = taps[i]
                older = history[start + m - 1 - i:stop + m - 1 - i]
                for k in range(stop - start):
                    acc[k] += tap * older[k]
            out[r, start:stop] = acc


def _leastsq(p, xs, acc, vel, out):
    fir_side_by_side(p[1:1 + int(p[0])], xs, out)


# Estimators with a block form of their own (same output as their step, bit for bit).
BLOCK_FORMS = {"LEASTSQ": _leastsq}


def kernels():
    """Estimator name -> its compiled step (the registry's, the same functions the dispatch calls)."""
    from studyapp.estimators.registry import KERNELS

    return KERNELS


def run(estimator, position, acceleration, velocity, finite=None):
    """The estimate of a fresh ``estimator`` over whole arrays (float64, C-contiguous, equal length).

    ``finite`` says whether every sample of the three inputs is known to be good (finite and
    within ``estimators.bounds``; checked here when None).
    """
    step = kernels().get(estimator.name)
    if finite is None:
        finite = all_good(position, acceleration, velocity)
    if step is None or not finite:
        return estimator.process(position, acceleration, velocity)
    out = np.empty(position.shape[0])
    run_kernel(step, estimator.state[GUARD:], estimator.p, position, acceleration, velocity, out)
    return out


def run_many(estimator, positions, accelerations, velocities):
    """The estimates of a fresh ``estimator`` (as ``create`` makes it) on each column of the inputs.

    The inputs are (samples x recordings), float64, C-contiguous, every sample good
    (``estimators.bounds``). Row r of the result (recordings x samples) is
    ``run(estimator, positions[:, r], ...)``; the estimator itself is left untouched.
    """
    from studyapp.estimators import create

    n, count = positions.shape
    out = np.empty((count, n))
    block_form = BLOCK_FORMS.get(estimator.name)
    if block_form is not None:
        block_form(estimator.p, positions, accelerations, velocities, out)
        return out
    step = kernels().get(estimator.name)
    if step is None:
        for r in range(count):
            fresh = create(estimator.name, estimator.rate, **estimator.params)
            out[r] = fresh.process(positions[:, r], accelerations[:, r], velocities[:, r])
        return out
    states = np.repeat(estimator.state[None, GUARD:], count, axis=0)
    run_side_by_side(step, states, estimator.p, positions, accelerations, velocities, out)
    return out
