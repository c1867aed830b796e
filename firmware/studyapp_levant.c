/* LEVANT and LEVANTLP: Levant's two-sliding differentiator (paper Sec. 5.4, eqs. 10-15), explicit Euler, as
 * studyapp/estimators/levant.py:
 *     e = w - x_k,  u = u1 - lambda sqrt|e| sgn(e)  (the output),  w <- w + T u,  u1 <- u1 - T alpha sgn(e)
 * with alpha = 1.1 C and lambda = sqrt(C) computed on the host.
 *
 * LEVANT state [started, w, u1], parameters [alpha, lambda, T, from_first];
 * LEVANTLP state [started, w, u1, z1, z2], parameters [alpha, lambda, T, from_first, section(5)].
 * Uses sqrt, fabs and copysign (exact in IEEE 754).
 */
#include "studyapp_estimator_kernels.h"

#include <math.h>

#define LEVANT_STATE 3
#define LEVANT_PARAMS 4

/* np.sign as numba computes it: 1 above 0, -1 below, else the value itself (so -0.0 and NaN pass) */
static double sign_of(double e) {
    if (e > 0.0) return 1.0;
    if (e < 0.0) return -1.0;
    return e;
}

double se_levant_core(double *s, double alpha, double lam, double period, double from_first, double x) {
    double e, sign, u;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = x * from_first;
        s[2] = 0.0;
    }
    e = s[1] - x;
    sign = sign_of(e);
    u = s[2] - lam * copysign(sqrt(fabs(e)), e);
    s[1] += period * u;
    s[2] -= period * alpha * sign;
    return u;
}

/* levant.step_levant */
double se_kernel_levant(double *s, const double *p, double x, double a, double v) {
    (void)a;
    (void)v;
    return se_levant_core(s, p[0], p[1], p[2], p[3], x);
}

/* levant.step_levantlp: LEVANT, then the Butterworth low-pass */
double se_kernel_levantlp(double *s, const double *p, double x, double a, double v) {
    double u;
    (void)a;
    (void)v;
    u = se_levant_core(s, p[0], p[1], p[2], p[3], x);
    return se_section_step(p + LEVANT_PARAMS, s + LEVANT_STATE, u);
}
