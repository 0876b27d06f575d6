/*
 * main_test.c - the test image: golden vectors, then the recorded replay.
 * The exit status (through semihosting) is the number of failed checks,
 * capped at BOARD_EXIT_MAX_FAILS; 0 means everything passed.
 */
#include "board.h"
#include "checks.h"
#include "fmt.h"

int main(void)
{
    out_str("spvs " SPVS_TARGET_CPU_NAME " test image\n");
    int fails = golden_run();
    fails += replay_run();
    out_str(fails == 0 ? "RESULT: PASS\n" : "RESULT: FAIL\n");
    return fails > BOARD_EXIT_MAX_FAILS ? BOARD_EXIT_MAX_FAILS : fails;
}
