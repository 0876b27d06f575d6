/*
 * semihost.c - Arm semihosting through BKPT 0xAB (the M-profile form):
 * r0 holds the operation, r1 its argument; the debugger (QEMU with
 * -semihosting-config enable=on) answers in r0.
 */
#include "semihost.h"

#include <stdint.h>

enum {
    SYS_WRITEC = 0x03,
    SYS_WRITE0 = 0x04,
    SYS_EXIT_EXTENDED = 0x20,
    ADP_STOPPED_APPLICATION_EXIT = 0x20026
};

static uintptr_t sh_call(uintptr_t op, uintptr_t arg)
{
    register uintptr_t r0 __asm__("r0") = op;
    register uintptr_t r1 __asm__("r1") = arg;
    /* The memory clobber makes the compiler write out any buffer r1 points
     * at before the host reads it. */
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void sh_write0(const char *s)
{
    (void)sh_call(SYS_WRITE0, (uintptr_t)s);
}

void sh_writec(char c)
{
    (void)sh_call(SYS_WRITEC, (uintptr_t)&c);
}

void sh_exit(int status)
{
    /* SYS_EXIT_EXTENDED takes a two-word block: the reason and the status
     * (plain SYS_EXIT could only say 0 or 1). */
    static volatile uint32_t block[2];
    block[0] = ADP_STOPPED_APPLICATION_EXIT;
    block[1] = (uint32_t)status;
    (void)sh_call(SYS_EXIT_EXTENDED, (uintptr_t)block);
    /* Without a host that honours the call there is nothing left to do. */
    for (;;) {
        __asm__ volatile("wfi");
    }
}
