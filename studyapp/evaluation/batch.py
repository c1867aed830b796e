"""Recordings measured together: one estimator run side by side on several takes.

The optimiser measures each candidate parameter set on every take, from rest.
A ``Batch`` holds takes of one rate and one length whose samples are all good
(``Take.finite``), laid out sample-major (samples x takes), so that
``kernels.run_many`` runs the estimator on all of them at once, interleaved
sample by sample (why that is faster: ``kernels.py``); the estimator is built
once per batch rather than once per take. Each take's estimate, delay and
error are bit for bit those of running it alone (``Dataset`` with
``fast=False``; tests check it). A take with a bad sample is a batch of its
own, run through the input guard (``kernels.run``).

``batches(takes, references)`` groups a list of takes; ``Batch.measure`` gives
(delay, error) per take of the batch, in its order.
"""

import numpy as np

from studyapp.evaluation import kernels


class Batch:
    """Takes of one rate and length (all good, or a single take), with their ``metric.Reference``s."""

    def __init__(self, positions, takes, references):
        self.positions = list(positions)  # where each take sits in the caller's list
        self.takes = list(takes)
        self.references = list(references)
        self.rate = self.takes[0].rate
        self.side_by_side = all(t.finite for t in self.takes)
        self.fronts = {}  # the hybrids' front-end outputs on these takes (kernels.run_many)
        if self.side_by_side:
            self.x, self.a, self.v = (
                np.ascontiguousarray(np.stack([getattr(t, column) for t in self.takes], axis=1))
                for column in ("position", "acceleration", "velocity"))

    def estimates(self, name, params):
        """Rows of estimates, one per take, each from rest."""
        from studyapp.estimators import create

        if self.side_by_side:
            return kernels.run_many(create(name, self.rate, **params), self.x, self.a, self.v, self.fronts)
        return [kernels.run(create(name, self.rate, **params), t.position, t.acceleration, t.velocity, t.finite)
                for t in self.takes]

    def measure(self, name, params):
        """(delay, error) of each take (``metric.Reference.measure``), in the batch's order."""
        return [ref.measure(w) for ref, w in zip(self.references, self.estimates(name, params))]


def batches(takes, references):
    """``Batch``es covering ``takes``: the good ones grouped by rate and length, each bad one alone."""
    groups = {}
    for i, take in enumerate(takes):
        key = (take.rate, take.position.shape[0]) if take.finite else ("alone", i)
        groups.setdefault(key, []).append(i)
    return [Batch(members, [takes[i] for i in members], [references[i] for i in members])
            for members in groups.values()]
