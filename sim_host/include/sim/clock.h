/*
 * clock.h - the edge's two notions of "now", written once: a monotonic
 * clock for timeouts, watchdogs and resends, and the run id that tells a
 * controller node that a new run has started.
 *
 * Frame time (t_s, utime) is the simulator's own and never comes from here;
 * these are for waiting on processes and networks.
 */
#ifndef SIM_CLOCK_H
#define SIM_CLOCK_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Monotonic clock (CLOCK_MONOTONIC), seconds from an arbitrary origin.  It
 * never steps back when the wall clock is set. */
double sim_clock_now_s(void);

/* Sleep until the monotonic clock reads t_s (seconds, as sim_clock_now_s);
 * at once if that has passed.  A signal does not cut the sleep short: the
 * deadline is absolute. */
void sim_clock_sleep_until(double t_s);

/* A run id unlike any earlier run's on this machine: the wall clock in
 * nanoseconds mixed with the process id, so that two links opened in the
 * same nanosecond by different processes still differ.  A node that sees a
 * new run id resets its controller (docs/LCM.md). */
int64_t sim_clock_run_id(void);

#ifdef __cplusplus
}
#endif

#endif /* SIM_CLOCK_H */
