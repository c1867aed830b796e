"""Numerical evaluation and tuning of the estimators (paper Sec. 6-7), and their speed/accuracy trade.

    delay_and_error(reference, estimate, max_lag, method="normalised") -> (D samples, E)
                                   eqs. 22-24; normalised or the paper's eq. 22 (metric.py)
    normalisation.ObjectiveSum     the adaptive normalisation, eqs. 27-32, steps 1-8
    search.AdaptiveSearch, space.Space   pure adaptive search in each parameter's natural scale
    optimiser.Optimiser            the whole procedure: executor, checkpoints, progress
    report.evaluate, tradeoff.tradeoff   Fig. 5's comparison; cost against accuracy per rate
    perceptual.audio_distance, perceptual_scores.perceptual_scores   Sec. 10: the sound with each
                                   estimator in the loop against TRUE's (specific loudness in Bark bands)
    paper_comparison, findings     Table 1 and the Sec. 7 findings beside the paper's, with rules
    retune.retune                  the optimiser re-run at one rate (``tradeoff --tune``)

Command line: ``studyapp optimise``, ``studyapp evaluate``, ``studyapp tradeoff``.
"""

from studyapp.evaluation.metric import delay_and_error

__all__ = ["delay_and_error"]
