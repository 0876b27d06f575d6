/*
 * fmt_float.c - float formatting without stdio.  Floats are split in float
 * arithmetic into an integer part and a scaled fraction, each printed as an
 * integer, so the float build links no double helper.  A file of its own
 * (a library the images link on demand) so that an image that prints no
 * float links no float helper.
 */
#include "fmt.h"

#include "semihost.h"

static int fmt_special(char *buf, float v)
{
    const char *s = (v != v) ? "nan" : (v < 0.0f ? "-inf" : "inf");
    int n = 0;
    while (s[n] != '\0') {
        buf[n] = s[n];
        ++n;
    }
    buf[n] = '\0';
    return n;
}

int fmt_float(char *buf, float v, int decimals)
{
    static const uint32_t pow10[10] = {1u, 10u, 100u, 1000u, 10000u, 100000u,
                                       1000000u, 10000000u, 100000000u, 1000000000u};
    if (decimals < 0) {
        decimals = 0;
    }
    if (decimals > 9) {
        decimals = 9;
    }
    if (v != v || v >= 1e9f || v <= -1e9f) {
        return fmt_special(buf, v);
    }
    int n = 0;
    if (v < 0.0f) {
        buf[n++] = '-';
        v = -v;
    }
    /* Round once at the last printed digit, then split; the fraction is
     * below 1 so its scaled value fits in 32 bits for 9 decimals. */
    float scale = (float)pow10[decimals];
    uint32_t ip = (uint32_t)v;
    float frac = (v - (float)ip) * scale + 0.5f;
    uint32_t fp = (uint32_t)frac;
    if (fp >= pow10[decimals]) {
        fp -= pow10[decimals];
        ip += 1u;
    }
    n += fmt_u32(buf + n, ip);
    if (decimals > 0) {
        buf[n++] = '.';
        char digits[12];
        int nd = fmt_u32(digits, fp);
        for (int i = nd; i < decimals; ++i) {
            buf[n++] = '0';
        }
        for (int i = 0; i < nd; ++i) {
            buf[n++] = digits[i];
        }
        buf[n] = '\0';
    }
    return n;
}

int fmt_sci(char *buf, float v)
{
    if (v != v || v > 3e38f || v < -3e38f) {
        return fmt_special(buf, v);
    }
    int n = 0;
    if (v < 0.0f) {
        buf[n++] = '-';
        v = -v;
    }
    int e = 0;
    if (v != 0.0f) {
        while (v >= 10.0f) {
            v /= 10.0f;
            ++e;
        }
        while (v < 1.0f) {
            v *= 10.0f;
            --e;
        }
        /* Rounding to 3 significant digits can carry to 10.00. */
        if (v >= 9.995f) {
            v /= 10.0f;
            ++e;
        }
    }
    n += fmt_float(buf + n, v, 2);
    buf[n++] = 'e';
    buf[n++] = (e < 0) ? '-' : '+';
    if (e < 0) {
        e = -e;
    }
    if (e < 10) {
        buf[n++] = '0';
    }
    n += fmt_int(buf + n, e);
    return n;
}

void out_float(float v, int decimals)
{
    char b[24];
    (void)fmt_float(b, v, decimals);
    sh_write0(b);
}

void out_sci(float v)
{
    char b[24];
    (void)fmt_sci(b, v);
    sh_write0(b);
}
