"""Where the optimiser's time goes: CPU time per parameter set, per estimator, on recordings.

    PYTHONPATH=. python scripts/optimiser_profile.py DIR [--sets 10] [--seed 0]

For each of the paper's thirteen estimators: Table 1 and ``--sets - 1`` random
sets of its search space (``evaluation.space``), each measured on every recording
of DIR as the optimiser measures it (``Dataset(fast=True).raw_objectives``); the
delay and error part is timed again on its own (``metric.Reference.measure`` on
estimates made take by take), and the estimator runs are the difference. CPU time
(``time.process_time``), so a machine shared with other jobs changes it little.
It runs against any checkout (set PYTHONPATH), so a before and an after compare.
"""

import argparse
import time

import numpy as np

from studyapp.evaluation.dataset import RecordingFiles, expand_paths, warm_up
from studyapp.evaluation.space import PAPER_ESTIMATORS, Space


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings")
    parser.add_argument("--sets", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    warm_up(tuple(PAPER_ESTIMATORS), 5000.0, True)
    ds = RecordingFiles(tuple(expand_paths([args.recordings])), "lvt", 0.02, (), True).load()
    rng = np.random.default_rng(args.seed)
    totals = np.zeros(2)
    print(f"{'estimator':<11} {'runs ms/set':>12} {'delay+error ms/set':>19} {'total ms/set':>13}")
    for name in PAPER_ESTIMATORS:
        space = Space(name, 5000.0)
        sets = [space.start] + [space.values(rng.random(len(space.dims))) for _ in range(args.sets - 1)]
        sets = [p for p in sets if space.valid(p)]
        whole = metric = 0.0
        for params in sets:
            started = time.process_time()
            ds.raw_objectives(name, params)
            whole += time.process_time() - started
            estimates = [ds.estimate(take, name, params) for take in ds.takes]
            started = time.process_time()
            for ref, w in zip(ds.references, estimates):
                ref.measure(w)
            metric += time.process_time() - started
        runs, metric = 1e3 * (whole - metric) / len(sets), 1e3 * metric / len(sets)
        totals += (runs, metric)
        print(f"{name:<11} {runs:>12.1f} {metric:>19.1f} {runs + metric:>13.1f}")
    runs, metric = totals / len(PAPER_ESTIMATORS)
    print(f"{'mean':<11} {runs:>12.1f} {metric:>19.1f} {runs + metric:>13.1f}")


if __name__ == "__main__":
    main()
