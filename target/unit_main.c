/*
 * unit_main.c - the Unity test images: the core's unit tests of tests/unit/
 * (the host's test sources, built with SPVS_UNIT_TARGET) run one suite
 * after another under one UNITY_BEGIN/UNITY_END, Unity's output going out
 * through semihosting one line at a time.  Which suites the image holds is
 * unit_suites.h's list (target/unity.cmake writes it).  The exit status is
 * Unity's count of failed tests (capped at BOARD_EXIT_MAX_FAILS); ctest
 * judges the summary line "N Tests 0 Failures 0 Ignored".
 */
#include "board.h"
#include "fmt.h"
#include "semihost.h"
#include "unit_support.h"
#include "unity.h"

/* Unity's characters, gathered into lines: one semihosting call per line
 * instead of one per character. */
static char unit_line[128];
static unsigned unit_len;

void unit_flush(void)
{
    if (unit_len > 0u) {
        unit_line[unit_len] = '\0';
        sh_write0(unit_line);
        unit_len = 0u;
    }
}

void unit_putc(int c)
{
    unit_line[unit_len++] = (char)c;
    if (c == '\n' || unit_len + 1u >= sizeof unit_line) {
        unit_flush();
    }
}

/* One suite, and the time it took (SysTick at BOARD_CPU_HZ: under QEMU
 * without -icount, the emulation's virtual clock). */
static void unit_timed(const char *name, void (*suite)(void))
{
    const uint64_t t0 = board_ticks();
    suite();
    const uint64_t ms = (board_ticks() - t0) / (BOARD_CPU_HZ / 1000u);
    unit_flush();
    out_str("suite ");
    out_str(name);
    out_str(": ");
    out_u32((uint32_t)ms);
    out_str(" ms\n");
}

int main(void)
{
    board_ticks_start();
    out_str("spvs " SPVS_TARGET_CPU_NAME " Unity image\n");
    UNITY_BEGIN();
#define SPVS_UNIT_SUITE(name) unit_timed(#name, suite_##name);
#include "unit_suites.h"
#undef SPVS_UNIT_SUITE
    int fails = UNITY_END();
    unit_flush();
    const uint32_t unused = board_stack_unused();
    out_str("stack used: ");
    out_u32(board_stack_size() - unused);
    out_str(" of ");
    out_u32(board_stack_size());
    out_str(" bytes\n");
    /* A stack used to its last word may have run into .bss: nothing the
     * tests said can be trusted then. */
    if (unused == 0u) {
        out_str("FAIL: the stack overflowed\n");
        fails += 1;
    }
    return fails > BOARD_EXIT_MAX_FAILS ? BOARD_EXIT_MAX_FAILS : fails;
}
