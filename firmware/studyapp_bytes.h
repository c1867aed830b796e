/* Little-endian fields and wrapping sample counters, for the device core's C files (studyapp_device*.c):
 * every integer of the protocol is little-endian, every float IEEE-754 binary64 (docs/device-protocol.md). */
#ifndef STUDYAPP_BYTES_H
#define STUDYAPP_BYTES_H

#include <stdint.h>
#include <string.h>

static inline uint32_t rd32(const uint8_t *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static inline uint64_t rd64(const uint8_t *p) { return (uint64_t)rd32(p) | ((uint64_t)rd32(p + 4) << 32); }
static inline double rdf64(const uint8_t *p) {
    uint64_t u = rd64(p);
    double f;
    memcpy(&f, &u, 8);
    return f;
}
static inline void wr32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); p[2] = (uint8_t)(v >> 16); p[3] = (uint8_t)(v >> 24);
}
static inline void wrf64(uint8_t *p, double f) {
    uint64_t u;
    memcpy(&u, &f, 8);
    wr32(p, (uint32_t)u);
    wr32(p + 4, (uint32_t)(u >> 32));
}
static inline int finite64(const uint8_t *p) { return ((rd64(p) >> 52) & 0x7FFu) != 0x7FFu; }

/* a - b as a signed difference of wrapping 32-bit counters */
static inline int64_t sd_ahead(uint32_t a, uint32_t b) {
    uint32_t d = a - b;
    return d < 0x80000000u ? (int64_t)d : (int64_t)d - (int64_t)0x100000000LL;
}

#endif
