/*
 * test_cli.c - the edge's command-line helper (sim/cli.h): integers, reals
 * and triples against their ranges, junk, empty text, overflow and
 * underflow, the exact one-line messages, and the refusal itself (exit
 * status 2, one line on stderr) in a child process.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "sim/cli.h"

/* A value the parsers must leave alone when they refuse. */
#define UNTOUCHED 777

/* ---- integers ------------------------------------------------------------ */

static void int_in_range(void **state)
{
    (void)state;
    char err[128] = "";
    long long v = UNTOUCHED;
    assert_int_equal(sim_cli_parse_int("--n", "42", 0, 100, &v, err, sizeof err), 0);
    assert_int_equal(v, 42);
    assert_int_equal(sim_cli_parse_int("--n", "-5", -10, 10, &v, err, sizeof err), 0);
    assert_int_equal(v, -5);
    /* Both ends belong to the range. */
    assert_int_equal(sim_cli_parse_int("--n", "0", 0, 100, &v, err, sizeof err), 0);
    assert_int_equal(v, 0);
    assert_int_equal(sim_cli_parse_int("--n", "100", 0, 100, &v, err, sizeof err), 0);
    assert_int_equal(v, 100);
    /* The largest seed a 32-bit option takes. */
    assert_int_equal(sim_cli_parse_int("--seed", "4294967295", 0, 4294967295LL, &v,
                                       err, sizeof err), 0);
    assert_true(v == 4294967295LL);
    /* strtoll's own forms: a sign, leading spaces. */
    assert_int_equal(sim_cli_parse_int("--n", "+7", 0, 100, &v, err, sizeof err), 0);
    assert_int_equal(v, 7);
    assert_int_equal(sim_cli_parse_int("--n", "  8", 0, 100, &v, err, sizeof err), 0);
    assert_int_equal(v, 8);
}

static void int_refused(void **state)
{
    (void)state;
    static const char *const bad[] = {
        "101",                   /* above the range 0..100      */
        "-1",                    /* below it                    */
        "4294967296",            /* far above                   */
        "",                      /* empty                       */
        " ",                     /* only a space                */
        "12x",                   /* junk after the digits       */
        "x12",                   /* junk before                 */
        "1.5",                   /* not an integer              */
        "1e3",                   /* exponent form               */
        "8 ",                    /* trailing space              */
        "99999999999999999999",  /* overflows long long         */
        "-99999999999999999999", /* underflows long long        */
        "0x10",                  /* not decimal                 */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char err[128] = "";
        long long v = UNTOUCHED;
        int rc = sim_cli_parse_int("--seed", bad[i], 0, 100, &v, err, sizeof err);
        assert_int_equal(rc, -1);
        assert_int_equal(v, UNTOUCHED);
        assert_non_null(strstr(err, "--seed: '"));
    }
    char err[128];
    long long v = UNTOUCHED;
    assert_int_equal(sim_cli_parse_int("--seed", "-1", 0, 4294967295LL, &v, err,
                                       sizeof err), -1);
    assert_string_equal(err, "--seed: '-1' is not an integer in 0..4294967295");
    assert_int_equal(sim_cli_parse_int("--method", "7", 1, 3, &v, err, sizeof err), -1);
    assert_string_equal(err, "--method: '7' is not an integer in 1..3");
    assert_int_equal(sim_cli_parse_int("--method", NULL, 1, 3, &v, err, sizeof err), -1);
    assert_string_equal(err, "--method: '' is not an integer in 1..3");
    assert_int_equal(v, UNTOUCHED);
}

/* ---- reals ----------------------------------------------------------------- */

static void real_in_range(void **state)
{
    (void)state;
    char err[128] = "";
    double v = UNTOUCHED;
    assert_int_equal(sim_cli_parse_real("--noise", "0.25", 0.0, SIM_CLI_INF,
                                        SIM_CLI_OPEN_HI, &v, err, sizeof err), 0);
    assert_true(v == 0.25);
    assert_int_equal(sim_cli_parse_real("--drift", "-1.5e-2", -SIM_CLI_INF, SIM_CLI_INF,
                                        SIM_CLI_OPEN, &v, err, sizeof err), 0);
    assert_true(v == -1.5e-2);
    /* (0, 3600]: the upper end is in, a hair above it is not. */
    assert_int_equal(sim_cli_parse_real("--timeout", "3600", 0.0, 3600.0,
                                        SIM_CLI_OPEN_LO, &v, err, sizeof err), 0);
    assert_true(v == 3600.0);
    /* [0, 1): the lower end is in. */
    assert_int_equal(sim_cli_parse_real("--outliers", "0", 0.0, 1.0, SIM_CLI_OPEN_HI,
                                        &v, err, sizeof err), 0);
    assert_true(v == 0.0);
    assert_int_equal(sim_cli_parse_real("--outliers", "0.999", 0.0, 1.0, SIM_CLI_OPEN_HI,
                                        &v, err, sizeof err), 0);
    assert_true(v == 0.999);
    /* Leading spaces are skipped, as strtod does. */
    assert_int_equal(sim_cli_parse_real("--dt", " .5", 0.0, 10.0, SIM_CLI_OPEN_LO,
                                        &v, err, sizeof err), 0);
    assert_true(v == 0.5);
}

/* Text with its range; each must be refused and leave v alone. */
typedef struct {
    const char *s;
    double lo, hi;
    int bounds;
} real_case_t;

static void real_refused(void **state)
{
    (void)state;
    static const real_case_t bad[] = {
        { "0", 0.0, 3600.0, SIM_CLI_OPEN_LO },           /* open lower end    */
        { "3600.0001", 0.0, 3600.0, SIM_CLI_OPEN_LO },   /* above the range   */
        { "1", 0.0, 1.0, SIM_CLI_OPEN_HI },              /* open upper end    */
        { "-0.001", 0.0, 1.0, SIM_CLI_CLOSED },          /* below             */
        { "0", 0.0, 1.0, SIM_CLI_OPEN },                 /* both ends open    */
        { "1", 0.0, 1.0, SIM_CLI_OPEN },
        { "1e999", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },   /* overflow  */
        { "-1e999", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "1e-400", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },  /* underflow */
        { "inf", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "-inf", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "nan", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },        /* empty     */
        { "   ", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "5abc", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },    /* junk      */
        { "abc", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "5 ", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },      /* trailing  */
        { "1,2", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
        { "--", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char err[128] = "";
        double v = UNTOUCHED;
        int rc = sim_cli_parse_real("--x", bad[i].s, bad[i].lo, bad[i].hi,
                                    bad[i].bounds, &v, err, sizeof err);
        assert_int_equal(rc, -1);
        assert_true(v == UNTOUCHED);
        assert_non_null(strstr(err, "--x: '"));
    }
}

static void real_messages(void **state)
{
    (void)state;
    char err[128];
    double v;
    sim_cli_parse_real("--outliers", "1", 0.0, 1.0, SIM_CLI_OPEN_HI, &v, err, sizeof err);
    assert_string_equal(err, "--outliers: '1' is not a number in [0, 1)");
    sim_cli_parse_real("--dt", "11", 0.0, 10.0, SIM_CLI_OPEN_LO, &v, err, sizeof err);
    assert_string_equal(err, "--dt: '11' is not a number in (0, 10]");
    sim_cli_parse_real("--drop", "2", 0.0, 1.0, SIM_CLI_CLOSED, &v, err, sizeof err);
    assert_string_equal(err, "--drop: '2' is not a number in [0, 1]");
    sim_cli_parse_real("--x", "1", 0.0, 1.0, SIM_CLI_OPEN, &v, err, sizeof err);
    assert_string_equal(err, "--x: '1' is not a number in (0, 1)");
    sim_cli_parse_real("--distance", "0", 0.0, SIM_CLI_INF, SIM_CLI_OPEN, &v, err,
                       sizeof err);
    assert_string_equal(err, "--distance: '0' is not a number > 0");
    sim_cli_parse_real("--noise", "-1", 0.0, SIM_CLI_INF, SIM_CLI_OPEN_HI, &v, err,
                       sizeof err);
    assert_string_equal(err, "--noise: '-1' is not a number >= 0");
    sim_cli_parse_real("--x", "3", -SIM_CLI_INF, 2.5, SIM_CLI_OPEN_LO, &v, err, sizeof err);
    assert_string_equal(err, "--x: '3' is not a number <= 2.5");
    sim_cli_parse_real("--x", "2.5", -SIM_CLI_INF, 2.5, SIM_CLI_OPEN, &v, err, sizeof err);
    assert_string_equal(err, "--x: '2.5' is not a number < 2.5");
    sim_cli_parse_real("k_w", "abc", -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_CLOSED, &v, err,
                       sizeof err);
    assert_string_equal(err, "k_w: 'abc' is not a finite number");
}

/* ---- triples --------------------------------------------------------------- */

static void triple_parsed(void **state)
{
    (void)state;
    char err[128] = "";
    double v[3] = { UNTOUCHED, UNTOUCHED, UNTOUCHED };
    assert_int_equal(sim_cli_parse_triple("--pose", "-3,-10,-30", -SIM_CLI_INF,
                                          SIM_CLI_INF, v, err, sizeof err), 0);
    assert_true(v[0] == -3.0 && v[1] == -10.0 && v[2] == -30.0);
    assert_int_equal(sim_cli_parse_triple("--normal", "0.3,-6e-1,-.75", -SIM_CLI_INF,
                                          SIM_CLI_INF, v, err, sizeof err), 0);
    assert_true(v[0] == 0.3 && v[1] == -0.6 && v[2] == -0.75);
    /* Spaces after the commas are skipped, as strtod does. */
    assert_int_equal(sim_cli_parse_triple("--pose", "1, 2, 3", -SIM_CLI_INF,
                                          SIM_CLI_INF, v, err, sizeof err), 0);
    assert_true(v[0] == 1.0 && v[1] == 2.0 && v[2] == 3.0);
    /* Within [-1, 1], ends included. */
    assert_int_equal(sim_cli_parse_triple("--dir", "-1,0,1", -1.0, 1.0, v, err,
                                          sizeof err), 0);
    assert_true(v[0] == -1.0 && v[1] == 0.0 && v[2] == 1.0);
}

static void triple_refused(void **state)
{
    (void)state;
    static const char *const bad[] = {
        "1,2",       /* two values            */
        "1,2,3,4",   /* four                  */
        "1,,3",      /* an empty one          */
        ",1,2",
        "1,2,",
        "",          /* empty                 */
        "a,b,c",     /* junk                  */
        "1,2,3x",
        "1;2;3",     /* wrong separator       */
        "1,2,inf",   /* not finite            */
        "nan,0,0",
        "1e999,0,0", /* overflow              */
        "0,1e-400,0",/* underflow             */
        "1,2,3 ",    /* trailing space        */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char err[128] = "";
        double v[3] = { UNTOUCHED, UNTOUCHED, UNTOUCHED };
        assert_int_equal(sim_cli_parse_triple("--pose", bad[i], -SIM_CLI_INF,
                                              SIM_CLI_INF, v, err, sizeof err), -1);
        assert_true(v[0] == UNTOUCHED && v[1] == UNTOUCHED && v[2] == UNTOUCHED);
    }
    char err[128];
    double v[3] = { UNTOUCHED, UNTOUCHED, UNTOUCHED };
    sim_cli_parse_triple("--pose", "1,2", -SIM_CLI_INF, SIM_CLI_INF, v, err, sizeof err);
    assert_string_equal(err, "--pose: '1,2' is not three finite numbers X,Y,Z");
    /* A value outside the range: the message gives the range. */
    assert_int_equal(sim_cli_parse_triple("--dir", "0,0,2", -1.0, 1.0, v, err,
                                          sizeof err), -1);
    assert_string_equal(err, "--dir: '0,0,2' is not three numbers in [-1, 1]");
    assert_true(v[2] == UNTOUCHED);
}

/* ---- messages -------------------------------------------------------------- */

static void message_bounded(void **state)
{
    (void)state;
    /* A huge argument is quoted up to 80 characters, and a small buffer
     * is never overrun: the sentinel after it survives. */
    char text[400];
    memset(text, '7', sizeof text - 1);
    text[sizeof text - 1] = '\0';
    char err[200];
    long long v;
    assert_int_equal(sim_cli_parse_int("--n", text, 0, 9, &v, err, sizeof err), -1);
    assert_int_equal(strlen(err), strlen("--n: '' is not an integer in 0..9") + 80);

    struct {
        char buf[16];
        uint32_t sentinel;
    } small = { "", 0xC0FFEE11u };
    double d = UNTOUCHED;
    assert_int_equal(sim_cli_parse_real("--noise", "-1", 0.0, SIM_CLI_INF,
                                        SIM_CLI_OPEN_HI, &d, small.buf,
                                        sizeof small.buf), -1);
    assert_int_equal(strlen(small.buf), sizeof small.buf - 1);
    assert_int_equal(small.sentinel, 0xC0FFEE11u);
    /* No buffer at all is allowed. */
    assert_int_equal(sim_cli_parse_int("--n", "x", 0, 9, &v, NULL, 0), -1);
}

/* Run sim_cli_int on `text` in a child and return its exit status; its
 * stderr goes to out (out_len bytes). */
static int refuse_in_child(const char *text, char *out, size_t out_len)
{
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(fds[1], 2);
        close(fds[0]);
        sim_cli_program("spvs-test");
        (void)sim_cli_int("--count", text, 0, 9);
        _exit(0); /* not reached for bad text */
    }
    close(fds[1]);
    size_t got = 0;
    ssize_t n;
    while (got + 1 < out_len && (n = read(fds[0], out + got, out_len - 1 - got)) > 0)
        got += (size_t)n;
    out[got] = '\0';
    close(fds[0]);
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static void refusal_exits_2_with_one_line(void **state)
{
    (void)state;
    char out[512];
    assert_int_equal(refuse_in_child("12", out, sizeof out), SIM_CLI_EXIT_USAGE);
    assert_int_equal(SIM_CLI_EXIT_USAGE, 2);
    assert_string_equal(out, "spvs-test: --count: '12' is not an integer in 0..9 "
                             "(see --help)\n");
    /* A newline inside the argument cannot split the line. */
    assert_int_equal(refuse_in_child("1\n2", out, sizeof out), 2);
    assert_string_equal(out, "spvs-test: --count: '1?2' is not an integer in 0..9 "
                             "(see --help)\n");
    /* A good value is no refusal. */
    assert_int_equal(refuse_in_child("9", out, sizeof out), 0);
    assert_string_equal(out, "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(int_in_range),
        cmocka_unit_test(int_refused),
        cmocka_unit_test(real_in_range),
        cmocka_unit_test(real_refused),
        cmocka_unit_test(real_messages),
        cmocka_unit_test(triple_parsed),
        cmocka_unit_test(triple_refused),
        cmocka_unit_test(message_bounded),
        cmocka_unit_test(refusal_exits_2_with_one_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
