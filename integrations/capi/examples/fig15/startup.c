/* Reset and exception vectors of the QEMU example (mps2-an386). A fault
   ends the run with a distinct exit code instead of spinning. */
#include <stdint.h>
#include "semihost.h"

extern uint32_t __stack_top, __data_start, __data_end, __data_load, __bss_start, __bss_end, __noinit_end;

/* Stack painting: the free RAM between the statics and the stack is filled
   with this word at reset; stack_high_water_b() finds the deepest word the
   stack overwrote. */
#define PAINT 0x5AC3A55Cu

uint32_t stack_high_water_b(void)
{
    const uint32_t *p = &__noinit_end;
    while (p < &__stack_top && *p == PAINT) {
        p++;
    }
    return (uint32_t)((uintptr_t)&__stack_top - (uintptr_t)p);
}
int main(void);

enum { EXIT_HARDFAULT = 3, EXIT_EXCEPTION = 4 };

void reset_handler(void)
{
    uint32_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = &__noinit_end; (uintptr_t)p < sp - 64; p++) {
        *p = PAINT;
    }
#if defined(__ARM_FP)
    /* The FPU first (CPACR: CP10 and CP11 full access): the guard is f32.
       (A Cortex-M3 build has no FPU: its f32 is soft-float.) */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n isb" ::: "memory");
#endif
    const uint32_t *src = &__data_load;
    for (uint32_t *dst = &__data_start; dst < &__data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &__bss_start; dst < &__bss_end;) {
        *dst++ = 0;
    }
    sh_exit((uint32_t)main());
}

static void hard_fault(void) { sh_exit(EXIT_HARDFAULT); }
static void other_exception(void) { sh_exit(EXIT_EXCEPTION); }

__attribute__((section(".vectors"), used)) static void (*const vectors[16 + 32])(void) = {
    (void (*)(void))(&__stack_top),
    reset_handler,
    other_exception, /* NMI */
    hard_fault,
    hard_fault, /* MemManage */
    hard_fault, /* BusFault */
    hard_fault, /* UsageFault */
    0, 0, 0, 0,
    other_exception, /* SVCall */
    other_exception, /* DebugMon */
    0,
    other_exception, /* PendSV */
    other_exception, /* SysTick (not enabled as an interrupt) */
    [16 ... 47] = other_exception,
};
