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

The loop is compiled once per process and kernel (numba cannot cache a
function compiled for another compiled function as argument), so it pays
off in long runs: the optimiser's worker processes warm it up at start.
"""

import numpy as np
from numba import njit

from studyapp.estimators.bounds import all_good
from studyapp.estimators.dispatch import GUARD


@njit
def run_kernel(step, s, p, xs, acc, vel, out):
    for i in range(xs.shape[0]):
        out[i] = step(s, p, xs[i], acc[i], vel[i])


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
