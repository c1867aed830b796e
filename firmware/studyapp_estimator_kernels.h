/* The estimators' kernels and the building blocks they share, for the C files of studyapp_estimators.h
 * (a firmware calls studyapp_estimators.h, not these). Each mirrors its namesake in studyapp/estimators/,
 * statement for statement: a kernel's signature is the numba kernels' step(s, p, x, a, v), s its own state
 * (after the guard's slots) and p its parameter vector, laid out as that module's docstring says.
 */
#ifndef STUDYAPP_ESTIMATOR_KERNELS_H
#define STUDYAPP_ESTIMATOR_KERNELS_H

/* biquad.section_step: one 2nd-order section in transposed direct form II, p = b0 b1 b2 a1 a2, s = z1 z2 */
static inline double se_section_step(const double *p, double *s, double x) {
    double y = p[0] * x + s[0];
    s[0] = p[1] * x - p[3] * y + s[1];
    s[1] = p[2] * x - p[4] * y;
    return y;
}

/* biquad.section_prime: the section's state at rest under the constant input x */
static inline void se_section_prime(const double *p, double *s, double x) {
    double g = (p[0] + p[1] + p[2]) / (1.0 + p[3] + p[4]);
    double y = g * x;
    s[1] = p[2] * x - p[4] * y;
    s[0] = y - p[0] * x;
}

/* foaw.foaw_state_size / foaw_core: s is the FOAW state's first slot (foaw_core's s[at]) */
int se_foaw_state_size(double longest);
double se_foaw_core(double *s, double longest, double margin, double rate, double x);

/* levant.levant_core on the state [started, w, u1] */
double se_levant_core(double *s, double alpha, double lam, double period, double from_first, double x);

/* kalman.kalman_step on KALMAN's 10 state slots and its 12 parameters; a is the acceleration measured */
double se_kalman_step(double *s, const double *p, double x, double a);

double se_kernel_bdiff(double *s, const double *p, double x, double a, double v);
double se_kernel_lowpass(double *s, const double *p, double x, double a, double v);
double se_kernel_leastsq(double *s, const double *p, double x, double a, double v);
double se_kernel_foaw(double *s, const double *p, double x, double a, double v);
double se_kernel_levant(double *s, const double *p, double x, double a, double v);
double se_kernel_levantlp(double *s, const double *p, double x, double a, double v);
double se_kernel_kalpos(double *s, const double *p, double x, double a, double v);
double se_kernel_kalman(double *s, const double *p, double x, double a, double v);
double se_kernel_kallev(double *s, const double *p, double x, double a, double v);
double se_kernel_kallevacc(double *s, const double *p, double x, double a, double v);
double se_kernel_kalfoaw(double *s, const double *p, double x, double a, double v);
double se_kernel_kalfoawacc(double *s, const double *p, double x, double a, double v);
double se_kernel_complementary(double *s, const double *p, double x, double a, double v);
double se_kernel_lvt(double *s, const double *p, double x, double a, double v);

#endif
