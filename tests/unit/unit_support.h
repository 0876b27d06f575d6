/*
 * unit_support.h - what the core's Unity tests share on the host and on
 * the Cortex-M images (README.md, "Tests"):
 *
 *   UNIT_NOTE(fmt, ...)       a measured figure printed beside the test's
 *                             result on the host (printf); nothing on the
 *                             target, whose images link no stdio
 *   UNIT_FAIL_NOTE(fmt, ...)  fail the running test with a formatted
 *                             message (on the target: the format itself)
 *   UNIT_MAIN(suite)          the host program of one test file: Unity's
 *                             run of suite(), its summary line and exit
 *                             status; on the target (SPVS_UNIT_TARGET) one
 *                             main (target/unit_main.c) runs every suite
 *                             the image holds
 */
#ifndef SPVS_TESTS_UNIT_SUPPORT_H
#define SPVS_TESTS_UNIT_SUPPORT_H

#include "unity.h"

#if defined(SPVS_UNIT_TARGET)
#define UNIT_NOTE(...) ((void)0)
#define UNIT_FAIL_NOTE(fmt, ...) TEST_FAIL_MESSAGE(fmt)
#define UNIT_MAIN(suite)
#else
#include <stdio.h>
#define UNIT_NOTE(...) ((void)printf(__VA_ARGS__))
#define UNIT_FAIL_NOTE(...)                                   \
    do {                                                      \
        char unit_msg_[256];                                  \
        (void)snprintf(unit_msg_, sizeof unit_msg_, __VA_ARGS__); \
        TEST_FAIL_MESSAGE(unit_msg_);                         \
    } while (0)
#define UNIT_MAIN(suite)          \
    int main(void)                \
    {                             \
        UNITY_BEGIN();            \
        suite();                  \
        return UNITY_END();       \
    }
#endif

/* A suite's first statement: Unity's report names the test file (on the
 * target all suites run under one UNITY_BEGIN). */
#define UNIT_SUITE_FILE() (Unity.TestFile = __FILE__)

/* Each test file's suite: RUN_TEST of each of its tests. */
void suite_homography(void);
void suite_ransac(void);
void suite_epipole(void);
void suite_control(void);
void suite_spvs(void);
void suite_golden(void);
void suite_golden_fixed(void);
void suite_fixed_spvs(void);
void suite_fixed_q(void);
void suite_fixed_solve3(void);
void suite_fixed_fit(void);
void suite_fixed_ransac(void);
void suite_fixed_plane_h(void);
void suite_fixed_conv(void);
void suite_fixed_epipole(void);
void suite_fixed_control(void);

#endif /* SPVS_TESTS_UNIT_SUPPORT_H */
