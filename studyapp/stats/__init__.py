"""The statistical tests and helpers that the study analysis and the numerical evaluation share.

    rank_sum.rank_sum_test(a, b)        Wilcoxon rank-sum (paper Sec. 7.2 and 9, ref. [28]): z and p
    signed_rank.signed_rank_test(a, b)  Wilcoxon signed-rank of paired samples (within subject)
    friedman.friedman_test(table)       Friedman's test over k conditions x n participants
    holm.holm_adjust(p)                 Holm's step-down adjustment of a family of p-values
    spearman.spearman(x, y)             Spearman's rho and its two-sided p
    compact_letters.compact_letters(...) the letter display of which conditions differ

Plain functions on arrays, on numpy and scipy only: no studyapp layer above. Where
scipy has the test itself (rank-sum p, ranks, Spearman) it is scipy's, with the
statistic or guard the study needs around it; the tests check every number against scipy
or a count by hand.
"""
