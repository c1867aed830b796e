/* The loop on a Cortex-M7, fed a recorded sensor stream: reads the loop's arrays and the stream from the
 * host through semihosting, runs sl_sample once per sample as a firmware's sample interrupt would, and
 * writes every sample's outputs back, with the SysTick ticks each sample took.
 *
 * Files, in the emulator's current directory, little-endian (scripts/arm_loop.py writes and reads them):
 *   arm_in.bin     header: uint32 magic "SLA1", n_est, est_s_width, est_p_width, line, n_samples,
 *                  n_events, 0; then float64 ctl, state, lp, ls, int64 kinds, float64 est_s, est_p
 *                  (row-major), sp, ss, bridge, nut (studyapp_loop.h's sl_loop); then n_events control
 *                  events in sample order, each uint32 k, uint32 what, float64 value: before sample k,
 *                  ctl[what] = value, or the string at rest (sl_reset_string) for what = RESET_STRING, as
 *                  the host's CONTROL frames act; then n_samples x (x_m, a_m, v_m) float64
 *   arm_out.bin    n_samples x (sl_out's 7 members, then the n_est estimates) float64
 *   arm_ticks.bin  n_samples uint32: SysTick ticks around sl_sample
 *   arm_state.bin  the arrays after the last sample, in arm_in.bin's order (ctl to nut)
 *   arm_meta.bin   uint32: calibration instructions, their ticks, the ticks of EMPTY_REPS empty calls,
 *                  EMPTY_REPS, NO_SAMPLE_INSNS
 *
 * Counting. SysTick counts the processor clock (CLKSOURCE = 1) down from 2^24 - 1: on a real M7 that is
 * cycles. Under qemu with -icount shift=S every instruction advances virtual time by 2^S ns and SysTick
 * follows the board's 25 MHz clock in virtual time, so ticks measure executed instructions. The harness
 * calibrates the ratio on a loop of exactly 2 x CAL_LOOPS instructions (subs, bne: the difference of two
 * lengths, so the call's own instructions cancel). Each sample is timed by one function (timed) calling
 * sl_sample through a pointer; the same function calling no_sample, whose body is one instruction, times
 * the window's own instructions (the reads, the arguments, the call), which the host subtracts:
 * sl_sample's instructions = (ticks - empty) x calibration instructions / calibration ticks
 * + NO_SAMPLE_INSNS, empty being the mean of EMPTY_REPS timed calls of no_sample.
 * Exit status: 0, or 2 for a bad or missing input file, 3 for a processor fault (startup.c). */
#include <stdint.h>

#include "../studyapp_loop.h"
#include "semihost.h"

#define MAGIC 0x31414c53u /* "SLA1" */
#define CHUNK 256u        /* samples read, run and written per semihosting transfer */
#define CAL_LOOPS 100000u
#define EMPTY_REPS 64u
#define NO_SAMPLE_INSNS 1u /* no_sample's body: bx lr (x_m, its result, is already in d0) */
#define RESET_STRING 0xFFFFFFFFu
#define MAX_EVENTS 4096u

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

extern uint8_t __arena_start, __arena_end;
static uint8_t *arena_next = &__arena_start;

static void *take(uint32_t bytes)
{
    uint8_t *p = arena_next;
    bytes = (bytes + 7u) & ~7u;
    if ((uint32_t)(&__arena_end - p) < bytes) return 0;
    arena_next = p + bytes;
    return p;
}

static uint32_t ticks_since(uint32_t t0) { return (t0 - SYST_CVR) & 0xFFFFFFu; }

static void spin(uint32_t n)
{
    __asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
}

static uint32_t spin_ticks(uint32_t n)
{
    uint32_t t0 = SYST_CVR;
    spin(n);
    return ticks_since(t0);
}

typedef double (*sample_fn)(sl_loop *, uint32_t, double, double, double, sl_out *, double *);

/* a sample that does nothing, for the window's own cost: returns its first double where it came in */
static double __attribute__((noipa)) no_sample(sl_loop *L, uint32_t k, double x_m, double a_m, double v_m,
                                               sl_out *o, double *est)
{
    (void)L, (void)k, (void)a_m, (void)v_m, (void)o, (void)est;
    return x_m;
}

/* SysTick ticks of one call of f on the sensor sample s: the same code whichever f */
static uint32_t __attribute__((noipa)) timed(sample_fn f, sl_loop *L, uint32_t k, const double *s, sl_out *o,
                                             double *est)
{
    uint32_t t0 = SYST_CVR;
    f(L, k, s[0], s[1], s[2], o, est);
    return ticks_since(t0);
}

static void put_number(const char *label, uint64_t v)
{
    char digits[21];
    int d = 20;
    digits[20] = 0;
    do {
        digits[--d] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v);
    sh_write0(label);
    sh_write0(digits + d);
    sh_write0("\n");
}

static int fail(const char *why)
{
    sh_write0("harness: ");
    sh_write0(why);
    sh_write0("\n");
    return 2;
}

typedef struct {
    void *at;
    uint32_t bytes;
} span;

typedef struct {
    uint32_t k, what;
    double value;
} event;

int main(void)
{
    uint32_t head[8], n, i, k, n_spans, cal_ticks, empty = 0, n_events, next = 0, max = 0;
    uint64_t sum = 0;
    int in, out, tick_file;
    sl_loop L;
    sl_out o;
    span spans[11];
    double *sensors, *rows;
    uint32_t *ticks;
    event *events;

    SYST_RVR = 0xFFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, processor clock, no interrupt */

    in = sh_open("arm_in.bin", 0);
    if (in < 0) return fail("cannot open arm_in.bin");
    if (sh_read(in, head, sizeof head) || head[0] != MAGIC) return fail("arm_in.bin: no SLA1 header");
    L.n_est = head[1];
    L.est_s_width = head[2];
    L.est_p_width = head[3];
    L.line = head[4];
    L.est_s0 = 0; /* no START here: sl_reset is not used */
    n = head[5];
    n_events = head[6];
    if (n_events > MAX_EVENTS) return fail("arm_in.bin: more control events than MAX_EVENTS");
    spans[0] = (span){L.ctl = take(SL_N_CONTROL * 8u), SL_N_CONTROL * 8u};
    spans[1] = (span){L.state = take(SL_N_LOOP_STATE * 8u), SL_N_LOOP_STATE * 8u};
    spans[2] = (span){(void *)(L.lp = take(SL_N_LIMIT_PARAMS * 8u)), SL_N_LIMIT_PARAMS * 8u};
    spans[3] = (span){L.ls = take(SL_N_LIMIT_STATE * 8u), SL_N_LIMIT_STATE * 8u};
    spans[4] = (span){(void *)(L.kinds = take(L.n_est * 8u)), L.n_est * 8u};
    spans[5] = (span){L.est_s = take(L.n_est * L.est_s_width * 8u), L.n_est * L.est_s_width * 8u};
    spans[6] = (span){(void *)(L.est_p = take(L.n_est * L.est_p_width * 8u)), L.n_est * L.est_p_width * 8u};
    spans[7] = (span){(void *)(L.sp = take(SL_N_STRING_PARAMS * 8u)), SL_N_STRING_PARAMS * 8u};
    spans[8] = (span){L.ss = take(SL_N_STRING_STATE * 8u), SL_N_STRING_STATE * 8u};
    spans[9] = (span){L.bridge = take(L.line * 8u), L.line * 8u};
    spans[10] = (span){L.nut = take(L.line * 8u), L.line * 8u};
    n_spans = 11;
    sensors = take(CHUNK * 3u * 8u);
    rows = take(CHUNK * (SL_N_OUT + L.n_est) * 8u);
    ticks = take(CHUNK * 4u);
    events = take(MAX_EVENTS * sizeof(event));
    if (!sensors || !rows || !ticks || !events || !L.nut) return fail("arm_in.bin: the arrays do not fit the arena");
    for (i = 0; i < n_spans; i++)
        if (sh_read(in, spans[i].at, spans[i].bytes)) return fail("arm_in.bin: shorter than its header says");
    if (sh_read(in, events, n_events * sizeof(event))) return fail("arm_in.bin: fewer events than its header says");
    for (i = 0; i < n_events; i++)
        if ((events[i].what >= SL_N_CONTROL && events[i].what != RESET_STRING) || (i && events[i].k < events[i - 1].k))
            return fail("arm_in.bin: an event out of order or of no control");
    if (sl_check(&L) != 0) return fail("arm_in.bin: the arrays fail sl_check");

    out = sh_open("arm_out.bin", 1);
    tick_file = sh_open("arm_ticks.bin", 1);
    if (out < 0 || tick_file < 0) return fail("cannot write arm_out.bin or arm_ticks.bin");
    for (i = 0; i < 3u * CHUNK; i++) sensors[i] = 0.0;
    for (i = 0; i < EMPTY_REPS; i++) empty += timed(no_sample, &L, 0, sensors, &o, rows + SL_N_OUT);
    for (k = 0; k < n; k += CHUNK) {
        uint32_t m = n - k < CHUNK ? n - k : CHUNK;
        if (sh_read(in, sensors, m * 3u * 8u)) return fail("arm_in.bin: fewer samples than its header says");
        for (i = 0; i < m; i++) {
            double *row = rows + i * (SL_N_OUT + L.n_est);
            const double *s = sensors + 3u * i;
            for (; next < n_events && events[next].k == k + i; next++) {
                if (events[next].what == RESET_STRING)
                    sl_reset_string(&L);
                else
                    L.ctl[events[next].what] = events[next].value;
            }
            ticks[i] = timed(sl_sample, &L, k + i, s, &o, row + SL_N_OUT);
            row[0] = o.force;
            row[1] = o.source_velocity;
            row[2] = o.string_velocity;
            row[3] = o.bridge_velocity;
            row[4] = o.v_delta;
            row[5] = o.stick;
            row[6] = o.friction;
            sum += ticks[i];
            if (ticks[i] > max) max = ticks[i];
        }
        if (sh_write(out, rows, m * (SL_N_OUT + L.n_est) * 8u) || sh_write(tick_file, ticks, m * 4u))
            return fail("cannot write the outputs");
    }
    sh_close(in);
    sh_close(out);
    sh_close(tick_file);

    out = sh_open("arm_state.bin", 1);
    if (out < 0) return fail("cannot write arm_state.bin");
    for (i = 0; i < n_spans; i++)
        if (sh_write(out, spans[i].at, spans[i].bytes)) return fail("cannot write arm_state.bin");
    sh_close(out);

    cal_ticks = spin_ticks(2u * CAL_LOOPS) - spin_ticks(CAL_LOOPS);
    head[0] = 2u * CAL_LOOPS;
    head[1] = cal_ticks;
    head[2] = empty;
    head[3] = EMPTY_REPS;
    head[4] = NO_SAMPLE_INSNS;
    out = sh_open("arm_meta.bin", 1);
    if (out < 0 || sh_write(out, head, 5u * 4u)) return fail("cannot write arm_meta.bin");
    sh_close(out);

    put_number("samples: ", n);
    if (n && cal_ticks && sum * EMPTY_REPS > (uint64_t)n * empty) {
        /* the mean in hundredths: (sum / n - empty / EMPTY_REPS) x 2 CAL_LOOPS / cal_ticks + NO_SAMPLE_INSNS */
        uint64_t net = sum * EMPTY_REPS - (uint64_t)n * empty;
        put_number("instructions per sample, mean x 100: ",
                   net * 200u * CAL_LOOPS / cal_ticks / EMPTY_REPS / n + 100u * NO_SAMPLE_INSNS);
        put_number("instructions per sample, max: ",
                   ((uint64_t)max * EMPTY_REPS - empty) * 2u * CAL_LOOPS / cal_ticks / EMPTY_REPS + NO_SAMPLE_INSNS);
    }
    return 0;
}
