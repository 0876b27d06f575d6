/*
 * cli.h - command-line options at the edge, written once: numbers checked
 * against their ranges with a message that names the option, and the one
 * way a program refuses bad options (one line on stderr, exit status 2).
 *
 * Used by spvs-sim, spvs-node, spvs-lcm-faults and the bench programs, from
 * C and C++.  Two layers:
 *   - sim_cli_parse_*: parse text into a value; on failure return -1 and
 *     write a one-line reason "OPT: 'TEXT' is not ..." to err.  They never
 *     exit, so library code (parameter files, environment settings) and the
 *     unit tests use them;
 *   - sim_cli_int/real/triple: the same for a command line, refusing bad
 *     input through sim_cli_fail.
 * Each program keeps its options in one table that its parser and its
 * --help read; sim_cli_help_option lays out one row of --help.
 *
 * Accepted text: an integer is what strtoll reads in base 10 (an optional
 * sign and decimal digits); a real is what strtod reads that is finite and
 * neither overflows nor underflows (1e999, 1e-999, inf and nan are
 * refused); a triple is three reals separated by commas ("X,Y,Z").  As with
 * strtod, leading spaces are skipped; an empty string, or anything after the
 * number, is refused.  The text is quoted in a message up to 80 characters.
 */
#ifndef SIM_CLI_H
#define SIM_CLI_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exit status of a program refusing its options. */
#define SIM_CLI_EXIT_USAGE 2

/* Which ends of a real range [lo, hi] are themselves outside it. */
enum {
    SIM_CLI_CLOSED = 0,  /* [lo, hi] */
    SIM_CLI_OPEN_LO = 1, /* (lo, hi] */
    SIM_CLI_OPEN_HI = 2, /* [lo, hi) */
    SIM_CLI_OPEN = 3     /* (lo, hi) */
};

/* No bound on that side: -SIM_CLI_INF or SIM_CLI_INF as lo or hi. */
#define SIM_CLI_INF HUGE_VAL

/* Integer in lo..hi (inclusive).  Returns 0 with *out set, or -1 with
 * "OPT: 'S' is not an integer in LO..HI" in err (err_len bytes, may be 0);
 * *out is then untouched. */
int sim_cli_parse_int(const char *opt, const char *s, long long lo,
                      long long hi, long long *out, char *err,
                      size_t err_len);

/* Finite real in the range lo..hi with the ends given by `bounds`
 * (SIM_CLI_CLOSED ...).  Returns 0 with *out set, or -1 with "OPT: 'S' is
 * not a finite number" or "OPT: 'S' is not a number in [LO, HI)" (or
 * "> LO", "<= HI", ... for a one-sided range) in err; *out untouched. */
int sim_cli_parse_real(const char *opt, const char *s, double lo, double hi,
                       int bounds, double *out, char *err, size_t err_len);

/* "X,Y,Z": three finite reals, each in [lo, hi].  Returns 0 with out[0..2]
 * set, or -1 with "OPT: 'S' is not three finite numbers X,Y,Z" (or the
 * range) in err; out untouched. */
int sim_cli_parse_triple(const char *opt, const char *s, double lo, double hi,
                         double out[3], char *err, size_t err_len);

/* The program name that starts every error line ("spvs-sim").  Call once
 * at the start of main; until then "error" is used. */
void sim_cli_program(const char *name);

/* Refuse the command line: "PROGRAM: MESSAGE (see --help)" on stderr, one
 * line, then exit(SIM_CLI_EXIT_USAGE).  MESSAGE is printf-formatted. */
#if defined(__GNUC__)
__attribute__((noreturn, format(printf, 1, 2)))
#endif
void sim_cli_fail(const char *fmt, ...);

/* The parse functions above for a command-line option: the value, or
 * sim_cli_fail with the reason. */
long long sim_cli_int(const char *opt, const char *s, long long lo,
                      long long hi);
double sim_cli_real(const char *opt, const char *s, double lo, double hi,
                    int bounds);
void sim_cli_triple(const char *opt, const char *s, double lo, double hi,
                    double out[3]);

/* One option's lines of --help on f: "  NAME METAVAR" (metavar NULL for a
 * flag), then help from `col` columns after the indent: on the same line
 * where two spaces are left before it, else on the next; each '\n' in help
 * starts a line at the same column. */
void sim_cli_help_option(FILE *f, int col, const char *name, const char *metavar,
                         const char *help);

#ifdef __cplusplus
}
#endif

#endif /* SIM_CLI_H */
