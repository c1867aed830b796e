"""The in-silico pilot's figures (issue 30): Fig. 7 against the paper's order, and how much of its spread is the person's.

A pilot is a set of simulated participants of ``sinclair2014`` (one session
each, seeded), analysed like people. For one set, from its non-practice
adjustment responses (F_max in N, participant p, condition c, trial t):

- **Fig. 7 medians**: the median F_max per condition, all trials of all
  participants pooled (``studyapp analyse``'s ``summary_adjustment.csv``).
- **rho**: Spearman's rho between those medians and the paper's Fig. 7 order
  (Sec. 9.1), ``PAPER_FIG7_RANK``: LVT first, LEVANT second, KALPOS and LOWPASS
  next (tied: the paper names them together), the other four tied in the
  middle, FOAW last. A rank of 1 is best, so rho is taken against minus the rank.
- **Variance components**: per condition, a one-way random-effects model of
  y = log10 F_max (the knob is logarithmic, so a person's criterion shifts y):
  y_pt = mu + a_p + e_pt, var(a) = s_b^2 (between participants), var(e) = s_w^2
  (within). With k participants, N trials, n_p trials of participant p:

      MS_w = sum_p sum_t (y_pt - ybar_p)^2 / (N - k)
      MS_b = sum_p n_p (ybar_p - ybar)^2 / (k - 1)
      n0   = (N - sum_p n_p^2 / N) / (k - 1)          (= n when balanced)
      s_w^2 = MS_w,  s_b^2 = max(0, (MS_b - MS_w) / n0)

  (the ANOVA estimators; ``scipy.stats.f_oneway``'s F is MS_b / MS_w).
  ``within_lower_pct`` = 100 (1 - s_w^2 / (s_w^2 + s_b^2)), how far the
  within-participant variance lies below the total, the intraclass correlation
  ICC(1) in per cent; the paper's "intra-subject variance was on average 61
  percent lower" (Sec. 9.1) is read the same way (as
  ``studyapp.analysis.consistency`` reads it, there on F_max in N with plain
  sample variances), averaged over conditions.
"""

import numpy as np

from studyapp.stats.spearman import spearman

PAPER_FIG7_RANK = {"LVT": 1.0, "LEVANT": 2.0, "KALPOS": 3.5, "LOWPASS": 3.5,
                   "LEASTSQ": 6.5, "LEVANTLP": 6.5, "KALLEV": 6.5, "KALFOAW": 6.5, "FOAW": 9.0}


def rho_against_paper(medians):
    """Spearman's rho of ``{condition: median F_max}`` against the paper's Fig. 7 order (its conditions only)."""
    conditions = [c for c in PAPER_FIG7_RANK if c in medians]
    rho, _ = spearman([medians[c] for c in conditions], [-PAPER_FIG7_RANK[c] for c in conditions])
    return rho


def variance_components(groups):
    """(s_w^2, s_b^2) of the one-way random-effects model over ``groups``, one array of values per participant."""
    groups = [np.asarray(g, dtype=float) for g in groups if len(g)]
    sizes = np.array([g.size for g in groups], dtype=float)
    k, total = len(groups), sizes.sum()
    if k < 2 or total <= k:
        return float("nan"), float("nan")
    grand = np.concatenate(groups).mean()
    ms_within = sum(((g - g.mean()) ** 2).sum() for g in groups) / (total - k)
    ms_between = sum(g.size * (g.mean() - grand) ** 2 for g in groups) / (k - 1)
    n0 = (total - (sizes ** 2).sum() / total) / (k - 1)
    return float(ms_within), float(max(0.0, (ms_between - ms_within) / n0))


def within_lower_pct(groups):
    """100 (1 - s_w^2 / (s_w^2 + s_b^2)) of ``groups`` (per participant), nan when there is no spread at all."""
    within, between = variance_components(groups)
    total = within + between
    return 100.0 * (1.0 - within / total) if total > 0 else float("nan")


def pilot_figures(responses):
    """The set's figures from a DataFrame of adjustment responses with ``participant, condition, fmax``:
    ``{"medians": {condition: N}, "rho": float, "within_lower_pct": {condition: %}, "mean_within_lower_pct": %}``."""
    medians = {c: float(v) for c, v in responses.groupby("condition")["fmax"].median().sort_values(ascending=False).items()}
    lower = {}
    for condition, rows in responses.groupby("condition"):
        logs = np.log10(rows["fmax"].to_numpy(dtype=float))
        lower[condition] = within_lower_pct([logs[rows["participant"].to_numpy() == p]
                                             for p in sorted(set(rows["participant"]))])
    finite = [v for v in lower.values() if np.isfinite(v)]
    return {"medians": medians, "rho": rho_against_paper(medians), "within_lower_pct": lower,
            "mean_within_lower_pct": float(np.mean(finite)) if finite else float("nan")}
