/* FOAW: first-order adaptive windowing, best-fit method (paper Sec. 5.3), as studyapp/estimators/foaw.py.
 *
 * With d_i = y_{k-i} - y_k, S0 = sum d_i and S1 = sum i d_i over i = 0 .. n, window n's slope per sample is
 * b_n = 6 (n S0 - 2 S1) / (n (n+1) (n+2)); window n passes while L_n <= b_n <= U_n, the running extremes of
 * (-d - d_j) / j and (d - d_j) / j over the interior samples j = 1 .. n-1. The output is the slope of the
 * last window that passed, times the rate.
 *
 * State from s[0] (foaw_state_size(N) = 3 + 4 (N + 1) slots, N the longest window in intervals):
 * [started, head, chosen n, ring of N+1 samples stored twice, 1/j table, 6/(n(n+1)(n+2)) table].
 * Parameters of the FOAW kernel: [N, d, rate].
 */
#include "studyapp_estimator_kernels.h"

#include <math.h>

#define CHOSEN 2 /* state slot: the window n chosen at the last step */
#define RING 3   /* first slot of the ring */

int se_foaw_state_size(double longest) { return RING + 4 * ((int)longest + 1); }

double se_foaw_core(double *s, double longest, double margin, double rate, double x) {
    int big = (int)longest;
    int m = big + 1;
    int ring = RING;
    int inv = ring + 2 * m; /* 1 / j: the inner loop multiplies, never divides */
    int fit = ring + 3 * m; /* 6 / (n (n+1) (n+2)) */
    int head, newest, n, i, j, chosen;
    double s0, s1, best, low, high, d, b, dj, bound;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = 0.0;
        for (i = 0; i < 2 * m; i++) s[ring + i] = x;
        for (j = 1; j < m; j++) {
            s[inv + j] = 1.0 / (double)j;
            s[fit + j] = 6.0 / ((double)j * ((double)j + 1.0) * ((double)j + 2.0));
        }
    }
    head = (int)s[1] - 1;
    if (head < 0) head = m - 1;
    s[1] = head;
    newest = ring + head;
    s[newest] = x;
    s[newest + m] = x;
    s0 = 0.0;
    s1 = 0.0;
    best = 0.0;
    chosen = 1;
    low = -INFINITY; /* L_n: the slope must be at least this for every interior sample to pass */
    high = INFINITY; /* U_n: ... and at most this */
    for (n = 1; n < big + 1; n++) {
        d = s[newest + n] - x;
        s0 += d;
        s1 += (double)n * d;
        b = ((double)n * s0 - 2.0 * s1) * s[fit + n];
        if (n > 1) {
            j = n - 1;
            dj = s[newest + j] - x;
            /* Python's max(low, c) and min(high, c): c only when it compares greater (less) */
            bound = (-margin - dj) * s[inv + j];
            if (bound > low) low = bound;
            bound = (margin - dj) * s[inv + j];
            if (bound < high) high = bound;
            if (b < low || b > high) break;
        }
        best = b;
        chosen = n;
    }
    s[CHOSEN] = chosen;
    return best * rate;
}

/* foaw.step */
double se_kernel_foaw(double *s, const double *p, double x, double a, double v) {
    (void)a;
    (void)v;
    return se_foaw_core(s, p[0], p[1], p[2], x);
}
