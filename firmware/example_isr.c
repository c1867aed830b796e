/* A lab's firmware for a device that runs studyapp's loop (protocol version 2), in plain C99: no vendor SDK.
 *
 * What the lab writes is the board: four functions (below) for its ADCs, its motor's DAC and its serial link.
 * What the lab generates is studyapp_params.h, the host's own loop written out exactly:
 *
 *     studyapp firmware-params --rate 5000 -o studyapp_params.h
 *
 * and the rest is studyapp's: studyapp_device*.c (the protocol and the device's safety core),
 * studyapp_loop.c and the estimators (the loop). Build, for example,
 *
 *     cc -std=c99 -O2 -ffp-contract=off -c example_isr.c studyapp_*.c   (then link with the board and -lm)
 *
 * -ffp-contract=off matters: a fused multiply-add rounds once where the host rounds twice, and the host's
 * shadow of the loop would then differ from the device (docs/device-protocol.md, "Version 2").
 *
 * The board calls studyapp_init() once at start-up and studyapp_sample_isr() from the timer interrupt that
 * owns the sample clock (SP_RATE_HZ). Everything lives in static storage: nothing is allocated.
 */
#include <string.h>

#include "studyapp_device_loop.h"
#include "studyapp_params.h"

/* The board (the lab's): this sample's sensor values in INFO's channel order and formats (counts as
 * integers, f64 in SI); the force to hold over the next sample period (N); the serial link, non-blocking. */
void board_read_sensors(double raw[SP_N_CHANNELS]);
void board_write_force(double newtons);
uint32_t board_uart_read(uint8_t *buf, uint32_t cap);
void board_uart_write(const uint8_t *buf, uint32_t n);

static sd_device dev;
static double ctl[SL_N_CONTROL];
static double state[SL_N_LOOP_STATE];
static double lp[SL_N_LIMIT_PARAMS];
static double ls[SL_N_LIMIT_STATE];
static int64_t kinds[SP_N_EST];
static double est_s[SP_N_EST * SP_EST_S_WIDTH];
static double est_p[SP_N_EST * SP_EST_P_WIDTH];
static double sp[SL_N_STRING_PARAMS];
static double ss[SL_N_STRING_STATE];
static double bridge[SP_LINE];
static double nut[SP_LINE];
static sl_loop loop;
static uint8_t rx[256];
static uint8_t tx[2048];

/* 0 when the device is ready; a negative number says which step refused (the device then never arms). */
int studyapp_init(void)
{
    memcpy(ctl, sp_ctl, sizeof ctl);
    memset(state, 0, sizeof state);
    memcpy(lp, sp_lp, sizeof lp);
    memset(ls, 0, sizeof ls);
    memcpy(kinds, sp_kinds, sizeof kinds);
    memcpy(est_s, sp_est_s, sizeof est_s);
    memcpy(est_p, sp_est_p, sizeof est_p);
    memcpy(sp, sp_sp, sizeof sp);
    memcpy(ss, sp_ss, sizeof ss);
    memset(bridge, 0, sizeof bridge);
    memset(nut, 0, sizeof nut);
    loop.ctl = ctl;
    loop.state = state;
    loop.lp = lp;
    loop.ls = ls;
    loop.kinds = kinds;
    loop.n_est = SP_N_EST;
    loop.est_s = est_s;
    loop.est_s_width = SP_EST_S_WIDTH;
    loop.est_p = est_p;
    loop.est_p_width = SP_EST_P_WIDTH;
    loop.sp = sp;
    loop.ss = ss;
    loop.bridge = bridge;
    loop.nut = nut;
    loop.line = SP_LINE;
    loop.est_s0 = sp_est_s; /* START puts the estimators back here (sl_reset) */
    if (sl_check(&loop) != 0)
        return -1;
    if (sd_init(&dev, sp_info, (uint32_t)sizeof sp_info, sp_rms_alpha) != 0)
        return -2;
    if (sd_attach_loop(&dev, &loop) != 0)
        return -3;
    return 0;
}

/* One sample: the host's bytes in, the sensors read, the loop and the safety core run, the force out, the
 * telemetry queued. Its cost is the loop's (studyapp bench loop; docs/firmware-arm.md for a Cortex-M7). */
void studyapp_sample_isr(void)
{
    double raw[SP_N_CHANNELS];
    uint32_t n;

    /* a UART with a DMA ring or a FIFO: take whatever has arrived since the last sample, in any split */
    while ((n = board_uart_read(rx, (uint32_t)sizeof rx)) > 0)
        sd_rx(&dev, rx, n);
    board_read_sensors(raw);
    sd_sample(&dev, raw);              /* the CONTROLs due, then the loop: estimators, string, force */
    board_write_force(sd_actuate(&dev)); /* the safety core's force: 0 unless armed, ramped, clamped */
    n = sd_tx(&dev, tx, (uint32_t)sizeof tx);
    if (n > 0)
        board_uart_write(tx, n);       /* a TELEMETRY frame every START.packet samples, and the replies */
}
