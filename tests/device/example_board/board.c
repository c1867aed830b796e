/* A board for firmware/example_isr.c in a test: the sensors and the host's bytes come from the test (ctypes),
 * the force and the device's bytes go back to it. A lab's board reads ADCs, writes a DAC and drives a UART. */
#include <stdint.h>
#include <string.h>

#include "studyapp_params.h"

#define LINK_SIZE (1u << 20)

static double sensors[SP_N_CHANNELS];
static double force;
static uint8_t to_device[LINK_SIZE];
static uint32_t to_device_len, to_device_at;
static uint8_t to_host[LINK_SIZE];
static uint32_t to_host_len;

void board_read_sensors(double raw[SP_N_CHANNELS]) { memcpy(raw, sensors, sizeof sensors); }
void board_write_force(double newtons) { force = newtons; }

uint32_t board_uart_read(uint8_t *buf, uint32_t cap)
{
    uint32_t n = to_device_len - to_device_at;
    if (n > cap)
        n = cap;
    memcpy(buf, to_device + to_device_at, n);
    to_device_at += n;
    return n;
}

void board_uart_write(const uint8_t *buf, uint32_t n)
{
    if (n > LINK_SIZE - to_host_len)
        n = LINK_SIZE - to_host_len;
    memcpy(to_host + to_host_len, buf, n);
    to_host_len += n;
}

/* the test's side */
void test_set_sensors(const double *raw) { memcpy(sensors, raw, sizeof sensors); }
double test_force(void) { return force; }

int test_host_write(const uint8_t *buf, uint32_t n)
{
    if (n > LINK_SIZE - to_device_len)
        return -1;
    memcpy(to_device + to_device_len, buf, n);
    to_device_len += n;
    return 0;
}

uint32_t test_host_read(uint8_t *buf, uint32_t cap)
{
    uint32_t n = to_host_len < cap ? to_host_len : cap;
    memcpy(buf, to_host, n);
    memmove(to_host, to_host + n, to_host_len - n);
    to_host_len -= n;
    return n;
}
