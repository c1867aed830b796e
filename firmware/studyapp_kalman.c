/* KALPOS and KALMAN: Kalman filters on a driven-mass model (paper Sec. 5.6, eqs. 16-19), as
 * studyapp/estimators/kalman.py: the scaled state y = [x, T v, T^2 a], the covariance kept as U D U^T,
 * Thornton's weighted Gram-Schmidt time update and Bierman's scalar measurement updates, unrolled.
 *
 * KALMAN state (10): [started, y0, y1, y2, u01, u02, u12, d0, d1, d2];
 *   parameters (12): [rate, T^2, q_g, r_pos, T^4 r_acc, P0_x, T^2 P0_v, T^4 P0_a, g_0, g_1, q_h, q_e].
 * KALPOS state (6): [started, y0, y1, u01, d0, d1]; parameters (6): [rate, q_g, r_pos, P0_x, T^2 P0_v, q_e].
 * No maths library function: + - * / only.
 */
#include "studyapp_estimator_kernels.h"

double se_kalman_step(double *s, const double *p, double x, double a) {
    double q, g0, g1, qh, qe, u01, u02, u12, d0, d1, d2, y0, y1, y2;
    double w01, w02, w12, w03, w13, w04, d2n, u02n, u12n, d1n, u01n, d0n;
    double r, alpha, b0, b1, v1, v2, beta, lam, u01_old, u02_old, u12_old, e;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = x;
        s[2] = 0.0;
        s[3] = 0.0;
        s[4] = 0.0;
        s[5] = 0.0;
        s[6] = 0.0;
        s[7] = p[5];
        s[8] = p[6];
        s[9] = p[7];
        return 0.0;
    }
    q = p[2];
    g0 = p[8];
    g1 = p[9];
    qh = p[10];
    qe = p[11];
    u01 = s[4];
    u02 = s[5];
    u12 = s[6];
    d0 = s[7];
    d1 = s[8];
    d2 = s[9];
    /* predict: y = F_s y with F_s = [[1, 1, 1/2], [0, 1, 1], [0, 0, 1]] */
    y0 = s[1] + s[2] + 0.5 * s[3];
    y1 = s[2] + s[3];
    y2 = s[3];
    /* P- = W diag(d0, d1, d2, q_g, q_h, q_e) W^T with W = [F_s U | g h e_x]; Thornton, last row first */
    w01 = u01 + 1.0;
    w02 = u02 + u12 + 0.5;
    w12 = u12 + 1.0;
    d2n = d2 + q;
    u02n = (w02 * d2 + g0 * q) / d2n;
    u12n = (w12 * d2 + g1 * q) / d2n;
    w02 -= u02n;
    w03 = g0 - u02n;
    w12 -= u12n;
    w13 = g1 - u12n;
    d1n = d1 + d2 * w12 * w12 + q * w13 * w13 + qh;
    u01n = (w01 * d1 + w02 * w12 * d2 + w03 * w13 * q + 0.5 * qh) / d1n;
    w01 -= u01n;
    w02 -= u01n * w12;
    w03 -= u01n * w13;
    w04 = 0.5 - u01n;
    d0n = d0 + d1 * w01 * w01 + d2 * w02 * w02 + q * w03 * w03 + qh * w04 * w04 + qe;
    /* Bierman's update with the position, H = e_0: f = U^T e_0 = [1, u01, u02] */
    r = p[3];
    alpha = r + d0n;
    b0 = d0n;
    d0n *= r / alpha;
    v1 = d1n * u01n;
    beta = alpha;
    alpha += v1 * u01n;
    d1n *= beta / alpha;
    b1 = v1;
    u01_old = u01n;
    u01n -= u01n / beta * b0;
    b0 += u01_old * v1;
    v2 = d2n * u02n;
    beta = alpha;
    alpha += v2 * u02n;
    d2n *= beta / alpha;
    lam = u02n / beta;
    u02_old = u02n;
    u12_old = u12n;
    u02n -= lam * b0;
    u12n -= lam * b1;
    b0 += u02_old * v2;
    b1 += u12_old * v2;
    e = (x - y0) / alpha;
    y0 += b0 * e;
    y1 += b1 * e;
    y2 += v2 * e;
    /* Bierman's update with the scaled acceleration T^2 a, H = e_2: f = [0, 0, 1]; U is unchanged */
    r = p[4];
    alpha = r + d2n;
    e = (a * p[1] - y2) / alpha;
    y0 += u02n * d2n * e;
    y1 += u12n * d2n * e;
    y2 += d2n * e;
    d2n *= r / alpha;
    s[1] = y0;
    s[2] = y1;
    s[3] = y2;
    s[4] = u01n;
    s[5] = u02n;
    s[6] = u12n;
    s[7] = d0n;
    s[8] = d1n;
    s[9] = d2n;
    return y1 * p[0];
}

/* kalman.step_kalman */
double se_kernel_kalman(double *s, const double *p, double x, double a, double v) {
    (void)v;
    return se_kalman_step(s, p, x, a);
}

/* kalman.step_kalpos */
double se_kernel_kalpos(double *s, const double *p, double x, double a, double v) {
    double q, u01, d0, d1, y0, y1, w01, d1n, u01n, w02, d0n, r, alpha, b0, v1, beta, u01_old, e;
    (void)a;
    (void)v;
    if (s[0] == 0.0) {
        s[0] = 1.0;
        s[1] = x;
        s[2] = 0.0;
        s[3] = 0.0;
        s[4] = p[3];
        s[5] = p[4];
        return 0.0;
    }
    q = p[1];
    u01 = s[3];
    d0 = s[4];
    d1 = s[5];
    /* predict: y = F_s y with F_s = [[1, 1], [0, 1]]; W = [F_s U | g e_x], g = [1/2, 1]^T,
     * weights diag(d0, d1, q_g, q_e) */
    y0 = s[1] + s[2];
    y1 = s[2];
    w01 = u01 + 1.0;
    d1n = d1 + q;
    u01n = (w01 * d1 + 0.5 * q) / d1n;
    w01 -= u01n;
    w02 = 0.5 - u01n;
    d0n = d0 + d1 * w01 * w01 + q * w02 * w02 + p[5]; /* p[5] = q_e */
    /* Bierman's update with the position: f = [1, u01] */
    r = p[2];
    alpha = r + d0n;
    b0 = d0n;
    d0n *= r / alpha;
    v1 = d1n * u01n;
    beta = alpha;
    alpha += v1 * u01n;
    d1n *= beta / alpha;
    u01_old = u01n;
    u01n -= u01n / beta * b0;
    b0 += u01_old * v1;
    e = (x - y0) / alpha;
    s[1] = y0 + b0 * e;
    s[2] = y1 + v1 * e;
    s[3] = u01n;
    s[4] = d0n;
    s[5] = d1n;
    return s[2] * p[0];
}
