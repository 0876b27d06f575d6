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

int main(void)
{
    out_str("spvs " SPVS_TARGET_CPU_NAME " Unity image\n");
    UNITY_BEGIN();
#define SPVS_UNIT_SUITE(name) suite_##name();
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
