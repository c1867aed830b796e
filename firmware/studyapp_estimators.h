/* studyapp's velocity estimators in portable C99: every compiled kernel of studyapp/estimators/, operation
 * for operation, so that on one machine the C and the numba kernels give the same bits (tests/estimators/
 * test_estimators_c.py holds them equal, every sample's output and the whole state vector).
 *
 * No allocation, no state outside the caller's arrays, double precision throughout. Build with
 *     cc -std=c99 -O2 -ffp-contract=off ...   (studyapp/device/c_core.py's FLAGS)
 * -ffp-contract=off matters: a * b + c must stay a rounded product and a rounded sum, as numba computes it
 * (numba emits no fused multiply-add); never -ffast-math (it reorders sums and drops NaN/-0 rules).
 *
 * One sample of one estimator:
 *     v_hat = se_step_guarded(kind, s, p, x, a, v);
 * kind is one of the SE_ ids below (studyapp/estimators/kinds.py); x, a, v are the position (m), the
 * acceleration (m/s^2) and the tachometer velocity (m/s), 0.0 for a sensor the device lacks. p is the
 * estimator's parameter vector and s its state vector (zeros at the start), both exactly the float64 arrays
 * of studyapp.estimators.Estimator (.p, .state) or one row of a Bank (.params, .states): the host builds the
 * parameters once (filter design, exact least-squares taps, Kalman noise) and hands them over; the kernels
 * only step. Row widths of a Bank are padded with zeros, which the kernels never read.
 *
 * The bad-input guard (studyapp/estimators/dispatch.py, bounds.py): a sample that is NaN, inf or beyond its
 * bound (|x| <= 1 m, |a| <= 1e5 m/s^2, |v| <= 100 m/s are good) is replaced by that input's last good sample
 * (0.0 before the first) and counted. s[0..3] = last x, last a, last v, bad count; the kernel's own state
 * follows from s[SE_GUARD]. se_step is the kernel alone (dispatch.step_any): s is then the kernel's state.
 *
 * An unknown kind: se_known(kind) is 0, and se_step / se_step_guarded return NaN and leave s untouched
 * (the numba dispatch raises ValueError there). Check se_known once when the bank is set up.
 *
 * Maths library. The kernels use sqrt, fabs and copysign from <math.h> (LEVANT's observer, eq. 11, and the
 * guard's |x|), and the NAN macro. IEEE 754 specifies all three exactly: sqrt is correctly rounded, fabs and
 * copysign only touch the sign bit. No kernel calls exp, log, pow, tan or tanh (the filter design that needs
 * them is done on the host, in Python), so a conforming platform's libm cannot change a bit here. What can:
 *   - double not IEEE binary64 (some 8-bit targets make double a 32-bit float);
 *   - FLT_EVAL_METHOD != 0: 32-bit x86 with the x87 unit keeps 80-bit intermediates (use -msse2
 *     -mfpmath=sse); ARM, x86-64 and RISC-V with a double FPU evaluate in double;
 *   - fused multiply-add contraction (compile with -ffp-contract=off) or -ffast-math;
 *   - subnormals flushed to zero (the FZ bit of ARM's FPSCR, x86's FTZ/DAZ): within the parameters' bounds
 *     the numbers stay far above the subnormal range (the smallest, the Kalman filters' scaled noise
 *     q T^5, is about 1e-34 at q = 1e-9 and 96 kHz), but a product of small numbers can still land there;
 *     leave FZ off;
 *   - NaN payloads: a kernel whose state became NaN (not seen with validated parameters and guarded input)
 *     would return a NaN whose sign and payload bits may differ between compilers; never its being NaN.
 */
#ifndef STUDYAPP_ESTIMATORS_H
#define STUDYAPP_ESTIMATORS_H

#define SE_GUARD 4 /* = dispatch.GUARD: the guard's slots at the head of every state vector */

#define SE_POSITION_BOUND 1.0      /* m, bounds.POSITION_BOUND */
#define SE_ACCELERATION_BOUND 1e5  /* m/s^2, bounds.ACCELERATION_BOUND */
#define SE_VELOCITY_BOUND 100.0    /* m/s, bounds.VELOCITY_BOUND */

/* = studyapp/estimators/kinds.py (the order of studyapp.estimators.names()) */
enum {
    SE_BDIFF = 0,
    SE_LOWPASS = 1,
    SE_LEASTSQ = 2,
    SE_FOAW = 3,
    SE_LEVANT = 4,
    SE_LEVANTLP = 5,
    SE_KALPOS = 6,
    SE_KALMAN = 7,
    SE_KALLEV = 8,
    SE_KALLEVACC = 9,
    SE_KALFOAW = 10,
    SE_KALFOAWACC = 11,
    SE_COMP1 = 12,
    SE_COMP2 = 13,
    SE_LVT = 14,
    SE_KINDS = 15 /* the number of kinds */
};

/* 1 if kind has a kernel, else 0 */
int se_known(int kind);

/* one sample with the bad-input guard (dispatch.step_guarded); s has SE_GUARD slots before the kernel's */
double se_step_guarded(int kind, double *s, const double *p, double x, double a, double v);

/* one sample of the kernel alone (dispatch.step_any): no guard, s is the kernel's own state */
double se_step(int kind, double *s, const double *p, double x, double a, double v);

/* out[i] = se_step_guarded(kind, s, p, xs[i], as[i], vs[i]) for i = 0 .. n-1 (dispatch.run_block) */
void se_run(int kind, double *s, const double *p, const double *xs, const double *as, const double *vs,
            double *out, long n);

#endif
