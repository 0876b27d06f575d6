/* test_fixed_conv.c - the fixed-point core's conversion of Q values to the
 * public API's float and double bits (firmware/src/fixed/q.h,
 * spvs_q_ieee_bits) against the host's own rounding (ldexp in long
 * double, then the conversion the FPU makes: to nearest, ties to even). */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

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
static void test_q_ieee_bits(void **state)
{
    (void)state;
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
    print_message("ieee bits: %ld values, float differs at %ld, double at %ld\n", n, differ32,
                  differ64);
    assert_int_equal(differ32, 0);
    assert_int_equal(differ64, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_q_ieee_bits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
