/* studyapp's haptic loop, one sample, in portable C99: the controller of studyapp/model/control.py
 * (``sample``) with every estimator of the bank stepped on the same sample, as the paper ran them on its
 * device (Sec. 8.4). Given the same parameter vectors and the same sensor samples it gives the numba
 * loop's numbers bit for bit (tests/device/test_c_loop.py).
 *
 * One sample k:
 *     sensors x_m (m), a_m (m/s^2), v_m (m/s); a non-finite one latches FAULT_SENSOR
 *     -> the source velocity: estimator ctl[C_SOURCE] stepped by se_step_guarded, or the LVT sensor v_m
 *        (C_SOURCE = -2); any other index (TRUE = -1, none here) gives NaN, which latches FAULT_ESTIMATE
 *     -> bow: v_bow = ctl[C_SCALE] * v_source while bowing (ctl[C_BOWING] != 0) and not faulted
 *     -> the bowed string (studyapp/model/bowed_string.py): u = rho(v_delta) v_delta, |u| <= peak
 *        (bow_table.py); a non-finite string latches FAULT_STRING and puts the string at rest
 *     -> F = -ctl[C_GAIN] * u * ctl[C_FORCE_SCALE]  (C_GAIN = F_max / peak, paper eq. 20)
 *     -> the motor limits (studyapp/model/device.py clamp_force); non-finite latches FAULT_FORCE;
 *        once faulted the force is 0 and the bow lifted, until the host clears state[L_FAULT]
 *     -> every other estimator of the bank on (x_m, a_m, v_m)
 * The body filter, the contact microphone and the stability monitor are not here: they stay on the
 * host, which plays the bridge velocity (sl_out.bridge_velocity) through its audio chain.
 *
 * Memory: the caller owns everything (no allocation), float64 unless said:
 *     ctl      SL_N_CONTROL          the control vector; the host changes it between samples
 *                                    (source, F_max via C_GAIN, force scale, bowing)
 *     state    SL_N_LOOP_STATE       fault code and the sample it latched at (0 = no fault)
 *     lp, ls   SL_N_LIMIT_PARAMS, SL_N_LIMIT_STATE   motor limits and the mean square force
 *     kinds    n_est int64           estimator kinds (studyapp_estimators.h SE_*)
 *     est_s    n_est x est_s_width   row e: estimator e's state (SE_GUARD guard slots first)
 *     est_p    n_est x est_p_width   row e: estimator e's parameters
 *     sp, ss   SL_N_STRING_PARAMS, SL_N_STRING_STATE
 *     bridge, nut  line each         the string's two delay lines, line > ceil(max delay) + 1
 *     est      n_est                 sl_sample's estimates out (may be NULL when n_est is 0)
 * The host builds them once (studyapp/model/loop.py ClosedLoop: Control.arrays) and a device that runs
 * the loop receives them; studyapp/device/c_loop.py points an sl_loop at the numpy arrays themselves.
 * The fourteen position/acceleration estimators with Table 1's parameters take 18.5 kB at 48 kHz
 * (est_s 14 x 119, est_p 14 x 34; lines of 67; `studyapp bench loop --core c` prints the figure).
 *
 * A firmware provides: this file, studyapp_loop.c, studyapp_estimators.h and its C files, a C99
 * compiler with IEEE double arithmetic and no contraction (-ffp-contract=off), and from <math.h>: fabs,
 * the isfinite and NAN macros here, and what studyapp_estimators.h names (sqrt, fabs, copysign). Each
 * time it takes new arrays it calls sl_check; its sample interrupt calls sl_sample once and writes the
 * returned force to the motor.
 */
#ifndef STUDYAPP_LOOP_H
#define STUDYAPP_LOOP_H

#include <stdint.h>

#include "studyapp_estimators.h"

/* control vector: studyapp/model/control.py C_* */
enum { SL_C_GAIN, SL_C_SCALE, SL_C_FORCE_SCALE, SL_C_BOWING, SL_C_SOURCE, SL_C_USE_AUDIO, SL_C_PEAK,
       SL_C_BREAKAWAY, SL_N_CONTROL };
/* loop state and fault codes: control.py L_*, FAULT_* */
enum { SL_L_FAULT, SL_L_FAULT_SAMPLE, SL_N_LOOP_STATE };
enum { SL_FAULT_SENSOR = 1, SL_FAULT_ESTIMATE = 2, SL_FAULT_STRING = 3, SL_FAULT_FORCE = 4 };
/* the LVT sensor as the source: studyapp/model/sources.py LVT_SENSOR_INDEX */
#define SL_SOURCE_LVT_SENSOR (-2)
/* string parameters and state: bowed_string.py P_*, S_* */
enum { SL_P_DB, SL_P_DN, SL_P_LOSS_B0, SL_P_LOSS_A1, SL_P_SLOPE, SL_P_OFFSET, SL_P_PEAK, SL_P_NUT_GAIN,
       SL_N_STRING_PARAMS };
enum { SL_S_WRITE, SL_S_LOSS_Y, SL_N_STRING_STATE };
/* motor limits: device.py LP_*, LS_* */
enum { SL_LP_IMPULSIVE, SL_LP_SUSTAINED, SL_LP_RMS_ALPHA, SL_N_LIMIT_PARAMS };
enum { SL_LS_MS, SL_N_LIMIT_STATE };

typedef struct {
    double *ctl;
    double *state;
    const double *lp;
    double *ls;
    const int64_t *kinds;
    uint32_t n_est;
    double *est_s;
    uint32_t est_s_width;
    const double *est_p;
    uint32_t est_p_width;
    const double *sp;
    double *ss;
    double *bridge;
    double *nut;
    uint32_t line;
    const double *est_s0; /* the estimators' starting states (n_est x est_s_width), or NULL: sl_reset keeps est_s */
} sl_loop;

/* one sample's outputs (the order of sl_run's rows) */
typedef struct {
    double force;           /* N, clamped, 0 once faulted: what the motor gets */
    double source_velocity; /* m/s */
    double string_velocity; /* the string's velocity at the bow in m/s (control.py O_STRING_VELOCITY) */
    double bridge_velocity; /* the wave at the bridge, string units: the audio chain's input */
    double v_delta;         /* bow minus incoming string velocity, string units */
    double stick;           /* 1 while the bow sticks, else 0 */
    double friction;        /* u / peak, in [-1, 1] */
} sl_out;
#define SL_N_OUT 7

/* Sample k (recorded as the fault's sample): returns the force and fills o and est[0..n_est-1]. */
double sl_sample(sl_loop *L, uint32_t k, double x_m, double a_m, double v_m, sl_out *o, double *est);

/* n samples k0 .. k0 + n - 1: out is SL_N_OUT x n (row r: sl_out's r-th member), est is n x n_est
 * (sample i's estimates at est + i * n_est), both row-major. */
void sl_run(sl_loop *L, uint32_t k0, uint32_t n, const double *x_m, const double *a_m, const double *v_m,
            double *out, double *est);

/* 0 if L can run, else -1: ctl, state, lp, ls, sp, ss, bridge, nut and (with n_est > 0) kinds, est_s,
 * est_p given; line >= 3; both line delays from 1 to line - 2; the write index an integer from 0 to
 * line - 1; every kind known (se_known); est_s_width >= SE_GUARD. The kernels and the string index their
 * arrays from these, unchecked: a firmware calls sl_check whenever it takes new parameters, before it arms.
 * Each estimator's own state and parameter sizes depend on its parameters (FOAW's window, LEASTSQ's taps)
 * and are not checked here: the rows come whole from the host (Estimator.state_size, len(Estimator.p)). */
int sl_check(const sl_loop *L);

/* the string at rest (studyapp/model/loop.py ClosedLoop.reset_string's part of it) */
void sl_reset_string(sl_loop *L);

/* the loop as built: the string at rest, the estimators at est_s0 (when given), the mean square force 0, no
 * fault. A device loop runs it at START, so that a host's shadow, built afresh, starts from the same state. */
void sl_reset(sl_loop *L);

/* the layout constants above (in the order of studyapp_loop.c's table), for a binding to check against
 * its own: writes SL_N_LAYOUT int32s */
#define SL_N_LAYOUT 37
void sl_layout(int32_t *out);

#endif
