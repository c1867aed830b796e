/* Reset for the harness on a Cortex-M7 (qemu-system-arm -M mps2-an500, or a board with the same map):
 * the vector table (initial stack pointer, then the handlers), and a reset handler that copies .data from
 * its load address, zeroes .bss, turns the FPU on and calls main.
 *
 * The FPU: coprocessors CP10 and CP11 get full access in CPACR (bits 20-23) before any floating-point
 * instruction runs (the loop is all double precision: -mfpu=fpv5-d16 -mfloat-abi=hard). Then FPSCR and FPDSCR
 * (the value every new floating-point context starts from) are set to 0, whatever a boot loader left: round
 * to nearest, no flush to zero (FZ = 0) and no default NaN (DN = 0), the IEEE arithmetic the loop's
 * bit-for-bit equality with x86-64 needs (studyapp_estimators.h, "Maths library").
 * A fault of any kind reports through semihosting and stops with exit status 3. */
#include <stdint.h>

#include "semihost.h"

extern uint32_t __data_start, __data_end, __data_load, __bss_start, __bss_end, __stack_top;
int main(void);

#define CPACR (*(volatile uint32_t *)0xE000ED88u)
#define FPDSCR (*(volatile uint32_t *)0xE000EF3Cu)

void reset_handler(void)
{
    uint32_t *src = &__data_load, *dst = &__data_start;
    while (dst < &__data_end) *dst++ = *src++;
    for (dst = &__bss_start; dst < &__bss_end; dst++) *dst = 0;
    CPACR |= 0xFu << 20;
    __asm volatile("dsb\n\tisb" ::: "memory");
    FPDSCR = 0u;
    __asm volatile("vmsr fpscr, %0" : : "r"(0u) : "memory");
    sh_exit(main());
}

static void fault_handler(void)
{
    sh_write0("harness: processor fault\n");
    sh_exit(3);
}

/* initial stack pointer, reset, NMI, HardFault, MemManage, BusFault, UsageFault; the rest unused (no
 * interrupt is enabled). Addresses as words: ISO C has no conversion between function and data pointers. */
__attribute__((section(".vectors"), used)) static const uint32_t vectors[16] = {
    (uint32_t)&__stack_top, (uint32_t)reset_handler, (uint32_t)fault_handler, (uint32_t)fault_handler,
    (uint32_t)fault_handler, (uint32_t)fault_handler, (uint32_t)fault_handler,
};
