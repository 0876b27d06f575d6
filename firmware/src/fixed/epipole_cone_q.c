/*
 * epipole_cone_q.c - the epipole's support test, the reference path
 * (epipole_cone_q.h): every pair by its dot product and its squared
 * cross product, every supporter counted.  Built where SPVS_ACCEL is OFF;
 * accel/epipole_cone_fast_q.c gives the same supporters and roots.
 */
#include "epipole_cone_q.h"
#include "q.h"

int spvs_q_cone_supports(const int32_t d[2], int32_t xj, int32_t zj, const spvs_q_cone_t *k)
{
    const int64_t dot = (int64_t)d[0] * xj + (int64_t)d[1] * zj;
    const int64_t crs = (int64_t)d[0] * zj - (int64_t)d[1] * xj;
    const uint64_t c = spvs_q_abs64(crs) >> 29;
    return dot > 0 && c * c <= k->tol;
}

uint16_t spvs_q_cone_count(const int32_t (*u)[2], uint16_t n, int32_t xj, int32_t zj,
                           const spvs_q_cone_t *k, uint32_t need)
{
    (void)need;
    uint16_t support = 0;
    for (uint16_t i = 0; i < n; i++) {
        support = (uint16_t)(support + spvs_q_cone_supports(u[i], xj, zj, k));
    }
    return support;
}

uint32_t spvs_q_sqrt_floor(uint64_t x)
{
    return spvs_q_isqrt64(x);
}
