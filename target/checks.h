/*
 * checks.h - the check suites the test image runs; each returns its number
 * of failed checks and prints a summary through semihosting.
 */
#ifndef TARGET_CHECKS_H
#define TARGET_CHECKS_H

/* Golden vectors (tests/golden/golden_vectors.h). */
int golden_run(void);

/* Recorded closed-loop replay (tests/golden/replay_frames.h). */
int replay_run(void);

#endif /* TARGET_CHECKS_H */
