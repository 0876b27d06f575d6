/* clock.c - monotonic clock and run ids (sim/clock.h). */
#define _POSIX_C_SOURCE 200809L

#include "sim/clock.h"

#include <math.h>
#include <time.h>
#include <unistd.h>

double sim_clock_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void sim_clock_sleep_until(double t_s)
{
    double whole = floor(t_s);
    struct timespec ts;
    ts.tv_sec = (time_t)whole;
    ts.tv_nsec = (long)((t_s - whole) * 1e9);
    if (ts.tv_nsec >= 1000000000L) {
        ts.tv_sec += 1;
        ts.tv_nsec -= 1000000000L;
    }
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) != 0) {
    }
}

int64_t sim_clock_run_id(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return ((int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec) ^
           ((int64_t)getpid() << 40);
}
