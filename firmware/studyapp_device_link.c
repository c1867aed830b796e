/* studyapp device protocol, the link's side of the device core: CRC-16/CCITT-FALSE, COBS framing out
 * (sd_send_payload), the receiver (sd_rx: runs to 0x00, COBS, CRC; sound payloads go to sd_payload in
 * studyapp_device.c) and the send buffer (sd_tx). Mirrors studyapp/device/crc.py, cobs.py and frames.py. */
#include "studyapp_device.h"

#include <string.h>

uint16_t sd_crc16(const uint8_t *data, uint32_t n, uint16_t crc) {
    uint32_t i;
    int b;
    for (i = 0; i < n; i++) {
        crc ^= (uint16_t)(data[i] << 8);
        for (b = 0; b < 8; b++)
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
    }
    return crc;
}

void sd_send_payload(sd_device *d, uint8_t *payload, uint32_t n) {
    uint32_t need = n + 2u + (n + 2u) / 254u + 2u, i, o, code_at;
    uint16_t crc;
    uint8_t code, byte;
    payload[1] = d->tx_seq++;
    if (d->tx_len + need > SD_TX_SIZE) {
        d->tx_dropped++;
        return;
    }
    crc = sd_crc16(payload, n, 0xFFFFu);
    o = d->tx_len;
    code_at = o++;
    code = 1;
    for (i = 0; i < n + 2u; i++) {
        byte = i < n ? payload[i] : (i == n ? (uint8_t)(crc & 0xFFu) : (uint8_t)(crc >> 8));
        if (code == 255) {
            d->tx[code_at] = 255;
            code_at = o++;
            code = 1;
        }
        if (byte == 0) {
            d->tx[code_at] = code;
            code_at = o++;
            code = 1;
        } else {
            d->tx[o++] = byte;
            code++;
        }
    }
    d->tx[code_at] = code;
    d->tx[o++] = 0;
    d->tx_len = o;
}

static void finish_run(sd_device *d) {
    uint8_t p[SD_MAX_ENCODED];
    uint32_t i = 0, n = d->rx_len, o = 0, end, code, k;
    int overlong = d->rx_overlong;
    d->rx_len = 0;
    d->rx_overlong = 0;
    if (overlong) {
        sd_corrupt_frame(d);
        return;
    }
    if (n == 0) return;
    while (i < n) { /* COBS: the run holds no 0x00 */
        code = d->rx[i];
        end = i + code;
        if (end > n) {
            sd_corrupt_frame(d);
            return;
        }
        for (k = i + 1u; k < end; k++) p[o++] = d->rx[k];
        i = end;
        if (code < 255u && i < n) p[o++] = 0;
    }
    if (o < 4u || sd_crc16(p, o - 2u, 0xFFFFu) != (uint16_t)(p[o - 2u] | (p[o - 1u] << 8))) {
        sd_corrupt_frame(d);
        return;
    }
    sd_payload(d, p, o - 2u);
}

void sd_rx(sd_device *d, const uint8_t *data, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++) {
        if (data[i] == 0) {
            finish_run(d);
        } else if (!d->rx_overlong) {
            if (d->rx_len == SD_MAX_ENCODED) {
                d->rx_overlong = 1;
                d->rx_len = 0;
            } else {
                d->rx[d->rx_len++] = data[i];
            }
        }
    }
}

uint32_t sd_tx(sd_device *d, uint8_t *out, uint32_t cap) {
    uint32_t n = d->tx_len < cap ? d->tx_len : cap;
    memcpy(out, d->tx, n);
    memmove(d->tx, d->tx + n, d->tx_len - n);
    d->tx_len -= n;
    return n;
}
