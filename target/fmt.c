/*
 * fmt.c - integer formatting without stdio (floats: fmt_float.c, which the
 * fixed-point build's images, linking no float helper, leave out).
 */
#include "fmt.h"

#include "semihost.h"

int fmt_u32(char *buf, uint32_t v)
{
    char tmp[12];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + (v % 10u));
        v /= 10u;
    } while (v != 0u);
    for (int i = 0; i < n; ++i) {
        buf[i] = tmp[n - 1 - i];
    }
    buf[n] = '\0';
    return n;
}

int fmt_int(char *buf, int32_t v)
{
    if (v < 0) {
        buf[0] = '-';
        /* Negate in unsigned arithmetic so INT32_MIN does not overflow. */
        return 1 + fmt_u32(buf + 1, 0u - (uint32_t)v);
    }
    return fmt_u32(buf, (uint32_t)v);
}

void out_str(const char *s)
{
    sh_write0(s);
}

void out_int(int32_t v)
{
    char b[24];
    (void)fmt_int(b, v);
    sh_write0(b);
}

void out_u32(uint32_t v)
{
    char b[24];
    (void)fmt_u32(b, v);
    sh_write0(b);
}

void out_fail_case(const char *what, int idx, int ok)
{
    if (!ok) {
        out_str("FAIL ");
        out_str(what);
        out_str(" case ");
        out_int(idx);
        out_str("\n");
    }
}
