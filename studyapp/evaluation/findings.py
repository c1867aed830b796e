"""The paper's findings of Sec. 7 (Fig. 5, Secs. 7.3-7.4), each judged on our evaluation by a stated rule.

``findings.csv`` (columns ``finding, paper, ours, agrees, verdict``): one row
per finding; ``paper`` gives the paper's statement and, after "rule:", the
quantitative rule that decides it; ``verdict`` is "holds", "fails" or
"undecided (ties)", and ``agrees`` is True only when it holds. Three kinds of
rule, as strict as the paper's own words allow:

- a number (a percentage, a mean): ours within a factor 2 of the paper's,
  paper / 2 <= ours <= 2 paper;
- an order: the rank of ours among the n evaluated estimators (1 = lowest;
  an undefined median ranks last), e.g. "rank n of n", "ranks 1 to k",
  "rank <= n / 2". Tied values could stand in either order, so a value's rank
  is the span of ranks its ties allow (``rank_span``): the rule holds when it
  holds at every rank of the span, fails when at none, and is undecided
  (ties) otherwise. Ties are equal values, and for the delay values closer
  than ``DELAY_RESOLUTION`` samples (issue 30: on the study's recordings every
  tuned estimator's median whole-sample |D| was 0, so every delay rank was a
  tie, and a mean rank of a tie passed or failed "rank <= n / 2" by default);
- a significance: the two-sided Wilcoxon rank-sum test of Fig. 5
  (``significance.rank_sum``) over the group's recordings, significant when
  p < 0.05 (the paper's threshold); ``ours`` quotes the deciding p.

Measures (Fig. 5, Sec. 7.2): per recording, error E and |D| as a percentage
of LOWPASS's on that recording; an estimator's value is its median over the
group's recordings. The delay is the sub-sample delay where the evaluation
measured it (``subsample_delay.subsample_delay``; else the whole-sample D), and delay
ranks are of the median |D| in samples (a percentage of a LOWPASS delay near 0
would blow its resolution up). Delay counts by its magnitude everywhere (ranks, medians,
tests), as in the objective F_g: a lead of the band-limited LVT is as much a
mismatch as a lag. Group a is F_max 0 to 7.7 N (Fig. 5a), group b 2.2 to
12.1 N (Fig. 5b), ``report.GROUPS``.

The findings and their rules:

 1. KALMAN best on the objective (Sec. 7.4, "KALMAN provides the best global
    results"): KALMAN has rank 1 on F_g over group a.
 2. The third-order Kalman filters best on both criteria (Sec. 7.4): those
    evaluated (KALMAN, KALLEV, KALLEVACC, KALFOAW, KALFOAWACC; k of them) hold
    ranks 1 to k of median error and ranks 1 to k of median |delay|.
 3. No significant differences among the best six on both criteria at once
    (Sec. 7.4): among the six best on F_g, no pair where one is significantly
    better than the other on error and on |delay| (each p < 0.05, the better
    median on the same side).
 4. No significant gain from the measured acceleration (Sec. 7.4): in none of
    the pairs without / with the accelerometer, (KALPOS, KALMAN), (KALLEV,
    KALLEVACC), (KALFOAW, KALFOAWACC), is the one with it significantly better
    (p < 0.05, lower median) on error or on |delay|.
 5. LEVANT's error (Fig. 5 caption: median 560 % of LOWPASS, the worst):
    within a factor 2 of 560 % and rank n of n.
 6. FOAW's "very good error performance" (Sec. 7.4): median error rank <= n / 2.
 7. FOAW "suffered badly from delay" (Sec. 7.4): median |delay| rank > n / 2.
 8. FOAW's window at its maximum "for over 98 percent of time steps"
    (Sec. 7.4): over 98 % of all samples of the evaluated recordings
    (``foaw.window_sizes``, our FOAW parameters).
 9. LEASTSQ "very effective ... in terms of delay" (Sec. 7.4): median |delay|
    rank <= n / 2.
10. The Levant-Kalman estimators the only ones to beat LOWPASS on both error
    and delay (Sec. 7.4, Fig. 5b): the set of estimators with median error and
    median |delay| both below 100 % of LOWPASS over group b is exactly
    {KALLEV, KALLEVACC} (those of them evaluated). (The paper's Fig. 5b comes
    from a second optimisation on group b; ours uses the one parameter set.)
11. Validation error difference (Sec. 7.3: 10.3 +- 7.76 %): our mean within a
    factor 2 of 10.3 %.
12. Validation delay difference (Sec. 7.3: 2.60 +- 2.02 samples): our mean
    within a factor 2 of 2.60 samples.

A finding whose estimators were not evaluated (2, 3: fewer than two of them;
4: no complete pair), whose group holds no recording, or (11, 12) without
``--validation`` is left out.
"""

import itertools

import numpy as np

from studyapp.evaluation.report import BASELINE, GROUPS
from studyapp.evaluation.significance import ALPHA, rank_sum

FINDING_COLUMNS = ["finding", "paper", "ours", "agrees", "verdict"]
HOLDS, FAILS, UNDECIDED = "holds", "fails", "undecided (ties)"
# Delays closer than this (samples) are ties: twice the largest error of the sub-sample delay on
# pure fractional delays of signals band-limited to fs / 5 (0.017 samples,
# tests/evaluation/test_evaluation_subsample_delay.py), rounded up.
DELAY_RESOLUTION = 0.05

THIRD_ORDER_KALMAN = ("KALMAN", "KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC")
ACCELEROMETER_PAIRS = (("KALPOS", "KALMAN"), ("KALLEV", "KALLEVACC"), ("KALFOAW", "KALFOAWACC"))
PAPER_BEST = "KALMAN"
BEST_SIX = 6
PAPER_LEVANT_ERROR_PCT = 560.0
PAPER_FOAW_AT_MAXIMUM = 0.98
PAPER_BEAT_LOWPASS = ("KALLEV", "KALLEVACC")
PAPER_VALIDATION_ERROR_PCT = (10.3, 7.76)  # mean, standard deviation
PAPER_VALIDATION_DELAY = (2.60, 2.02)  # samples
FACTOR = 2.0


def within_factor(ours, paper, factor=FACTOR):
    """True when ``paper / factor <= ours <= paper * factor`` (False for a missing or undefined value)."""
    return ours is not None and bool(np.isfinite(ours)) and paper / factor <= ours <= paper * factor


def _samples(result, measure, mask):
    """name -> per-recording error % or |delay| % of LOWPASS over the group's recordings."""
    if measure == "error":
        return {n: result.error_pct(n)[mask] for n in result.names}
    return {n: np.abs(result.subsample_delay_pct(n)[mask]) for n in result.names}


def _median(values):
    finite = np.asarray(values, dtype=np.float64)
    finite = finite[np.isfinite(finite)]
    return float(np.median(finite)) if finite.size else float("nan")


def _medians(result, measure, mask):
    return {n: _median(v) for n, v in _samples(result, measure, mask).items()}


def rank_span(values, name, resolution=0.0):
    """(lowest, highest) rank ``name``'s value can take: values within ``resolution`` of it are ties."""
    finite = {n: v if np.isfinite(v) else np.inf for n, v in values.items()}
    own = finite[name]
    others = [v for n, v in finite.items() if n != name]
    below = sum(v < own - resolution or (np.isinf(own) and not np.isinf(v)) for v in others)
    above = sum(v > own + resolution or (np.isinf(v) and not np.isinf(own)) for v in others)
    return 1 + below, len(finite) - above


def verdict(outcomes):
    """holds / fails / undecided (ties) from the rule's outcomes over every order the ties allow."""
    outcomes = set(outcomes)
    return UNDECIDED if len(outcomes) > 1 else HOLDS if outcomes == {True} else FAILS


def combined(verdicts):
    """The verdict of a rule that needs every part: fails if one fails, holds if all hold."""
    return FAILS if FAILS in verdicts else HOLDS if all(v == HOLDS for v in verdicts) else UNDECIDED


def _span_text(span):
    low, high = span
    return f"{low}" if low == high else f"{low}-{high} (tied)"


def _delay_medians(result, mask):
    """name -> median |D| in samples over the group, and the resolution of their ranks."""
    medians = {n: _median(result.abs_delays(n)[mask]) for n in result.names}
    return medians, DELAY_RESOLUTION if result.subsample_delays is not None else 0.0


def _whole_zero(result, mask):
    """A note when every estimator's median whole-sample |D| over the group is 0 (issue 30), else ''."""
    if any(_median(np.abs(result.delays[n][mask])) != 0 for n in result.names):
        return ""
    if result.subsample_delays is None:
        return "; every median whole-sample |D| is 0: not ranked"
    return "; every median whole-sample |D| is 0: ranked by the sub-sample delay"


def _group(group):
    low, high = GROUPS[group]
    return f"F_max {low:g} to {high:g} N"


def _g(x):
    return f"{x:.3g}" if x is not None and np.isfinite(x) else "undefined"


def _row(finding, paper, rule, ours, decided):
    """A findings.csv row; ``decided`` a verdict, or a bool for a rule without ties."""
    decided = decided if isinstance(decided, str) else HOLDS if decided else FAILS
    return {"finding": finding, "paper": f"{paper}; rule: {rule}", "ours": ours, "agrees": decided == HOLDS,
            "verdict": decided}


def _objective_totals(result, mask):
    totals = {n: float(np.sum(result.recording_objective[n][mask])) for n in result.names}
    return {n: t if np.isfinite(t) else np.inf for n, t in totals.items()}


def kalman_best(result, mask):
    totals = _objective_totals(result, mask)
    span = rank_span(totals, PAPER_BEST)
    n = len(totals)
    best = min(result.names, key=lambda name: (totals[name], result.names.index(name)))
    ours = f"{best} best (F_g {_g(totals[best])}); {PAPER_BEST} rank {_span_text(span)} of {n}"
    return _row(f"{PAPER_BEST} best on the objective ({_group('a')})", f"{PAPER_BEST} best (Sec. 7.4)",
                f"{PAPER_BEST} rank 1 of n on F_g", ours, verdict(r == 1 for r in range(span[0], span[1] + 1)))


def third_order_best(result, mask):
    family = [n for n in THIRD_ORDER_KALMAN if n in result.names]
    k, n = len(family), len(result.names)
    parts, verdicts = [], []
    for label, (medians, resolution) in (("error", (_medians(result, "error", mask), 0.0)),
                                         ("|delay|", _delay_medians(result, mask))):
        spans = {name: rank_span(medians, name, resolution) for name in family}
        # holds when every member's worst rank is within 1..k, fails when some member's best rank is not
        verdicts.append(verdict({max(high for _, high in spans.values()) <= k,
                                 max(low for low, _ in spans.values()) <= k}))
        parts.append(f"{label} ranks " + ", ".join(f"{name} {_span_text(spans[name])}" for name in family))
    return _row(f"third-order Kalman filters best on both criteria ({_group('a')})",
                "the best performers on both criteria (Sec. 7.4)",
                f"the {k} evaluated hold ranks 1 to {k} of {n} of median error and of median |delay|",
                "; ".join(parts) + _whole_zero(result, mask), combined(verdicts))


def _better_on(samples, a, b):
    """The estimator significantly better than the other on these samples (p < ALPHA, lower median), or None."""
    _, p = rank_sum(samples[a], samples[b])
    if p >= ALPHA:
        return None, p
    return (a if _median(samples[a]) < _median(samples[b]) else b), p


def best_six_not_different(result, mask):
    totals = _objective_totals(result, mask)
    six = sorted(result.names, key=lambda name: (totals[name], result.names.index(name)))[:BEST_SIX]
    errors, delays = _samples(result, "error", mask), _samples(result, "delay", mask)
    dominating = []
    for a, b in itertools.combinations(six, 2):
        on_error, p_e = _better_on(errors, a, b)
        on_delay, p_d = _better_on(delays, a, b)
        if on_error is not None and on_error == on_delay:
            loser = b if on_error == a else a
            dominating.append(f"{on_error} over {loser} (error p {p_e:.2g}, |delay| p {p_d:.2g})")
    ours = (f"best {len(six)}: {', '.join(six)}; " + (f"{len(dominating)} pair(s) significantly different on both: "
            + "; ".join(dominating) if dominating else "no pair significantly different on both"))
    return _row(f"best six not significantly different on both criteria ({_group('a')})",
                "no significant differences for the best six on both error and delay simultaneously (Sec. 7.4)",
                f"among the six best on F_g, no pair with one better on error and on |delay|, each "
                f"Wilcoxon rank-sum p < {ALPHA:g}", ours, not dominating)


def accelerometer_gain(result, mask):
    pairs = [(a, b) for a, b in ACCELEROMETER_PAIRS if a in result.names and b in result.names]
    errors, delays = _samples(result, "error", mask), _samples(result, "delay", mask)
    parts, gains = [], 0
    for without, with_acc in pairs:
        cells = []
        for label, samples in (("error", errors), ("|delay|", delays)):
            better, p = _better_on(samples, without, with_acc)
            gain = better == with_acc
            gains += gain
            cells.append(f"{label} p {p:.2g}{' (gain)' if gain else ''}")
        parts.append(f"{with_acc} vs {without}: " + ", ".join(cells))
    return _row(f"no significant gain from the accelerometer ({_group('a')})",
                "no significant improvements by including measured acceleration (Sec. 7.4)",
                f"in no pair (without, with) {', '.join(f'({a}, {b})' for a, b in pairs)} is the one with "
                f"the accelerometer better on error or |delay|, Wilcoxon rank-sum p < {ALPHA:g}",
                "; ".join(parts), gains == 0)


def levant_error(result, mask):
    medians = _medians(result, "error", mask)
    span, n = rank_span(medians, "LEVANT"), len(medians)
    ours = medians["LEVANT"]
    highest = verdict(r == n for r in range(span[0], span[1] + 1))
    return _row(f"LEVANT error, median % of LOWPASS ({_group('a')})",
                f"{PAPER_LEVANT_ERROR_PCT:g}, the highest (Fig. 5)",
                f"within a factor {FACTOR:g} ({PAPER_LEVANT_ERROR_PCT / FACTOR:g} to "
                f"{PAPER_LEVANT_ERROR_PCT * FACTOR:g}) and rank n of n",
                f"{_g(ours)} (rank {_span_text(span)} of {n})",
                combined([verdict([within_factor(ours, PAPER_LEVANT_ERROR_PCT)]), highest]))


def _half(result, mask, name, measure, paper, better):
    medians = _medians(result, measure, mask)
    ranked, resolution = (medians, 0.0) if measure == "error" else _delay_medians(result, mask)
    span, n = rank_span(ranked, name, resolution), len(medians)
    label = "error" if measure == "error" else "|delay|"
    rule = f"median {label} rank <= n / 2" if better else f"median {label} rank > n / 2"
    samples = "" if measure == "error" else f", median {_g(ranked[name])} samples" + _whole_zero(result, mask)
    return _row(f"{name} {label}, median % of LOWPASS ({_group('a')})", paper, rule,
                f"{_g(medians[name])} (rank {_span_text(span)} of {n}{samples})",
                verdict((r <= n / 2) == better for r in range(span[0], span[1] + 1)))


def foaw_error(result, mask):
    return _half(result, mask, "FOAW", "error", "very good error performance (Sec. 7.4)", better=True)


def foaw_delay(result, mask):
    return _half(result, mask, "FOAW", "delay", "suffered badly from delay (Sec. 7.4)", better=False)


def leastsq_delay(result, mask):
    return _half(result, mask, "LEASTSQ", "delay", "very effective in terms of delay (Sec. 7.4)", better=True)


def foaw_window_at_maximum(fraction, window):
    return _row("FOAW window at its maximum, % of samples", "over 98 % of time steps (Sec. 7.4)",
                f"over {100 * PAPER_FOAW_AT_MAXIMUM:g} % of all samples", f"{_g(100 * fraction)} (size {int(window)})",
                fraction > PAPER_FOAW_AT_MAXIMUM)


def beat_lowpass(result, mask):
    errors = _medians(result, "error", mask)
    delays = _medians(result, "delay", mask)
    _, resolution = _delay_medians(result, mask)
    # a median |delay| within the resolution of LOWPASS's own is a tie with 100 %: neither below nor not
    own = result.baseline_subsample_delays if result.subsample_delays is not None else result.baseline_delays
    baseline = _median(np.abs(np.asarray(own, dtype=np.float64))[mask])
    tie = 100.0 * resolution / baseline if baseline > 0 else np.inf
    candidates = [n for n in result.names if n != BASELINE and errors[n] < 100.0]
    ours = [n for n in candidates if delays[n] < 100.0 - tie]
    tied = [n for n in candidates if n not in ours and not delays[n] >= 100.0 + tie]
    paper = [n for n in PAPER_BEAT_LOWPASS if n in result.names]
    if set(ours) == set(paper) and not tied:
        decided = HOLDS
    elif set(ours) <= set(paper) <= set(ours) | set(tied):
        decided = UNDECIDED
    else:
        decided = FAILS
    text = (", ".join(ours) or "none") + (f"; tied with LOWPASS on |delay|: {', '.join(tied)}" if tied else "")
    return _row(f"beat LOWPASS on both error and |delay| ({_group('b')})",
                f"only {' and '.join(PAPER_BEAT_LOWPASS)} (Sec. 7.4, Fig. 5b)",
                "the estimators with median error and median |delay| below 100 % of LOWPASS are exactly "
                + (", ".join(paper) or "none"), text, decided)


def _validation(finding, paper, mean, std, unit):
    paper_mean, paper_std = paper
    return _row(finding, f"{paper_mean:g} +- {paper_std:g} {unit} (Sec. 7.3)",
                f"our mean within a factor {FACTOR:g} ({paper_mean / FACTOR:g} to {paper_mean * FACTOR:g} {unit})",
                f"{_g(mean)} +- {_g(std)} {unit}", within_factor(mean, paper_mean))


def validation_error(summary):
    return _validation("validation error difference, mean +- sd", PAPER_VALIDATION_ERROR_PCT,
                       summary["error_difference_pct_mean"], summary["error_difference_pct_std"], "%")


def validation_delay(summary):
    return _validation("validation delay difference, mean +- sd", PAPER_VALIDATION_DELAY,
                       summary["delay_difference_mean"], summary["delay_difference_std"], "samples")


def findings(result, foaw_fraction=None, validation=None):
    """``findings.csv`` rows from an ``report.Evaluation``, FOAW's fraction at its maximum and a validation summary."""
    a, b = result.group_mask("a"), result.group_mask("b")
    names = set(result.names)
    rows = []
    if a.any():
        if PAPER_BEST in names:
            rows.append(kalman_best(result, a))
        if len(names & set(THIRD_ORDER_KALMAN)) >= 2:
            rows.append(third_order_best(result, a))
        if len(names) >= 2:
            rows.append(best_six_not_different(result, a))
        if any(x in names and y in names for x, y in ACCELEROMETER_PAIRS):
            rows.append(accelerometer_gain(result, a))
        if "LEVANT" in names:
            rows.append(levant_error(result, a))
        if "FOAW" in names:
            rows += [foaw_error(result, a), foaw_delay(result, a)]
    if "FOAW" in names and foaw_fraction is not None:
        rows.append(foaw_window_at_maximum(foaw_fraction, result.params["FOAW"]["window"]))
    if a.any() and "LEASTSQ" in names:
        rows.append(leastsq_delay(result, a))
    if b.any():
        rows.append(beat_lowpass(result, b))
    if validation is not None:
        rows += [validation_error(validation), validation_delay(validation)]
    return rows
