"""Numerical evaluation and tuning of the estimators (paper Sec. 6-7), and their speed/accuracy trade.

    delay_and_error(reference, estimate, max_lag) -> (D samples, E)   eqs. 22-24
    ObjectiveSum                                  the adaptive normalisation, eqs. 27-32, steps 1-8
    AdaptiveSearch, Space                         pure adaptive search in each parameter's natural scale
    Optimiser                                     the whole procedure: executor, checkpoints, progress

Command line: ``studyapp optimise``, ``studyapp evaluate``, ``studyapp tradeoff``.
"""

from studyapp.evaluation.metric import delay_and_error

__all__ = ["delay_and_error"]
