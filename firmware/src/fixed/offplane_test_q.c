/*
 * offplane_test_q.c - the off-plane transfer test, the reference path
 * (offplane_test_q.h): the squared transfer error, compared.  Built where
 * SPVS_ACCEL is OFF; accel/offplane_fast_q.c gives the same answers.
 */
#include "epipole_q.h"
#include "offplane_test_q.h"

spvs_q_off_thr_t spvs_q_off_thr(int32_t offplane_q16)
{
    spvs_q_off_thr_t t;
    const uint32_t o = offplane_q16 > 0 ? 2u * (uint32_t)offplane_q16 : 0u;
    t.off2 = (uint64_t)o * o;
    t.o_fast = 0u;
    return t;
}

int spvs_q_off_above(const int32_t H[9], const int32_t p[4], const spvs_q_off_thr_t *t)
{
    const int64_t e2 = spvs_q_transfer_err2(H, p);
    if (e2 < 0) {
        return -1;
    }
    return (uint64_t)e2 > t->off2;
}
