/* cli.c - command-line options at the edge (sim/cli.h). */
#include "sim/cli.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

static const char *g_program = "error";

/* strtod over s up to *end, with the checks every real shares: something
 * was read, no overflow or underflow, finite.  Returns 0 or -1. */
static int read_real(const char *s, double *v, char **end)
{
    errno = 0;
    *v = strtod(s, end);
    return *end == s || errno == ERANGE || !isfinite(*v) ? -1 : 0;
}

/* The range in words, "in [0, 1)", "> 0", or "" for (-inf, inf). */
static void describe_range(double lo, double hi, int bounds, char *buf,
                           size_t len)
{
    const int open_lo = (bounds & SIM_CLI_OPEN_LO) != 0;
    const int open_hi = (bounds & SIM_CLI_OPEN_HI) != 0;
    if (isinf(lo) && isinf(hi)) {
        buf[0] = '\0';
    } else if (isinf(hi)) {
        snprintf(buf, len, " %s %g", open_lo ? ">" : ">=", lo);
    } else if (isinf(lo)) {
        snprintf(buf, len, " %s %g", open_hi ? "<" : "<=", hi);
    } else {
        snprintf(buf, len, " in %c%g, %g%c", open_lo ? '(' : '[', lo, hi,
                 open_hi ? ')' : ']');
    }
}

static int in_range(double v, double lo, double hi, int bounds)
{
    const int lo_ok = (bounds & SIM_CLI_OPEN_LO) ? v > lo : v >= lo;
    const int hi_ok = (bounds & SIM_CLI_OPEN_HI) ? v < hi : v <= hi;
    return lo_ok && hi_ok;
}

int sim_cli_parse_int(const char *opt, const char *s, long long lo,
                      long long hi, long long *out, char *err,
                      size_t err_len)
{
    char *end = NULL;
    long long v = 0;
    int ok = s != NULL;
    if (ok) {
        errno = 0;
        v = strtoll(s, &end, 10);
        ok = end != s && *end == '\0' && errno != ERANGE && v >= lo &&
             v <= hi;
    }
    if (!ok) {
        if (err_len > 0) {
            snprintf(err, err_len, "%s: '%.80s' is not an integer in %lld..%lld",
                     opt, s ? s : "", lo, hi);
        }
        return -1;
    }
    *out = v;
    return 0;
}

int sim_cli_parse_real(const char *opt, const char *s, double lo, double hi,
                       int bounds, double *out, char *err, size_t err_len)
{
    char *end = NULL;
    double v = 0.0;
    int ok = s != NULL && read_real(s, &v, &end) == 0 && *end == '\0';
    if (ok && in_range(v, lo, hi, bounds)) {
        *out = v;
        return 0;
    }
    if (err_len > 0) {
        char range[96];
        describe_range(lo, hi, bounds, range, sizeof(range));
        if (range[0] == '\0') {
            snprintf(err, err_len, "%s: '%.80s' is not a finite number", opt,
                     s ? s : "");
        } else {
            snprintf(err, err_len, "%s: '%.80s' is not a number%s", opt,
                     s ? s : "", range);
        }
    }
    return -1;
}

int sim_cli_parse_triple(const char *opt, const char *s, double lo, double hi,
                         double out[3], char *err, size_t err_len)
{
    double v[3];
    int ok = s != NULL;
    int ranged = 1;
    const char *p = s;
    for (int i = 0; ok && i < 3; ++i) {
        char *end = NULL;
        ok = read_real(p, &v[i], &end) == 0 && *end == (i < 2 ? ',' : '\0');
        if (ok) {
            ranged = ranged && in_range(v[i], lo, hi, SIM_CLI_CLOSED);
            p = end + 1;
        }
    }
    if (ok && ranged) {
        out[0] = v[0];
        out[1] = v[1];
        out[2] = v[2];
        return 0;
    }
    if (err_len > 0) {
        char range[96];
        describe_range(lo, hi, SIM_CLI_CLOSED, range, sizeof(range));
        if (!ok || range[0] == '\0') {
            snprintf(err, err_len,
                     "%s: '%.80s' is not three finite numbers X,Y,Z", opt,
                     s ? s : "");
        } else {
            snprintf(err, err_len, "%s: '%.80s' is not three numbers%s", opt,
                     s, range);
        }
    }
    return -1;
}

void sim_cli_program(const char *name)
{
    g_program = name ? name : "error";
}

void sim_cli_fail(const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof(msg), fmt, ap);
    va_end(ap);
    /* One line whatever the text quoted: a control character in an
     * argument (a newline) would split it. */
    for (char *c = msg; *c; ++c) {
        if ((unsigned char)*c < 0x20 || *c == 0x7f) {
            *c = '?';
        }
    }
    fprintf(stderr, "%s: %s (see --help)\n", g_program, msg);
    exit(SIM_CLI_EXIT_USAGE);
}

long long sim_cli_int(const char *opt, const char *s, long long lo,
                      long long hi)
{
    char err[256];
    long long v = 0;
    if (sim_cli_parse_int(opt, s, lo, hi, &v, err, sizeof(err)) != 0) {
        sim_cli_fail("%s", err);
    }
    return v;
}

double sim_cli_real(const char *opt, const char *s, double lo, double hi,
                    int bounds)
{
    char err[256];
    double v = 0.0;
    if (sim_cli_parse_real(opt, s, lo, hi, bounds, &v, err, sizeof(err)) !=
        0) {
        sim_cli_fail("%s", err);
    }
    return v;
}

void sim_cli_triple(const char *opt, const char *s, double lo, double hi,
                    double out[3])
{
    char err[256];
    if (sim_cli_parse_triple(opt, s, lo, hi, out, err, sizeof(err)) != 0) {
        sim_cli_fail("%s", err);
    }
}

void sim_cli_help_option(FILE *f, int col, const char *name, const char *metavar,
                         const char *help)
{
    char left[96];
    const int w = snprintf(left, sizeof(left), "%s%s%s", name, metavar ? " " : "",
                           metavar ? metavar : "");
    fprintf(f, "  %s", left);
    if (w <= col - 2) {
        fprintf(f, "%*s", col - w, "");
    } else {
        fprintf(f, "\n  %*s", col, "");
    }
    for (const char *c = help; *c; c++) {
        if (*c == '\n') {
            fprintf(f, "\n  %*s", col, "");
        } else {
            fputc(*c, f);
        }
    }
    fputc('\n', f);
}
