/* The dispatch, the bad-input guard (studyapp/estimators/dispatch.py, bounds.py) and the short kernels:
 * BDIFF (bdiff.py), LOWPASS (lowpass.py), LEASTSQ (leastsq.py), COMP1/COMP2 (complementary.py), LVT (lvt.py).
 * See studyapp_estimators.h. */
#include "studyapp_estimators.h"
#include "studyapp_estimator_kernels.h"

#include <math.h>

int se_known(int kind) { return kind >= 0 && kind < SE_KINDS; }

double se_step(int kind, double *s, const double *p, double x, double a, double v) {
    switch (kind) {
    case SE_BDIFF: return se_kernel_bdiff(s, p, x, a, v);
    case SE_LOWPASS: return se_kernel_lowpass(s, p, x, a, v);
    case SE_LEASTSQ: return se_kernel_leastsq(s, p, x, a, v);
    case SE_FOAW: return se_kernel_foaw(s, p, x, a, v);
    case SE_LEVANT: return se_kernel_levant(s, p, x, a, v);
    case SE_LEVANTLP: return se_kernel_levantlp(s, p, x, a, v);
    case SE_KALPOS: return se_kernel_kalpos(s, p, x, a, v);
    case SE_KALMAN: return se_kernel_kalman(s, p, x, a, v);
    case SE_KALLEV: return se_kernel_kallev(s, p, x, a, v);
    case SE_KALLEVACC: return se_kernel_kallevacc(s, p, x, a, v);
    case SE_KALFOAW: return se_kernel_kalfoaw(s, p, x, a, v);
    case SE_KALFOAWACC: return se_kernel_kalfoawacc(s, p, x, a, v);
    case SE_COMP1:
    case SE_COMP2: return se_kernel_complementary(s, p, x, a, v);
    case SE_LVT: return se_kernel_lvt(s, p, x, a, v);
    default: return NAN;
    }
}

/* bounds.good: NaN compares false, so one test refuses NaN, inf and the absurd */
static int good(double value, double bound) { return fabs(value) <= bound; }

double se_step_guarded(int kind, double *s, const double *p, double x, double a, double v) {
    int bad = 0;
    if (!se_known(kind)) return NAN;
    if (good(x, SE_POSITION_BOUND)) {
        s[0] = x;
    } else {
        x = s[0];
        bad = 1;
    }
    if (good(a, SE_ACCELERATION_BOUND)) {
        s[1] = a;
    } else {
        a = s[1];
        bad = 1;
    }
    if (good(v, SE_VELOCITY_BOUND)) {
        s[2] = v;
    } else {
        v = s[2];
        bad = 1;
    }
    if (bad) s[3] += 1.0;
    return se_step(kind, s + SE_GUARD, p, x, a, v);
}

void se_run(int kind, double *s, const double *p, const double *xs, const double *as, const double *vs,
            double *out, long n) {
    long i;
    for (i = 0; i < n; i++) out[i] = se_step_guarded(kind, s, p, xs[i], as[i], vs[i]);
}

/* history.fill: every past sample equal to the first one (at rest before the stream) */
static void fill(double *history, int n, double x) {
    int i;
    for (i = 0; i < n; i++) history[i] = x;
}

/* bdiff.step: v = (x_k - x_{k-z}) / (z T); s = [started, head, ring of z], p = [z, z T] */
double se_kernel_bdiff(double *s, const double *p, double x, double a, double v) {
    int z = (int)p[0];
    double *ring = s + 2;
    int head;
    double old;
    (void)a;
    (void)v;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        fill(ring, z, x);
    }
    head = (int)s[1];
    old = ring[head];
    ring[head] = x;
    s[1] = (head + 1) % z;
    return (x - old) / p[1];
}

/* lowpass.step: the first difference through a Butterworth section; s = [started, x_{k-1}, z1, z2],
 * p = [1/T, section(5)] */
double se_kernel_lowpass(double *s, const double *p, double x, double a, double v) {
    double d;
    (void)a;
    (void)v;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = x;
    }
    d = (x - s[1]) * p[0];
    s[1] = x;
    return se_section_step(p + 1, s + 2, d);
}

/* leastsq.step: FIR taps on a ring of M samples; s = [started, head, ring of M], p = [M, taps(M)] with
 * taps[j] multiplying x_{k-j} */
double se_kernel_leastsq(double *s, const double *p, double x, double a, double v) {
    int m = (int)p[0];
    double *ring = s + 2;
    int head, i, j;
    double acc;
    (void)a;
    (void)v;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        fill(ring, m, x);
    }
    head = (int)s[1];
    ring[head] = x;
    acc = 0.0;
    j = head;
    for (i = 0; i < m; i++) {
        acc += p[1 + i] * ring[j];
        j -= 1;
        if (j < 0) j = m - 1;
    }
    s[1] = (head + 1) % m;
    return acc;
}

/* complementary.step: LP of the first difference plus the integrating HP of the acceleration;
 * s = [started, x_{k-1}, lp z1 z2, hp z1 z2], p = [1/T, lp section(5), integrating hp section(5)] */
double se_kernel_complementary(double *s, const double *p, double x, double a, double v) {
    double d, low;
    (void)v;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = x;
    }
    d = (x - s[1]) * p[0];
    s[1] = x;
    low = se_section_step(p + 1, s + 2, d);
    return low + se_section_step(p + 6, s + 4, a);
}

/* lvt.step: the tachometer, passed through */
double se_kernel_lvt(double *s, const double *p, double x, double a, double v) {
    (void)s;
    (void)p;
    (void)x;
    (void)a;
    return v;
}
