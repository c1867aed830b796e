/* studyapp's haptic loop, one sample: see studyapp_loop.h. Each function mirrors its namesake in
 * studyapp/model/control.py, bowed_string.py, bow_table.py or device.py operation for operation (the
 * same operands in the same order), which is what makes the two equal bit for bit. */
#include "studyapp_loop.h"

#include <math.h>
#include <string.h>

#define RHO_MAX 0.98
#define RHO_MIN 0.01

static int bad(double x) { return !isfinite(x); }

static void latch(double *state, double code, uint32_t k) {
    if (state[SL_L_FAULT] == 0.0) {
        state[SL_L_FAULT] = code;
        state[SL_L_FAULT_SAMPLE] = (double)k;
    }
}

/* bow_table.friction: u = rho(v) v with |u| <= peak */
static double friction(double v, double slope, double offset, double peak) {
    double t = fabs(slope * (v + offset)) + 0.75;
    double t2 = t * t;
    double r = 1.0 / (t2 * t2);
    double u;
    if (r > RHO_MAX)
        r = RHO_MAX;
    else if (r < RHO_MIN)
        r = RHO_MIN;
    u = r * v;
    if (u > peak) return peak;
    if (u < -peak) return -peak;
    return u;
}

/* bowed_string.read_line: the value written `delay` samples ago, linearly interpolated */
static double read_line(const double *buf, int64_t n, int64_t write, double delay) {
    int64_t i = (int64_t)delay;
    double frac = delay - (double)i;
    int64_t ia = write - i, ib;
    double a;
    if (ia < 0) ia += n;
    ib = ia - 1;
    if (ib < 0) ib += n;
    a = buf[ia];
    return a + frac * (buf[ib] - a);
}

/* bowed_string.step */
static void string_step(sl_loop *L, double v_bow, int bowing, double *u_out, double *v_string,
                        double *v_bridge, double *v_delta) {
    const double *p = L->sp;
    double *s = L->ss;
    int64_t n = (int64_t)L->line;
    int64_t write = (int64_t)s[SL_S_WRITE];
    double vb = read_line(L->bridge, n, write, p[SL_P_DB]);
    double y = p[SL_P_LOSS_B0] * vb + p[SL_P_LOSS_A1] * s[SL_S_LOSS_Y];
    double bridge_refl, nut_refl, v_h, vd, u = 0.0;
    s[SL_S_LOSS_Y] = y;
    bridge_refl = -y;
    nut_refl = -p[SL_P_NUT_GAIN] * read_line(L->nut, n, write, p[SL_P_DN]);
    v_h = bridge_refl + nut_refl;
    vd = v_bow - v_h;
    if (bowing) u = friction(vd, p[SL_P_SLOPE], p[SL_P_OFFSET], p[SL_P_PEAK]);
    L->nut[write] = bridge_refl + u;
    L->bridge[write] = nut_refl + u;
    write += 1;
    s[SL_S_WRITE] = write == n ? 0.0 : (double)write;
    *u_out = u;
    *v_string = v_h + u;
    *v_bridge = vb;
    *v_delta = vd;
}

/* device.clamp_force: the motor limits, and the mean square force behind the sustained one */
static double clamp_force(const double *p, double *s, double f) {
    double limit = p[SL_LP_IMPULSIVE];
    if (s[SL_LS_MS] > p[SL_LP_SUSTAINED] * p[SL_LP_SUSTAINED]) limit = p[SL_LP_SUSTAINED];
    if (f > limit)
        f = limit;
    else if (f < -limit)
        f = -limit;
    s[SL_LS_MS] += p[SL_LP_RMS_ALPHA] * (f * f - s[SL_LS_MS]);
    return f;
}

static double step_estimator(sl_loop *L, uint32_t e, double x_m, double a_m, double v_m) {
    return se_step_guarded((int)L->kinds[e], L->est_s + (uint64_t)e * L->est_s_width,
                           L->est_p + (uint64_t)e * L->est_p_width, x_m, a_m, v_m);
}

static int delay_ok(double d, uint32_t line) { return d >= 1.0 && d <= (double)line - 2.0; }

int sl_check(const sl_loop *L) {
    uint32_t e;
    double w;
    if (!L->ctl || !L->state || !L->lp || !L->ls || !L->sp || !L->ss || !L->bridge || !L->nut) return -1;
    if (L->n_est > 0 && (!L->kinds || !L->est_s || !L->est_p || L->est_s_width < SE_GUARD)) return -1;
    if (L->line < 3 || !delay_ok(L->sp[SL_P_DB], L->line) || !delay_ok(L->sp[SL_P_DN], L->line)) return -1;
    w = L->ss[SL_S_WRITE];
    if (!(w >= 0.0 && w < (double)L->line) || w != (double)(uint32_t)w) return -1;
    for (e = 0; e < L->n_est; e++)
        if (L->kinds[e] < 0 || L->kinds[e] >= SE_KINDS || !se_known((int)L->kinds[e])) return -1;
    return 0;
}

void sl_reset_string(sl_loop *L) {
    memset(L->ss, 0, SL_N_STRING_STATE * sizeof(double));
    memset(L->bridge, 0, L->line * sizeof(double));
    memset(L->nut, 0, L->line * sizeof(double));
}

void sl_reset(sl_loop *L) {
    sl_reset_string(L);
    if (L->est_s0 != NULL && L->n_est > 0u)
        memcpy(L->est_s, L->est_s0, (size_t)L->n_est * L->est_s_width * sizeof(double));
    memset(L->ls, 0, SL_N_LIMIT_STATE * sizeof(double));
    memset(L->state, 0, SL_N_LOOP_STATE * sizeof(double));
}

double sl_sample(sl_loop *L, uint32_t k, double x_m, double a_m, double v_m, sl_out *o, double *est) {
    double *ctl = L->ctl, *state = L->state;
    double source = ctl[SL_C_SOURCE];
    double v_src, v_bow, u, v_string, v_bridge, v_delta, f;
    int src = -1, bowing;
    uint32_t e;

    /* control.check_sensors */
    if (bad(x_m) || bad(v_m) || bad(a_m)) latch(state, SL_FAULT_SENSOR, k);

    /* control.source_velocity (TRUE, or no such estimator: NaN, as a device without truth gives) */
    if (source >= 0.0 && source < (double)L->n_est) {
        src = (int)source;
        v_src = step_estimator(L, (uint32_t)src, x_m, a_m, v_m);
        est[src] = v_src;
    } else if (source == SL_SOURCE_LVT_SENSOR) {
        v_src = v_m;
    } else {
        v_src = NAN;
    }

    /* control.bow_and_force */
    if (bad(v_src)) latch(state, SL_FAULT_ESTIMATE, k);
    bowing = ctl[SL_C_BOWING] != 0.0 && state[SL_L_FAULT] == 0.0;
    v_bow = bowing ? ctl[SL_C_SCALE] * v_src : 0.0;
    string_step(L, v_bow, bowing, &u, &v_string, &v_bridge, &v_delta);
    if (bad(u) || bad(v_string) || bad(v_bridge)) {
        latch(state, SL_FAULT_STRING, k);
        sl_reset_string(L); /* a poisoned string is set back to rest so every output stays finite */
        u = 0.0;
        v_string = 0.0;
        v_bridge = 0.0;
        v_delta = 0.0;
    }
    if (state[SL_L_FAULT] != 0.0) u = 0.0;
    o->source_velocity = v_src;
    o->string_velocity = v_string / ctl[SL_C_SCALE];
    o->bridge_velocity = v_bridge;
    o->v_delta = v_delta;
    o->friction = u / ctl[SL_C_PEAK];
    o->stick = bowing && fabs(v_delta) <= ctl[SL_C_BREAKAWAY] ? 1.0 : 0.0;
    f = -ctl[SL_C_GAIN] * u * ctl[SL_C_FORCE_SCALE];

    /* control.command */
    f = clamp_force(L->lp, L->ls, f);
    if (bad(f)) latch(state, SL_FAULT_FORCE, k);
    if (state[SL_L_FAULT] != 0.0) f = 0.0;
    o->force = f;

    /* control.observe_others, a sample at a time */
    for (e = 0; e < L->n_est; e++)
        if ((int)e != src) est[e] = step_estimator(L, e, x_m, a_m, v_m);
    return f;
}

void sl_run(sl_loop *L, uint32_t k0, uint32_t n, const double *x_m, const double *a_m, const double *v_m,
            double *out, double *est) {
    uint32_t i;
    sl_out o;
    for (i = 0; i < n; i++) {
        sl_sample(L, k0 + i, x_m[i], a_m[i], v_m[i], &o, est + (uint64_t)i * L->n_est);
        out[i] = o.force;
        out[(uint64_t)n + i] = o.source_velocity;
        out[2 * (uint64_t)n + i] = o.string_velocity;
        out[3 * (uint64_t)n + i] = o.bridge_velocity;
        out[4 * (uint64_t)n + i] = o.v_delta;
        out[5 * (uint64_t)n + i] = o.stick;
        out[6 * (uint64_t)n + i] = o.friction;
    }
}

static const int32_t LAYOUT[SL_N_LAYOUT] = {
    SL_C_GAIN, SL_C_SCALE, SL_C_FORCE_SCALE, SL_C_BOWING, SL_C_SOURCE, SL_C_USE_AUDIO, SL_C_PEAK, SL_C_BREAKAWAY,
    SL_N_CONTROL,
    SL_L_FAULT, SL_L_FAULT_SAMPLE, SL_N_LOOP_STATE,
    SL_FAULT_SENSOR, SL_FAULT_ESTIMATE, SL_FAULT_STRING, SL_FAULT_FORCE,
    SL_SOURCE_LVT_SENSOR,
    SL_P_DB, SL_P_DN, SL_P_LOSS_B0, SL_P_LOSS_A1, SL_P_SLOPE, SL_P_OFFSET, SL_P_PEAK, SL_P_NUT_GAIN,
    SL_N_STRING_PARAMS,
    SL_S_WRITE, SL_S_LOSS_Y, SL_N_STRING_STATE,
    SL_LP_IMPULSIVE, SL_LP_SUSTAINED, SL_LP_RMS_ALPHA, SL_N_LIMIT_PARAMS,
    SL_LS_MS, SL_N_LIMIT_STATE,
    SL_N_OUT, SE_GUARD,
};

void sl_layout(int32_t *out) { memcpy(out, LAYOUT, sizeof LAYOUT); }
