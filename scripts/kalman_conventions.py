"""Table 1's KALPOS and KALMAN under each q convention, on a set of recordings (docs/estimators-kalman.md).

    PYTHONPATH=. python scripts/kalman_conventions.py sim/        # sim/ from `studyapp simulate-set -o sim/`

Every one of the paper's thirteen estimators runs with its defaults (Table 1, the authors'
conventions), except the one whose q_convention is set in turn. Prints, for KALPOS and KALMAN
under each convention: the median over the recordings of E (mm/s) and of |D| (samples) against
the LVT, F_g and the rank among the thirteen (eqs. 27-32 over the evaluated estimators).
"""

import sys

import numpy as np

from studyapp.estimators.spec import Q_CONVENTIONS
from studyapp.evaluation.dataset import Dataset, expand_paths, load_takes
from studyapp.evaluation.parameter_sets import parameter_sets
from studyapp.evaluation.report import evaluate


def main(folder):
    dataset = Dataset(load_takes(expand_paths([folder]), "lvt"))
    table1, _ = parameter_sets(None, None, min(t.rate for t in dataset.takes), {})
    for name in ("KALPOS", "KALMAN"):
        for convention in Q_CONVENTIONS:
            params = {n: dict(p) for n, p in table1.items()}
            params[name]["q_convention"] = convention
            result = evaluate(dataset, params)
            print(f"{name:7s} {convention:10s} q = {params[name]['q']:<7g} median E "
                  f"{1e3 * np.median(result.errors[name]):.3g} mm/s, median |D| "
                  f"{np.median(np.abs(result.delays[name])):g} samples, F_g {result.objective[name]:.3g}, "
                  f"rank {result.ranking.index(name) + 1} of {len(result.names)}")
    result = evaluate(dataset, table1)
    print(f"LOWPASS (Table 1): median E {1e3 * np.median(result.errors['LOWPASS']):.3g} mm/s, median |D| "
          f"{np.median(np.abs(result.delays['LOWPASS'])):g} samples")


if __name__ == "__main__":
    main(sys.argv[1])
