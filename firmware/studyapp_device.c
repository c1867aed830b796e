/* studyapp device protocol v1, the device side: see studyapp_device.h and docs/device-protocol.md.
 * Each function mirrors its namesake in studyapp/device/device_side.py or firmware.py; the framing (CRC,
 * COBS, the receiver) is studyapp_device_link.c. */
#include "studyapp_device.h"
#include "studyapp_bytes.h"

#include <string.h>

enum { HELLO = 0x81, FORCE, ARM, DISARM, START, STOP, PING, KEEPALIVE, CONTROL, ALIVE };
enum { INFO = 0x01, SENSORS, PONG, FAULT, STATE };

/* a count from a double, saturating (a cast of an out-of-range double is undefined in C); NaN gives 0 */
static int32_t count_of(double v, double lo, double hi) {
    if (!(v == v)) return 0;
    if (v < lo) v = lo;
    if (v > hi) v = hi;
    return (int32_t)v;
}

uint32_t sd_sizeof(void) { return (uint32_t)sizeof(sd_device); }

static void fault_frame(sd_device *d, uint8_t code, uint32_t sample, uint32_t detail) {
    uint8_t p[11];
    p[0] = FAULT;
    p[2] = code;
    wr32(p + 3, sample);
    wr32(p + 7, detail);
    sd_send_payload(d, p, sizeof p);
}

static void state_frame(sd_device *d) {
    uint8_t p[17];
    p[0] = STATE;
    p[2] = (uint8_t)d->armed;
    p[3] = (uint8_t)d->streaming;
    p[4] = (uint8_t)d->fault;
    wr32(p + 5, d->late);
    wr32(p + 9, d->lost);
    wr32(p + 13, d->corrupt);
    sd_send_payload(d, p, sizeof p);
}

/* a FAULT that is not latched, at most once per second per code */
static void report(sd_device *d, int code, uint32_t detail) {
    if (!d->reported[code] || sd_ahead(d->now, d->report_at[code]) >= (int64_t)d->rate_hz) {
        d->reported[code] = 1;
        d->report_at[code] = d->now;
        fault_frame(d, (uint8_t)code, d->now, detail);
    }
}

static uint32_t milli(double f) {
    double a = f < 0.0 ? -f : f;
    if (a > 4294967.0) a = 4294967.0;
    return (uint32_t)(a * 1000.0);
}

/* ---- the safety core (device_side.py) ---- */

static void feed(sd_device *d, uint32_t until) {
    if (d->down_left) return;
    if (sd_ahead(until, d->deadline) > 0 || !d->armed) d->deadline = until;
    d->last_feed = d->now;
}

void sd_corrupt_frame(sd_device *d) {
    d->corrupt++;
    d->corrupt_run++;
    if (d->corrupt_run >= SD_LINK_RUN && d->armed) {
        d->armed = 0;
        d->down_left = 0;
        d->fault = SD_LINK_CORRUPT;
        fault_frame(d, SD_LINK_CORRUPT, d->now, d->corrupt_run);
    }
}

static void clear_tags(sd_device *d) { memset(d->valid, 0, sizeof d->valid); }

static void arm(sd_device *d, uint32_t ramp_ms) {
    uint32_t ms = ramp_ms > d->ramp_ms_min ? ramp_ms : d->ramp_ms_min;
    d->armed = 1;
    d->fault = 0;
    d->down_left = 0;
    d->arm_sample = d->now;
    d->ramp = (uint32_t)((uint64_t)ms * d->rate_hz / 1000u);
    d->got = 0;
    d->hold = 0.0;
    /* a device loop's watchdog is the keep-alive's: START's latency is no lead there */
    d->deadline = d->now + d->watchdog + (d->streaming && !d->loop_mode ? d->latency : 0u);
    d->last_feed = d->now;
}

static void force(sd_device *d, uint32_t sample, uint32_t count, const uint8_t *values) {
    uint32_t i, t, last = 0, slot;
    int any = 0;
    int64_t dt;
    if (!d->streaming) return;
    for (i = 0; i < count; i++) {
        t = sample + i;
        dt = sd_ahead(t, d->now);
        if (dt < 0) {
            d->late++;
            report(d, SD_LATE, d->late);
        } else if (dt >= (int64_t)SD_RING) {
            d->corrupt++;
        } else {
            slot = t % SD_RING;
            d->tags[slot] = t;
            d->values[slot] = rdf64(values + 8u * i);
            d->valid[slot] = 1;
            last = t;
            any = 1;
        }
    }
    if (any) feed(d, last + d->watchdog);
}

int sd_needs_force(const sd_device *d) {
    uint32_t slot;
    if (d->loop_mode || !d->streaming || sd_ahead(d->now, d->start_sample + d->latency) < 0) return 0;
    slot = d->now % SD_RING;
    return !(d->valid[slot] && d->tags[slot] == d->now);
}

static double clamp(sd_device *d, double f) {
    double limit = d->impulsive;
    int sustained = d->ms > d->sustained * d->sustained;
    if (sustained) {
        limit = d->sustained;
        if (!d->sustained_on) report(d, SD_SUSTAINED, milli(f));
    }
    d->sustained_on = sustained;
    if (f > limit || f < -limit) {
        report(d, SD_CLAMP, milli(f));
        f = f > limit ? limit : -limit;
        d->clamped = 1;
    }
    d->ms += d->rms_alpha * (f * f - d->ms);
    return f;
}

double sd_actuate(sd_device *d) {
    uint32_t j = d->now, slot;
    double f = 0.0;
    int64_t k;
    if (d->armed && d->down_left == 0 && sd_ahead(j, d->deadline) >= 0) {
        d->fault = SD_WATCHDOG;
        d->down_left = d->down;
        d->down_from = d->last_out;
    }
    if (d->down_left > 0) {
        d->down_left--;
        f = d->down_from * ((double)d->down_left / (double)d->down);
        if (d->down_left == 0) {
            d->armed = 0;
            fault_frame(d, SD_WATCHDOG, j, d->last_feed);
        }
    } else if (d->armed && d->streaming && d->loop_mode) {
        f = d->loop_force;
        k = sd_ahead(j, d->arm_sample);
        if (k < (int64_t)d->ramp) {
            f = f * ((double)k / (double)d->ramp);
            d->ramping = 1;
        }
    } else if (d->armed && d->streaming) {
        slot = j % SD_RING;
        if (d->valid[slot] && d->tags[slot] == j) {
            d->valid[slot] = 0;
            f = d->values[slot];
            d->hold = f;
            d->got = 1;
        } else if (d->got) {
            f = d->hold;
            d->missing++;
        }
        k = sd_ahead(j, d->arm_sample);
        if (k < (int64_t)d->ramp) {
            f = f * ((double)k / (double)d->ramp);
            d->ramping = 1;
        }
    }
    f = clamp(d, f);
    d->last_out = f;
    if (d->streaming && d->hooks) d->hooks->actuated(d, f);
    d->now = j + 1u;
    return f;
}

/* ---- the firmware loop (firmware.py) ---- */

static int body_ok(sd_device *d, const uint8_t *b, uint32_t n, int type) {
    uint32_t i, count;
    switch (type) {
    case HELLO: case ARM: return n == 2;
    case DISARM: return n == 1 && b[0] <= 2;
    case START: /* a device loop's latency is the lock-step lead: at least one packet */
        return n == 3 && b[0] >= 1 && (uint32_t)rd16(b + 1) + (d->loop_mode ? 0u : 1u) >= b[0] &&
               b[0] <= d->max_packet;
    case STOP: case KEEPALIVE: return n == 0;
    case PING: return n == 4;
    case FORCE:
        if (n < 5 || d->loop_mode) return 0;
        count = b[4];
        if (count < 1 || count > 64 || n != 5u + 8u * count) return 0;
        for (i = 0; i < count; i++)
            if (!finite64(b + 5u + 8u * i)) return 0;
        return 1;
    case CONTROL: case ALIVE: return d->hooks && d->hooks->valid(d, type, b, n);
    default: return 0;
    }
}

void sd_payload(sd_device *d, uint8_t *p, uint32_t n) {
    const uint8_t *b = p + 2;
    uint32_t bn = n - 2u;
    int type = p[0];
    uint8_t out[10];
    if (!body_ok(d, b, bn, type)) {
        sd_corrupt_frame(d);
        return;
    }
    /* a HELLO starts a new conversation (a host that reopened the link starts its seq at 0): no gap counted */
    if (d->have_seq && type != HELLO) d->lost += (uint8_t)(p[1] - d->last_seq - 1u);
    d->last_seq = p[1];
    d->have_seq = 1;
    d->corrupt_run = 0;
    if (!d->streaming) feed(d, d->now + d->watchdog);
    switch (type) {
    case FORCE: force(d, rd32(b), b[4], b + 5); return;
    case HELLO:
        sd_send_payload(d, d->info, d->info_len);
        return;
    case PING:
        out[0] = PONG;
        memcpy(out + 2, b, 4);
        wr32(out + 6, d->now);
        sd_send_payload(d, out, 10);
        return;
    case KEEPALIVE: return;
    case CONTROL: case ALIVE: /* only a device loop's hooks pass them as sound */
        d->hooks->frame(d, type, b);
        feed(d, d->now + d->watchdog);
        return;
    case ARM: arm(d, rd16(b)); break;
    case DISARM: d->armed = 0; d->down_left = 0; break;
    case START:
        d->packet = b[0];
        d->row_count = 0;
        d->streaming = 1;
        d->start_sample = d->now;
        d->latency = rd16(b + 1);
        d->got = 0;
        d->hold = 0.0;
        clear_tags(d);
        feed(d, d->now + (d->loop_mode ? 0u : d->latency) + d->watchdog);
        if (d->hooks) d->hooks->streaming(d, 1);
        break;
    case STOP:
        d->row_count = 0;
        d->streaming = 0;
        d->got = 0;
        d->hold = 0.0;
        clear_tags(d);
        if (d->hooks) d->hooks->streaming(d, 0);
        break;
    }
    state_frame(d);
}

void sd_sample(sd_device *d, const double *raw) {
    uint8_t *r, *row;
    uint32_t c, flags;
    if (!d->streaming) return;
    r = row = d->rows + 8u + d->row_count * d->row_size; /* after the header: the frame is built in place */
    for (c = 0; c < d->channels; c++) {
        if (d->format[c] == 0) {
            wrf64(r, raw[c]);
            r += 8;
        } else if (d->format[c] == 1) {
            wr32(r, (uint32_t)count_of(raw[c], -2147483648.0, 2147483647.0));
            r += 4;
        } else {
            uint16_t v = (uint16_t)(int16_t)count_of(raw[c], -32768.0, 32767.0);
            r[0] = (uint8_t)v;
            r[1] = (uint8_t)(v >> 8);
            r += 2;
        }
    }
    if (d->loop_mode) {
        if (d->hooks) d->hooks->sample(d, row);
        return;
    }
    if (++d->row_count < d->packet) return;
    flags = (d->armed ? 1u : 0u) | (d->fault ? 2u : 0u) | (d->clamped ? 4u : 0u) | (d->ramping ? 8u : 0u);
    d->clamped = 0;
    d->ramping = 0;
    d->rows[0] = SENSORS;
    wr32(d->rows + 2, d->now - d->packet + 1u);
    d->rows[6] = (uint8_t)d->packet;
    d->rows[7] = (uint8_t)flags;
    sd_send_payload(d, d->rows, 8u + d->packet * d->row_size);
    d->row_count = 0;
}

int sd_needs_alive(const sd_device *d) {
    return d->loop_mode && d->streaming && sd_ahead(d->now, d->seen + d->latency) >= 0;
}

void sd_counters(const sd_device *d, uint32_t out[8]) {
    out[0] = d->now;
    out[1] = (uint32_t)d->armed;
    out[2] = (uint32_t)d->streaming;
    out[3] = (uint32_t)d->fault;
    out[4] = d->late;
    out[5] = d->lost;
    out[6] = d->corrupt;
    out[7] = d->missing;
}

void sd_set_counter(sd_device *d, uint32_t sample) {
    d->now = sample;
    d->seen = sample;
    d->arm_sample = sample;
    d->start_sample = sample;
    d->deadline = sample;
    d->last_feed = sample;
}

int sd_init(sd_device *d, const uint8_t *info, uint32_t len, double rms_alpha) {
    const uint8_t *b = info + 2;
    uint32_t at, c, wd, size, version, end, keepalive = 0;
    memset(d, 0, sizeof *d);
    if (len < 2u + 10u || len > SD_MAX_PAYLOAD || info[0] != INFO) return -1;
    memcpy(d->info, info, len);
    d->info_len = len;
    version = rd16(b);
    d->rate_hz = rd32(b + 4);
    d->max_packet = b[8];
    at = 9u;
    at += 1u + b[at];                               /* name */
    if (2u + at + 1u > len) return -1;
    at += 1u + b[at];                               /* serial */
    if (2u + at + 37u > len) return -1;
    d->impulsive = rdf64(b + at + 8);
    d->sustained = rdf64(b + at + 16);
    wd = rd16(b + at + 32);
    d->ramp_ms_min = rd16(b + at + 34);
    d->channels = b[at + 36];
    at += 37u;
    end = 2u + at + 18u * d->channels;
    if (d->channels < 1u || d->channels > SD_MAX_CHANNELS || end > len || (version < 2u && end != len)) return -1;
    size = 0;
    for (c = 0; c < d->channels; c++) {
        d->kind[c] = b[at + 18u * c];
        d->format[c] = b[at + 18u * c + 1u];
        d->gain[c] = rdf64(b + at + 18u * c + 2u);
        d->offset[c] = rdf64(b + at + 18u * c + 10u);
        if (d->format[c] > 2u || d->kind[c] > 2u) return -1;
        size += d->format[c] == 0 ? 8u : (d->format[c] == 1 ? 4u : 2u);
    }
    if (version >= 2u) { /* the loop section: loop u8, keepalive_ms u16, image u32, n u8, kinds */
        if (end + 8u > len || info[end] > 1u || info[end + 7u] > SD_MAX_ESTIMATORS ||
            end + 8u + info[end + 7u] != len)
            return -1;
        d->loop_mode = info[end];
        keepalive = rd16(info + end + 1u);
        d->n_est = info[end + 7u];
        memcpy(d->kinds, info + end + 8u, d->n_est);
        if (d->loop_mode) {
            if (keepalive < 1u) return -1;
            wd = keepalive;
            size += SD_TELEMETRY_TAIL;
            for (c = 0; c < d->channels && d->kind[c] != 0u; c++) {}
            if (c == d->channels) return -1; /* the loop's estimators need a position channel */
        }
    }
    d->row_size = size;
    if (d->rate_hz == 0 || d->max_packet < 1u || d->max_packet * size + 8u > SD_MAX_PAYLOAD) return -1;
    d->rms_alpha = rms_alpha;
    d->watchdog = (uint32_t)((uint64_t)wd * d->rate_hz / 1000u);
    if (d->watchdog < 1u) d->watchdog = 1u;
    d->down = (d->rate_hz + 999u) / 1000u;
    if (d->down < 1u) d->down = 1u;
    d->packet = 1;
    return 0;
}
