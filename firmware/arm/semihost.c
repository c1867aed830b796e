/* The semihosting calls the harness uses (semihost.h). Operation numbers and argument blocks: ARM's
 * semihosting specification, SYS_OPEN 0x01 (mode 1 = "rb", 5 = "wb"), SYS_CLOSE 0x02, SYS_WRITE0 0x04,
 * SYS_WRITE 0x05, SYS_READ 0x06, SYS_EXIT_EXTENDED 0x20 (reason ADP_Stopped_ApplicationExit 0x20026 and
 * the exit status). */
#include "semihost.h"

static uint32_t call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static uint32_t length(const char *s)
{
    uint32_t n = 0;
    while (s[n]) n++;
    return n;
}

int sh_open(const char *path, int write)
{
    uint32_t block[3] = {(uint32_t)path, write ? 5u : 1u, length(path)};
    return (int)call(0x01, block);
}

uint32_t sh_read(int fd, void *buf, uint32_t n)
{
    uint32_t block[3] = {(uint32_t)fd, (uint32_t)buf, n};
    return call(0x06, block);
}

uint32_t sh_write(int fd, const void *buf, uint32_t n)
{
    uint32_t block[3] = {(uint32_t)fd, (uint32_t)buf, n};
    return call(0x05, block);
}

int sh_close(int fd)
{
    uint32_t block[1] = {(uint32_t)fd};
    return (int)call(0x02, block);
}

void sh_write0(const char *text)
{
    call(0x04, text);
}

void sh_exit(int status)
{
    uint32_t block[2] = {0x20026u, (uint32_t)status};
    for (;;) call(0x20, block);
}
