/* KALLEV, KALLEVACC, KALFOAW, KALFOAWACC: KALMAN fed with an acceleration differentiated twice from the
 * position (paper Sec. 5.7), as studyapp/estimators/hybrids.py:
 *     KALLEV  K(x, L(L(x)))     KALLEVACC  K(x, L(L(x)) + H(a))
 *     KALFOAW K(x, F(F(x)))     KALFOAWACC K(x, F(F(x)) + H(a))
 * with K = KALMAN (studyapp_kalman.c), L = LEVANT (studyapp_levant.c), F = FOAW (studyapp_foaw.c) and H a
 * Butterworth high-pass primed at the first sample.
 *
 * State: KALMAN's 10, z_a (the acceleration K saw last), then H's z1 z2 (ACC variants), then two LEVANT
 * states of 3 or two FOAW states. Parameters: KALMAN's 12, then [alpha, lambda, T, from_first] (LEVANT) or
 * [N, margin, margin_vel, rate] (FOAW), then H's section(5) (ACC variants).
 */
#include "studyapp_estimator_kernels.h"

#define KALMAN_STATE 10
#define KALMAN_PARAMS 12
#define Z_A KALMAN_STATE         /* state slot: the acceleration measurement of the last step */
#define AFTER (KALMAN_STATE + 1) /* first state slot after K and z_a */
#define P KALMAN_PARAMS          /* first parameter after K's */
#define LEVANT_STATE 3
#define FRONT_PARAMS 4           /* LEVANT's or FOAW's parameters before H's section */
#define SECTION_STATE 2

/* hybrids._levant_twice: L(L(x)) on two LEVANT states from s[0], parameters p[0..3] */
static double levant_twice(double *s, const double *p, double x) {
    double v1 = se_levant_core(s, p[0], p[1], p[2], p[3], x);
    return se_levant_core(s + LEVANT_STATE, p[0], p[1], p[2], p[3], v1);
}

/* hybrids._foaw_twice: F(F(x)) on two FOAW states from s[0], parameters p[0..3] */
static double foaw_twice(double *s, const double *p, double x) {
    int size = se_foaw_state_size(p[0]);
    double v1 = se_foaw_core(s, p[0], p[1], p[3], x);
    return se_foaw_core(s + size, p[0], p[2], p[3], v1);
}

/* hybrids._highpass: H(a), primed at the first sample (when K has not started yet) */
static double highpass(double *s, const double *p, double a) {
    if (s[0] == 0.0) se_section_prime(p, s + AFTER, a);
    return se_section_step(p, s + AFTER, a);
}

double se_kernel_kallev(double *s, const double *p, double x, double a, double v) {
    double z;
    (void)a;
    (void)v;
    z = levant_twice(s + AFTER, p + P, x);
    s[Z_A] = z;
    return se_kalman_step(s, p, x, z);
}

double se_kernel_kallevacc(double *s, const double *p, double x, double a, double v) {
    double h, z;
    (void)v;
    h = highpass(s, p + P + FRONT_PARAMS, a);
    z = levant_twice(s + AFTER + SECTION_STATE, p + P, x) + h;
    s[Z_A] = z;
    return se_kalman_step(s, p, x, z);
}

double se_kernel_kalfoaw(double *s, const double *p, double x, double a, double v) {
    double z;
    (void)a;
    (void)v;
    z = foaw_twice(s + AFTER, p + P, x);
    s[Z_A] = z;
    return se_kalman_step(s, p, x, z);
}

double se_kernel_kalfoawacc(double *s, const double *p, double x, double a, double v) {
    double h, z;
    (void)v;
    h = highpass(s, p + P + FRONT_PARAMS, a);
    z = foaw_twice(s + AFTER + SECTION_STATE, p + P, x) + h;
    s[Z_A] = z;
    return se_kalman_step(s, p, x, z);
}
