/* studyapp device protocol v2, the loop on the device: see studyapp_device_loop.h and docs/device-protocol.md.
 * studyapp_device.c calls these through sd_loop_hooks; everything else (framing, the safety core) is its. */
#include "studyapp_device_loop.h"

#include <string.h>

#include "studyapp_bytes.h"

enum { CONTROL = 0x89, ALIVE = 0x8A, TELEMETRY = 0x06, FAULT = 0x04 };
enum { SOURCE_SENSOR = -2, CONTROL_BODY = 25, ALIVE_BODY = 4 };

/* finite, without <math.h>: NaN fails every comparison, and an infinity minus itself is NaN */
static int finite(double f) { return f - f == 0.0; }

static sd_control parse_control(const uint8_t *b) {
    sd_control c;
    c.id = rd16(b);
    c.sample = rd32(b + 2);
    c.source = (int8_t)b[6];
    c.bowing = b[7];
    c.reset = b[8];
    c.gain = rdf64(b + 9);
    c.force_scale = rdf64(b + 17);
    return c;
}

static int valid(const sd_device *d, int type, const uint8_t *b, uint32_t n) {
    sd_control c;
    if (type == ALIVE) return n == ALIVE_BODY;
    if (type != CONTROL || n != CONTROL_BODY) return 0;
    c = parse_control(b);
    if (c.id == 0u || c.bowing > 1u || c.reset > 1u) return 0;
    if (c.source >= 0 ? (uint32_t)c.source >= d->n_est : c.source != SOURCE_SENSOR) return 0;
    if (!finite(c.gain) || !(c.gain >= 0.0)) return 0;
    return finite(c.force_scale) && c.force_scale >= 0.0 && c.force_scale <= 1.0;
}

static void apply(sd_device *d, const sd_control *c) {
    sl_loop *L = (sl_loop *)d->loop;
    L->ctl[SL_C_SOURCE] = (double)c->source;
    L->ctl[SL_C_BOWING] = (double)c->bowing;
    L->ctl[SL_C_GAIN] = c->gain;
    L->ctl[SL_C_FORCE_SCALE] = c->force_scale;
    if (c->reset) sl_reset_string(L);
    d->setting = *c;
}

/* the setting before the first CONTROL since START: the bow lifted, no force, the velocity sensor */
static void rest_setting(sd_device *d) {
    sd_control c;
    memset(&c, 0, sizeof c);
    c.source = SOURCE_SENSOR;
    c.force_scale = 1.0;
    apply(d, &c);
}

static void frame(sd_device *d, int type, const uint8_t *b) {
    sd_control c;
    if (type == ALIVE) {
        d->seen = rd32(b);
        return;
    }
    c = parse_control(b);
    if (d->queued == SD_QUEUE) { /* full: this one is dropped (the next CONTROL carries the whole setting) */
        d->corrupt++;
        return;
    }
    if (sd_ahead(c.sample, d->now) < 0) d->late++; /* it takes effect at the next sample */
    d->queue[d->queued++] = c;
}

static void streaming(sd_device *d, int on) {
    d->row_open = 0;
    if (on) {
        d->seen = d->now;
        sl_reset((sl_loop *)d->loop); /* a new run: the loop as built, as a host's fresh shadow is */
        d->loop_fault_sent = 0;
        rest_setting(d);
    } else {
        d->queued = 0;
    }
}

/* the CONTROLs due at sample j, in the order received */
static void apply_due(sd_device *d, uint32_t j) {
    uint32_t i, kept = 0;
    for (i = 0; i < d->queued; i++) {
        if (sd_ahead(j, d->queue[i].sample) >= 0)
            apply(d, &d->queue[i]);
        else
            d->queue[kept++] = d->queue[i];
    }
    d->queued = kept;
}

/* channel c of the row in SI, from the value as sent (a count is the saturated integer on the wire) */
static double si(const sd_device *d, const uint8_t *row, uint32_t c) {
    uint32_t i, at = 0;
    double raw;
    for (i = 0; i < c; i++) at += d->format[i] == 0 ? 8u : (d->format[i] == 1 ? 4u : 2u);
    if (d->format[c] == 0) return rdf64(row + at);
    raw = d->format[c] == 1 ? (double)(int32_t)rd32(row + at) : (double)(int16_t)rd16(row + at);
    return d->gain[c] * raw + d->offset[c];
}

static double sensor(const sd_device *d, const uint8_t *row, uint8_t kind) {
    uint32_t c;
    for (c = 0; c < d->channels; c++)
        if (d->kind[c] == kind) return si(d, row, c);
    return 0.0;
}

static void sample(sd_device *d, uint8_t *row) {
    sl_loop *L = (sl_loop *)d->loop;
    uint8_t *tail = row + d->row_size - SD_TELEMETRY_TAIL, p[11];
    double est[SD_MAX_ESTIMATORS];
    sl_out o;
    apply_due(d, d->now);
    d->loop_force = sl_sample(L, d->now, sensor(d, row, 0), sensor(d, row, 1), sensor(d, row, 2), &o, est);
    wrf64(tail, d->loop_force);
    wrf64(tail + 16, o.bridge_velocity);
    tail[24] = (uint8_t)d->setting.id;
    tail[25] = (uint8_t)(d->setting.id >> 8);
    d->row_open = 1;
    if (L->state[SL_L_FAULT] != 0.0 && !d->loop_fault_sent) {
        d->loop_fault_sent = 1;
        d->fault = 5; /* INTERNAL */
        p[0] = FAULT;
        p[2] = 5;
        wr32(p + 3, d->now);
        wr32(p + 7, (uint32_t)L->state[SL_L_FAULT]);
        sd_send_payload(d, p, sizeof p);
    }
}

static void actuated(sd_device *d, double applied) {
    uint8_t *row;
    uint32_t flags;
    if (!d->row_open) return;
    d->row_open = 0;
    row = d->rows + 8u + d->row_count * d->row_size;
    wrf64(row + d->row_size - SD_TELEMETRY_TAIL + 8u, applied);
    if (++d->row_count < d->packet) return;
    flags = (d->armed ? 1u : 0u) | (d->fault ? 2u : 0u) | (d->clamped ? 4u : 0u) | (d->ramping ? 8u : 0u);
    d->clamped = 0;
    d->ramping = 0;
    d->rows[0] = TELEMETRY;
    wr32(d->rows + 2, d->now - d->packet + 1u);
    d->rows[6] = (uint8_t)d->packet;
    d->rows[7] = (uint8_t)flags;
    sd_send_payload(d, d->rows, 8u + d->packet * d->row_size);
    d->row_count = 0;
}

static const sd_loop_hooks HOOKS = {valid, frame, streaming, sample, actuated};

int sd_attach_loop(sd_device *d, sl_loop *L) {
    uint32_t i;
    if (!d->loop_mode || L->n_est != d->n_est || sl_check(L) != 0) return -1;
    for (i = 0; i < d->n_est; i++)
        if (L->kinds[i] != (int64_t)d->kinds[i]) return -1;
    d->loop = L;
    d->hooks = &HOOKS;
    rest_setting(d);
    return 0;
}

void sd_loop_counters(const sd_device *d, uint32_t out[4]) {
    out[0] = d->setting.id;
    out[1] = d->queued;
    out[2] = d->seen;
    out[3] = d->loop ? (uint32_t)((const sl_loop *)d->loop)->state[SL_L_FAULT] : 0u;
}
