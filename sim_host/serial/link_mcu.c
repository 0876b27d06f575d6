/*
 * link_mcu.c - QEMU + spvs-serial-agent behind the LCM link, and the serial
 * link's quantisation in process; see sim/link_mcu.h.
 */
#define _DEFAULT_SOURCE
#define _POSIX_C_SOURCE 200809L

#include "sim/link_mcu.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "sim/link_lcm.h"
#include "spvs_serial.h"

#ifndef SPVS_MCU_IMAGE_DEFAULT
#define SPVS_MCU_IMAGE_DEFAULT "spvs_app.elf"
#endif
#ifndef SPVS_SERIAL_AGENT_PATH
#define SPVS_SERIAL_AGENT_PATH "spvs-serial-agent"
#endif

/* How long the MCU may take to boot and take its set-up, seconds. */
#define READY_S 30.0

const char *sim_link_mcu_default_image(void)
{
    return SPVS_MCU_IMAGE_DEFAULT;
}

typedef struct {
    sim_link_t lcm;
    pid_t qemu, agent;
    char dir[64];
    char path[4][128]; /* uart socket, ready file, agent log, qemu log */
} link_mcu_t;

/* For the signal handler: the children of the one open MCU link. */
static volatile pid_t g_kids[2] = { 0, 0 };
static char g_files[4][128];
static char g_dir[64];

static void remove_files(void)
{
    for (int i = 0; i < 4; i++)
        if (g_files[i][0])
            unlink(g_files[i]);
    if (g_dir[0])
        rmdir(g_dir);
}

static void on_fatal_signal(int sig)
{
    for (int i = 0; i < 2; i++)
        if (g_kids[i] > 0)
            kill(g_kids[i], SIGKILL);
    remove_files();
    signal(sig, SIG_DFL);
    raise(sig);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static pid_t spawn(char *const argv[], const char *log_path)
{
    pid_t pid = fork();
    if (pid != 0)
        return pid;
    /* The child dies with the simulator, whatever kills it. */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    int fd = open(log_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    int nul = open("/dev/null", O_RDONLY);
    if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
    }
    if (nul >= 0)
        dup2(nul, 0);
    execvp(argv[0], argv);
    fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
    _exit(127);
}

static void stop_child(pid_t *pid)
{
    if (*pid <= 0)
        return;
    kill(*pid, SIGTERM);
    for (int k = 0; k < 100; k++) {
        if (waitpid(*pid, NULL, WNOHANG) == *pid) {
            *pid = 0;
            return;
        }
        usleep(20000);
    }
    kill(*pid, SIGKILL);
    waitpid(*pid, NULL, 0);
    *pid = 0;
}

/* Last line of a log, for an error message. */
static void last_line(const char *path, char *buf, size_t len)
{
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[256];
    while (fgets(line, sizeof(line), f))
        if (line[0] != '\n')
            snprintf(buf, len, "%.199s", line);
    fclose(f);
    size_t n = strlen(buf);
    if (n && buf[n - 1] == '\n')
        buf[n - 1] = '\0';
}

/* 0 while both run; else -1 with the reason in err. */
static int check_children(link_mcu_t *l, char *err, unsigned err_len)
{
    const char *names[2] = { "QEMU", "spvs-serial-agent" };
    pid_t *pids[2] = { &l->qemu, &l->agent };
    const char *logs[2] = { l->path[3], l->path[2] };
    for (int i = 0; i < 2; i++) {
        int ws;
        if (*pids[i] > 0 && waitpid(*pids[i], &ws, WNOHANG) == *pids[i]) {
            *pids[i] = 0;
            g_kids[i] = 0;
            char line[200];
            last_line(logs[i], line, sizeof(line));
            snprintf(err, err_len, "MCU link: %s exited (%s %d)%s%s", names[i],
                     WIFEXITED(ws) ? "status" : "signal",
                     WIFEXITED(ws) ? WEXITSTATUS(ws) : WTERMSIG(ws),
                     line[0] ? ": " : "", line);
            return -1;
        }
    }
    return 0;
}

static void mcu_close(void *ctx)
{
    link_mcu_t *l = (link_mcu_t *)ctx;
    if (!l)
        return;
    if (l->lcm.close)
        l->lcm.close(l->lcm.ctx);
    stop_child(&l->agent);
    stop_child(&l->qemu);
    g_kids[0] = g_kids[1] = 0;
    remove_files();
    memset(g_files, 0, sizeof(g_files));
    g_dir[0] = '\0';
    free(l);
}

static int mcu_exchange(void *ctx, uint32_t seq, double t_s,
                        const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                        char *err, unsigned err_len)
{
    link_mcu_t *l = (link_mcu_t *)ctx;
    if (check_children(l, err, err_len) != 0)
        return -1;
    int rc = l->lcm.exchange(l->lcm.ctx, seq, t_s, m, n, out, err, err_len);
    if (rc != 0) {
        /* Say why when one of the processes is gone. */
        char why[200];
        if (check_children(l, why, sizeof(why)) != 0)
            snprintf(err, err_len, "%s", why);
    }
    return rc;
}

/* The board an image was built for: the cross build writes it beside its
 * images (target/qemu_machine: mps2-an386 for the Cortex-M4F, mps2-an385
 * for the Cortex-M3); an image elsewhere is taken for the Cortex-M4F's. */
static void image_machine(const char *image, char *machine, size_t len)
{
    snprintf(machine, len, "mps2-an386");
    char path[4200];
    const char *slash = strrchr(image, '/');
    int dir_len = slash ? (int)(slash - image) : 1;
    snprintf(path, sizeof(path), "%.*s/qemu_machine", dir_len, slash ? image : ".");
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[32];
    if (fgets(line, sizeof(line), f)) {
        line[strcspn(line, " \r\n")] = 0;
        /* Only the boards the images are made for. */
        if (strcmp(line, "mps2-an385") == 0 || strcmp(line, "mps2-an386") == 0)
            snprintf(machine, len, "%s", line);
    }
    fclose(f);
}

int sim_link_mcu_open(const sim_link_mcu_opts_t *o, sim_link_t *out,
                      char *err, unsigned err_len)
{
    const char *image = o->image ? o->image : SPVS_MCU_IMAGE_DEFAULT;
    if (access(image, R_OK) != 0) {
        snprintf(err, err_len, "MCU link: no application image '%s' (build "
                 "it: see docs/SERIAL.md, or give --mcu-image)", image);
        return -1;
    }
    if (g_kids[0] || g_kids[1]) {
        snprintf(err, err_len, "MCU link: one is open already");
        return -1;
    }
    link_mcu_t *l = (link_mcu_t *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_len, "MCU link: out of memory");
        return -1;
    }
    snprintf(l->dir, sizeof(l->dir), "/tmp/spvs-mcu-XXXXXX");
    if (!mkdtemp(l->dir)) {
        snprintf(err, err_len, "MCU link: no temporary folder: %s",
                 strerror(errno));
        free(l);
        return -1;
    }
    const char *names[4] = { "uart.sock", "ready", "agent.log", "qemu.log" };
    for (int i = 0; i < 4; i++) {
        snprintf(l->path[i], sizeof(l->path[i]), "%s/%s", l->dir, names[i]);
        snprintf(g_files[i], sizeof(g_files[i]), "%s", l->path[i]);
    }
    snprintf(g_dir, sizeof(g_dir), "%s", l->dir);

    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_fatal_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);

    const char *qemu = getenv("SPVS_QEMU_ARM");
    const char *agent = getenv("SPVS_SERIAL_AGENT");
    char serial_arg[200], device_arg[200], method[8], seed[16], alpha[32];
    snprintf(serial_arg, sizeof(serial_arg), "unix:%s,server=on,wait=on", l->path[0]);
    snprintf(device_arg, sizeof(device_arg), "unix:%s", l->path[0]);
    snprintf(method, sizeof(method), "%d", o->method);
    snprintf(seed, sizeof(seed), "%u", (unsigned)o->seed);
    snprintf(alpha, sizeof(alpha), "%.9g", o->alpha_px);
    /* -icount: the MCU's clock (and so its watchdog) counts executed
     * instructions, 8 ns each, not the host's wall clock. */
    char machine[32];
    image_machine(image, machine, sizeof(machine));
    char *qargv[] = { (char *)(qemu ? qemu : "qemu-system-arm"), "-M", machine,
                      "-nographic", "-monitor", "none",
                      "-semihosting-config", "enable=on,target=native",
                      "-icount", "shift=3,align=off,sleep=off",
                      "-serial", serial_arg, "-kernel", (char *)image, NULL };
    char *aargv[] = { (char *)(agent ? agent : SPVS_SERIAL_AGENT_PATH),
                      "--device", device_arg, "--lcm-url", (char *)o->lcm_url,
                      "--method", method, "--seed", seed, "--alpha", alpha,
                      "--ready-file", l->path[1], "--log-level", "2", NULL };
    l->qemu = spawn(qargv, l->path[3]);
    g_kids[0] = l->qemu;
    l->agent = l->qemu > 0 ? spawn(aargv, l->path[2]) : -1;
    g_kids[1] = l->agent;
    if (l->qemu < 0 || l->agent < 0) {
        snprintf(err, err_len, "MCU link: fork failed: %s", strerror(errno));
        mcu_close(l);
        return -1;
    }
    /* Wait for the agent to see the MCU running with the set-up. */
    double t0 = now_s();
    while (access(l->path[1], F_OK) != 0) {
        if (check_children(l, err, err_len) != 0) {
            mcu_close(l);
            return -1;
        }
        if (now_s() - t0 > READY_S) {
            snprintf(err, err_len, "MCU link: the MCU did not report ready "
                     "within %.0f s (logs in %s)", READY_S, l->dir);
            mcu_close(l);
            return -1;
        }
        usleep(20000);
    }
    if (!o->quiet)
        fprintf(stderr, "spvs-sim: MCU ready after %.2f s (QEMU pid %d, agent "
                "pid %d)\n", now_s() - t0, (int)l->qemu, (int)l->agent);
    if (sim_link_lcm_open(o->lcm_url, o->timeout_s, &l->lcm, err, err_len) != 0) {
        mcu_close(l);
        return -1;
    }
    out->ctx = l;
    out->exchange = mcu_exchange;
    out->close = mcu_close;
    return 0;
}

/* ---- quantisation in process -------------------------------------------------- */

typedef struct {
    sim_link_t inner;
    uint8_t last_step;
    spvs_match_t q[SPVS_MAX_MATCHES];
} link_quant_t;

static int quant_exchange(void *ctx, uint32_t seq, double t_s,
                          const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                          char *err, unsigned err_len)
{
    link_quant_t *l = (link_quant_t *)ctx;
    uint32_t t_ms = 0;
    int ok = n <= SPVS_MAX_MATCHES && isfinite(t_s) && t_s >= 0.0 && t_s < 9.0e12 &&
             spvs_serial_ms_from_utime((int64_t)llround(t_s * 1e6), &t_ms) == SPVS_SERIAL_OK;
    for (uint16_t i = 0; ok && i < n; i++)
        ok = spvs_serial_quantize_match(&m[i], &l->q[i]) == SPVS_SERIAL_OK;
    if (!ok) {
        /* What spvs-serial-agent answers for a frame the wire cannot carry. */
        memset(out, 0, sizeof(*out));
        out->status = SPVS_E_RANGE;
        out->step = l->last_step;
        out->n_matches = n;
        return 0;
    }
    int rc = l->inner.exchange(l->inner.ctx, seq, (double)spvs_serial_s_from_ms(t_ms),
                               l->q, n, out, err, err_len);
    if (rc == 0)
        l->last_step = out->step;
    return rc;
}

static void quant_close(void *ctx)
{
    link_quant_t *l = (link_quant_t *)ctx;
    if (l->inner.close)
        l->inner.close(l->inner.ctx);
    free(l);
}

int sim_link_quantize_wrap(sim_link_t *link, char *err, unsigned err_len)
{
    link_quant_t *l = (link_quant_t *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_len, "out of memory");
        return -1;
    }
    l->inner = *link;
    link->ctx = l;
    link->exchange = quant_exchange;
    link->close = quant_close;
    return 0;
}
