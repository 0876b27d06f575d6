/*
 * fmt.h - a tiny formatter for the image's console output: strings,
 * integers and floats, written through semihosting.  No stdio, no heap, no
 * double arithmetic (floats are printed from float operations only).
 */
#ifndef TARGET_FMT_H
#define TARGET_FMT_H

#include <stdint.h>

/* Write a string. */
void out_str(const char *s);
/* Write a signed decimal integer. */
void out_int(int32_t v);
/* Write an unsigned decimal integer. */
void out_u32(uint32_t v);
/* A check suite's failure line, "FAIL <what> case <idx>", when !ok. */
void out_fail_case(const char *what, int idx, int ok);
/* Write a float in fixed point with `decimals` digits (0..9) after the
 * point; |v| >= 1e9 or non-finite values print as "inf", "-inf" or "nan". */
void out_float(float v, int decimals);
/* Write a float in scientific form with 3 significant decimals, e.g.
 * "2.50e-07": for quantities of any magnitude such as relative errors. */
void out_sci(float v);

/* Format into a caller buffer instead (same rules); returns the length.
 * buf must hold at least 24 characters.  Used by the functions above. */
int fmt_int(char *buf, int32_t v);
int fmt_u32(char *buf, uint32_t v);
int fmt_float(char *buf, float v, int decimals);
int fmt_sci(char *buf, float v);

#endif /* TARGET_FMT_H */
