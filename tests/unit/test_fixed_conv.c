/* test_fixed_conv.c - the fixed-point core's conversion of Q values to the
 * public API's float and double bits (firmware/src/fixed/q.h,
 * spvs_q_ieee_bits) against the host's own rounding (ldexp in long
 * double, then the conversion the FPU makes: to nearest, ties to even). */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "fixed/points_q.h"
#include "fixed/q.h"

static uint64_t rnd64(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static uint32_t host_f32(int64_t x, int f)
{
    const float v = (float)ldexpl((long double)x, -f);
    uint32_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static uint64_t host_f64(int64_t x, int f)
{
    const double v = (double)ldexpl((long double)x, -f);
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

/* Random x of every bit length and sign, at every exponent that reaches
 * float's and double's normal, subnormal and overflowing ranges; and the
 * ties: x with exactly one bit below the kept mantissa set, odd and even.
 * Every result must be the host's bits exactly. */
static void test_q_ieee_bits(void)
{
    uint64_t s = 88172645463325252u;
    long n = 0, differ32 = 0, differ64 = 0;
    for (int f = -200; f <= 1200; f += 7) {
        for (int k = 0; k < 200; k++) {
            const int len = 1 + (int)(rnd64(&s) % 63u);
            uint64_t m = rnd64(&s) >> (64 - len);
            if (k % 4 == 0 && len > 26) {
                /* A tie for a normal float: of the bits below the 24 kept,
                 * only the first set. */
                const int low = len - 25;
                m = ((m >> (low + 1)) << (low + 1)) | ((uint64_t)1 << low);
            }
            const int64_t x = (rnd64(&s) & 1u) ? -(int64_t)m : (int64_t)m;
            n++;
            differ32 += spvs_q_ieee_bits(x, f, 23, 8) != host_f32(x, f);
            if (f <= 1100) {
                differ64 += spvs_q_ieee_bits(x, f, 52, 11) != host_f64(x, f);
            }
        }
    }
    /* Fixed cases: 0, the extremes of int64, 1 in every Q. */
    const int64_t fx[] = {0, 1, -1, INT64_MAX, INT64_MIN + 1, (int64_t)1 << 40};
    for (size_t i = 0; i < sizeof fx / sizeof fx[0]; i++) {
        for (int f = -64; f <= 160; f++) {
            n++;
            differ32 += spvs_q_ieee_bits(fx[i], f, 23, 8) != host_f32(fx[i], f);
            differ64 += spvs_q_ieee_bits(fx[i], f, 52, 11) != host_f64(fx[i], f);
        }
    }
    UNIT_NOTE("ieee bits: %ld values, float differs at %ld, double at %ld\n", n, differ32, differ64);
    TEST_ASSERT_EQUAL_INT64(0, differ32);
    TEST_ASSERT_EQUAL_INT64(0, differ64);
}

/* The loader's conversion of the matches' coordinates (points_q.c; in the
 * float build a 32-bit-only path) against q.h's general conversion of the
 * same bits: every coordinate within SPVS_MAX_COORD_PX, random bit patterns
 * of every exponent (subnormals, tiny values, the limit and the floats next
 * to it), the same integer and the same range decision. */
static void test_q_load_bits(void)
{
    static spvs_q_store_t st;
    uint16_t feat[1];
    spvs_match_t m[1];
    uint64_t s = 1234567u;
    const int px_frac = SPVS_QC - (31 - spvs_q_clz32((uint32_t)SPVS_COORD_SCALE));
    long n = 0, differ = 0, refused = 0;
    for (int k = 0; k < 400000; k++) {
        spvs_real c;
        if (k < 4) {
            const spvs_real lim = (spvs_real)SPVS_MAX_COORD_PX;
            c = k == 0 ? lim : (k == 1 ? -lim : (k == 2 ? nextafterf(lim, 1e9f) : nextafterf(lim, 0)));
        } else if (sizeof(spvs_real) == 4) {
            uint32_t b = (uint32_t)rnd64(&s);
            /* Exponents from subnormal to just above the limit's. */
            b = (b & 0x807fffffu) | ((uint32_t)(rnd64(&s) % 142u) << 23);
            memcpy(&c, &b, sizeof c);
        } else {
            c = (spvs_real)ldexp((double)(int32_t)rnd64(&s), -(int)(rnd64(&s) % 80u));
        }
        m[0].x_tgt = m[0].y_tgt = m[0].x_cur = m[0].y_cur = c;
        m[0].feature = 0;
        const uint32_t bad = spvs_q_pts_load(&st, feat, m, 1, 1, NULL, 1);
        uint32_t sat = 0;
        int below = 0;
#if SPVS_USE_DOUBLE
        uint64_t bits;
        memcpy(&bits, &c, sizeof bits);
        const spvs_q_ieee_t v = spvs_q_ieee_f64(bits);
#else
        uint32_t bits;
        memcpy(&bits, &c, sizeof bits);
        const spvs_q_ieee_t v = spvs_q_ieee_f32(bits);
#endif
        const int32_t q = spvs_q_from_ieee(v, px_frac, &sat, &below);
        const int out = fabs((double)c) > (double)SPVS_MAX_COORD_PX;
        n++;
        refused += bad != 0u;
        differ += (bad != 0u) != out || (!out && st.v[0] != q);
    }
    UNIT_NOTE("load bits: %ld coordinates, %ld out of range, %ld differ\n", n, refused, differ);
    TEST_ASSERT_EQUAL_INT64(0, differ);
    TEST_ASSERT_TRUE(refused > 0);
}

void suite_fixed_conv(void)
{
    UNIT_SUITE_FILE();
#if !defined(SPVS_UNIT_TARGET)
    /* On the Cortex-M images: its reference rounds through long double, which has a 64-bit mantissa on x86-64 but is double on ARM (double rounding there): host only. */
    RUN_TEST(test_q_ieee_bits);
#endif
    RUN_TEST(test_q_load_bits);
}

UNIT_MAIN(suite_fixed_conv)
