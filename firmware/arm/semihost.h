/* ARM semihosting (the "Semihosting for AArch32 and AArch64" specification): the harness's only I/O, a
 * debugger or qemu (-semihosting-config enable=on,target=native) serving files of the host's current
 * directory. On M-profile the call is BKPT 0xAB with the operation in r0 and its argument block in r1. */
#ifndef SEMIHOST_H
#define SEMIHOST_H

#include <stdint.h>

/* a file opened for binary reading ("rb") or writing ("wb"); -1 on failure */
int sh_open(const char *path, int write);
/* the bytes of buf not transferred (0: all of them) */
uint32_t sh_read(int fd, void *buf, uint32_t n);
uint32_t sh_write(int fd, const void *buf, uint32_t n);
int sh_close(int fd);
/* a NUL-terminated text on the host's console */
void sh_write0(const char *text);
/* stop the processor: the emulator exits with status */
void sh_exit(int status) __attribute__((noreturn));

#endif
