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

Compiled once, kept on disk. numba cannot cache a loop compiled for a
function passed as its argument, but it caches a function that names each
kernel in its source: ``side_by_side`` switches on the estimator's kind and
calls the loop with that kernel, as ``estimators.dispatch.run_block`` does,
so the loops load from numba's cache instead of compiling in every process
(7.5 s of CPU each run before, 2026-11-25).

Front ends. The hybrids K(x, z) feed KALMAN an acceleration z from a front
end (LEVANT or FOAW twice, plus the high-passed accelerometer) whose
parameters the paper's Table 2 never tunes: only q and r_acc are. So
``run_many(..., fronts=CACHE)`` runs a hybrid's front end once per setting
(``hybrids.front_*``, the same code as the hybrid's step), keeps z in CACHE
and runs KALMAN's step on (x, z) with the hybrid's parameters, the hybrid's
output bit for bit (tests check it): the FOAW hybrids' runs fall from about
67 to 16 ms per set on 15 recordings, KALMAN's cost.
"""

import numpy as np
from numba import njit

from studyapp.estimators import bdiff, complementary, foaw, hybrids, kalman, kinds, leastsq, levant, lowpass, lvt
from studyapp.estimators.bounds import all_good
from studyapp.estimators.dispatch import GUARD


@njit
def run_side_by_side(step, states, p, xs, acc, vel, out):
    """``out[r, i]`` = step of recording r's own state ``states[r]`` on sample ``xs[i, r]`` (and acc, vel)."""
    for i in range(xs.shape[0]):
        for r in range(xs.shape[1]):
            out[r, i] = step(states[r], p, xs[i, r], acc[i, r], vel[i, r])


# Kinds of the hybrids' front ends in ``side_by_side`` (after the estimators' own kinds).
FRONT_KALLEV, FRONT_KALLEVACC, FRONT_KALFOAW, FRONT_KALFOAWACC = 100, 101, 102, 103
FRONT = {"KALLEV": FRONT_KALLEV, "KALLEVACC": FRONT_KALLEVACC, "KALFOAW": FRONT_KALFOAW,
         "KALFOAWACC": FRONT_KALFOAWACC}



@njit(cache=True)
def side_by_side(kind, states, p, xs, acc, vel, out):
    """``run_side_by_side`` with the step of estimator ``kind`` (or of a hybrid's front end, ``FRONT``).

    Returns False for a kind without a branch here (LEASTSQ has its block form).
    """
    if kind == kinds.BDIFF:
        run_side_by_side(bdiff.step, states, p, xs, acc, vel, out)
    elif kind == kinds.LOWPASS:
        run_side_by_side(lowpass.step, states, p, xs, acc, vel, out)
    elif kind == kinds.FOAW:
        run_side_by_side(foaw.step, states, p, xs, acc, vel, out)
    elif kind == kinds.LEVANT:
        run_side_by_side(levant.step_levant, states, p, xs, acc, vel, out)
    elif kind == kinds.LEVANTLP:
        run_side_by_side(levant.step_levantlp, states, p, xs, acc, vel, out)
    elif kind == kinds.KALPOS:
        run_side_by_side(kalman.step_kalpos, states, p, xs, acc, vel, out)
    elif kind == kinds.KALMAN:
        run_side_by_side(kalman.step_kalman, states, p, xs, acc, vel, out)
    elif kind == kinds.KALLEV:
        run_side_by_side(hybrids.step_kallev, states, p, xs, acc, vel, out)
    elif kind == kinds.KALLEVACC:
        run_side_by_side(hybrids.step_kallevacc, states, p, xs, acc, vel, out)
    elif kind == kinds.KALFOAW:
        run_side_by_side(hybrids.step_kalfoaw, states, p, xs, acc, vel, out)
    elif kind == kinds.KALFOAWACC:
        run_side_by_side(hybrids.step_kalfoawacc, states, p, xs, acc, vel, out)
    elif kind == kinds.COMP1 or kind == kinds.COMP2:
        run_side_by_side(complementary.step, states, p, xs, acc, vel, out)
    elif kind == kinds.LVT:
        run_side_by_side(lvt.step, states, p, xs, acc, vel, out)
    elif kind == FRONT_KALLEV:
        run_side_by_side(hybrids.front_kallev, states, p, xs, acc, vel, out)
    elif kind == FRONT_KALLEVACC:
        run_side_by_side(hybrids.front_kallevacc, states, p, xs, acc, vel, out)
    elif kind == FRONT_KALFOAW:
        run_side_by_side(hybrids.front_kalfoaw, states, p, xs, acc, vel, out)
    elif kind == FRONT_KALFOAWACC:
        run_side_by_side(hybrids.front_kalfoawacc, states, p, xs, acc, vel, out)
    else:
        return False
    return True


@njit(cache=True, error_model="numpy")
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


def run(estimator, position, acceleration, velocity, finite=None):
    """The estimate of a fresh ``estimator`` over whole arrays (float64, C-contiguous, equal length).

    ``finite`` says whether every sample of the three inputs is known to be good (finite and
    within ``estimators.bounds``; checked here when None).
    """
    if finite is None:
        finite = all_good(position, acceleration, velocity)
    if not finite:
        return estimator.process(position, acceleration, velocity)
    return run_many(estimator, position[:, None], acceleration[:, None], velocity[:, None])[0]


def run_many(estimator, positions, accelerations, velocities, fronts=None):
    """The estimates of a fresh ``estimator`` (as ``create`` makes it) on each column of the inputs.

    The inputs are (samples x recordings), float64, C-contiguous, every sample good
    (``estimators.bounds``). Row r of the result (recordings x samples) is
    ``Estimator.process`` on column r; the estimator itself is left untouched. ``fronts``: a
    dict kept with these inputs, where a hybrid's front-end output is kept per setting.
    """
    from studyapp.estimators import create

    n, count = positions.shape
    out = np.empty((count, n))
    block_form = BLOCK_FORMS.get(estimator.name)
    if block_form is not None:
        block_form(estimator.p, positions, accelerations, velocities, out)
        return out
    states = np.repeat(estimator.state[None, GUARD:], count, axis=0)
    if fronts is not None and estimator.name in FRONT:
        k = states[:, :kalman.KALMAN_STATE].copy()  # K's fresh state (the front end changes its flag)
        z = _front(estimator, states, positions, accelerations, velocities, fronts)
        side_by_side(kinds.KALMAN, k, estimator.p[:kalman.KALMAN_PARAMS], positions, z, velocities, out)
        return out
    if not side_by_side(estimator.spec.kind, states, estimator.p, positions, accelerations, velocities, out):
        for r in range(count):
            fresh = create(estimator.name, estimator.rate, **estimator.params)
            out[r] = fresh.process(positions[:, r], accelerations[:, r], velocities[:, r])
    return out


def _front(estimator, states, positions, accelerations, velocities, fronts):
    """The front end's z (samples x recordings) of a hybrid, from ``fronts`` or run and kept there.

    Keyed by the hybrid and the parameters after KALMAN's (those of the front end), one setting per
    hybrid (a search that tunes the front end replaces it at every set).
    """
    key = estimator.p[kalman.KALMAN_PARAMS:].tobytes()
    kept = fronts.get(estimator.name)
    if kept is not None and kept[0] == key:
        return kept[1]
    z = np.empty((positions.shape[1], positions.shape[0]))
    side_by_side(FRONT[estimator.name], states, estimator.p, positions, accelerations, velocities, z)
    z = np.ascontiguousarray(z.T)
    fronts[estimator.name] = (key, z)
    return z
