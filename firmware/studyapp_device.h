/* studyapp device protocol v1: the device side (framing, CRC, messages, watchdog, clamps, arm, ramp,
 * tagged forces) in portable C99. No allocation, nothing from the C library but <stdint.h> and <string.h>.
 * docs/device-protocol.md is the protocol; studyapp/device/firmware.py and device_side.py are the same
 * core in Python, and the tests hold the two equal byte for byte.
 *
 * A firmware calls, from its sample interrupt or loop:
 *     sd_rx(d, bytes, n)       bytes received from the host since the last sample (any split)
 *     sd_sample(d, raw)        the current sample's sensor values, one per INFO channel (counts as integers)
 *     f = sd_actuate(d)        the force (N) to command over [now, now + 1]; advances the sample counter
 *     n = sd_tx(d, out, cap)   the bytes to send to the host (frames, whole), oldest first
 * and, once, sd_init(d, info_payload, len, rms_alpha) with its INFO message (as messages.Info.pack makes
 * it; the sequence byte is replaced when sent) and alpha = 1 - exp(-1 / (rate * sustained_window)).
 *
 * Version 2 (docs/device-protocol.md, "Version 2"): a device whose INFO says loop = 1 runs the loop itself.
 * It calls sd_attach_loop (studyapp_device_loop.h) once after sd_init; then sd_sample runs the loop on the
 * sample (CONTROL settings applied at their tags) and sd_actuate applies this core's unchanged safety to the
 * loop's force and streams TELEMETRY. This file reaches the loop only through the hooks below, so a
 * version 1 firmware links neither the loop nor the C maths library.
 */
#ifndef STUDYAPP_DEVICE_H
#define STUDYAPP_DEVICE_H

#include <stdint.h>

#define SD_RING 1024u          /* tagged forces held ahead, samples */
#define SD_LINK_RUN 16u        /* corrupt frames in a row that disarm */
#define SD_MAX_PAYLOAD 1024u
#define SD_MAX_ENCODED (SD_MAX_PAYLOAD + 2u + (SD_MAX_PAYLOAD + 2u + 253u) / 254u)
#define SD_MAX_CHANNELS 8u
#define SD_MAX_ROWS 255u
#define SD_TX_SIZE 8192u
#define SD_QUEUE 16u           /* version 2: CONTROL settings held before they take effect */
#define SD_MAX_ESTIMATORS 32u
#define SD_TELEMETRY_TAIL 26u  /* a TELEMETRY row after its channels: loop_force, applied, bridge (f64), control (u16) */

enum { SD_WATCHDOG = 1, SD_CLAMP = 2, SD_SUSTAINED = 3, SD_LINK_CORRUPT = 4, SD_INTERNAL = 5, SD_LATE = 6 };

typedef struct sd_device sd_device;

/* CONTROL's fields (version 2) */
typedef struct {
    uint16_t id;
    uint32_t sample;
    int8_t source;
    uint8_t bowing, reset;
    double gain, force_scale;
} sd_control;

/* What a loop on the device adds to this core (set by sd_attach_loop, studyapp_device_loop.c). */
typedef struct {
    int (*valid)(const sd_device *d, int type, const uint8_t *body, uint32_t n); /* CONTROL, ALIVE: 1 if sound */
    void (*frame)(sd_device *d, int type, const uint8_t *body);                  /* a sound CONTROL or ALIVE */
    void (*streaming)(sd_device *d, int on);                                     /* after START (1), STOP (0) */
    void (*sample)(sd_device *d, uint8_t *row);      /* row: this sample's channels, written; runs the loop */
    void (*actuated)(sd_device *d, double applied);  /* the force applied over [now, now + 1] */
} sd_loop_hooks;

struct sd_device {
    /* from INFO */
    uint8_t info[SD_MAX_PAYLOAD];
    uint32_t info_len;
    uint32_t rate_hz;
    uint32_t max_packet;
    double impulsive, sustained, rms_alpha;
    uint32_t watchdog, down, ramp_ms_min; /* watchdog and ramp-down in samples */
    uint32_t channels;
    uint8_t format[SD_MAX_CHANNELS], kind[SD_MAX_CHANNELS];
    double gain[SD_MAX_CHANNELS], offset[SD_MAX_CHANNELS];
    uint32_t row_size; /* a SENSORS row, or in a device loop a TELEMETRY row */
    /* safety core */
    uint32_t now;
    int armed, streaming, fault;
    uint32_t arm_sample, ramp, start_sample, latency, packet;
    int got;
    double hold;
    uint32_t tags[SD_RING];
    double values[SD_RING];
    uint8_t valid[SD_RING];
    uint32_t deadline, last_feed, down_left;
    double down_from, last_out, ms;
    uint32_t late, corrupt, missing, corrupt_run, lost;
    int clamped, ramping, sustained_on;
    uint32_t report_at[7];
    uint8_t reported[7];
    /* link */
    uint8_t rx[SD_MAX_ENCODED + 1];
    uint32_t rx_len;
    int rx_overlong;
    int have_seq;
    uint8_t last_seq, tx_seq;
    uint8_t rows[8 + SD_MAX_PAYLOAD]; /* the SENSORS frame being filled */
    uint32_t row_count;
    uint8_t tx[SD_TX_SIZE];
    uint32_t tx_len, tx_dropped;
    /* version 2: INFO's loop section and the loop's state (studyapp_device_loop.c) */
    int loop_mode;             /* INFO's loop = 1: the device runs the loop */
    uint32_t n_est;
    uint8_t kinds[SD_MAX_ESTIMATORS];
    const sd_loop_hooks *hooks; /* NULL until sd_attach_loop */
    void *loop;                 /* the sl_loop attached */
    double loop_force;          /* the loop's force for the current sample */
    uint32_t seen;              /* ALIVE's seen (START sets it to START's sample) */
    sd_control queue[SD_QUEUE], setting;
    uint32_t queued;
    int row_open, loop_fault_sent;
};

/* 0 on success; -1 if the INFO payload is not one this core can run */
int sd_init(sd_device *d, const uint8_t *info, uint32_t len, double rms_alpha);
void sd_rx(sd_device *d, const uint8_t *data, uint32_t n);
void sd_sample(sd_device *d, const double *raw);
int sd_needs_force(const sd_device *d);
double sd_actuate(sd_device *d);
uint32_t sd_tx(sd_device *d, uint8_t *out, uint32_t cap);
uint16_t sd_crc16(const uint8_t *data, uint32_t n, uint16_t crc);
uint32_t sd_sizeof(void);
/* now, armed, streaming, fault, late, lost, corrupt, missing */
void sd_counters(const sd_device *d, uint32_t out[8]);
/* the sample counter from here (after sd_init, before START): a firmware's counter may start anywhere and
   wraps after 2^32 samples; every comparison of two counters is by their signed 32-bit difference */
void sd_set_counter(sd_device *d, uint32_t sample);
/* version 2, lock-step: 1 while a streaming device loop has run up to ALIVE's seen + START's latency */
int sd_needs_alive(const sd_device *d);
/* between the core's files (studyapp_device.c, _link.c, _loop.c), not for a firmware: */
void sd_send_payload(sd_device *d, uint8_t *payload, uint32_t n); /* frame and queue (sets the seq byte) */
void sd_payload(sd_device *d, uint8_t *p, uint32_t n);            /* a sound frame's payload: apply it */
void sd_corrupt_frame(sd_device *d);                               /* count a corrupt frame */

#endif
