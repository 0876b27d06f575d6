/*
 * spvs-sim - closed-loop simulation of Shortest Path Control: a simulated
 * robot and camera drive a controller, in process or across a transport.
 * Command line contract: DESIGN.md section 5; usage: docs/SIM.md.
 *
 * Exit status: 0 when the run took place (whatever its outcome), 1 when the
 * link to the controller failed or an output file could not be written,
 * 2 on bad options.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/cli.h"
#include "sim/link_fixed.h"
#include "sim/link_inproc.h"
#include "sim/record.h"
#include "sim/sim.h"

#ifdef SPVS_HAVE_LCM
#include "sim/link_lcm.h"
#endif
#ifdef SPVS_HAVE_ZENOH
#include "sim/link_zenoh.h"
#endif
#ifdef SPVS_HAVE_DDS
#include "sim/link_dds.h"
#endif
#ifdef SPVS_HAVE_ROSBAG
#include "sim/rosbag.h"
#endif
#ifdef SPVS_HAVE_FRONTEND
#include "sim/frontend.h"
#endif
#ifdef SPVS_HAVE_MCU
#include "sim/link_mcu.h"
#endif

#define PI 3.14159265358979323846
#define EXIT_LINK 1
#define EXIT_USAGE SIM_CLI_EXIT_USAGE

typedef struct {
    sim_config_t cfg;
    int json;
    int quiet;
    const char *trace_path;
    const char *record_path;
    const char *rosbag_dir;     /* --rosbag (NULL: none)                  */
    const char *transport;
    const char *lcm_url;
    const char *zenoh_endpoint;
    double timeout_s;
    const char *lcm_matches_channel;
    double keep_last_s;
    uint32_t seed32;
    int images;                 /* --frontend images                      */
    int focal_given;            /* --focal-mm was given                   */
    const char *save_frames_dir;
    const char *texture;        /* --texture: the plane's photograph      */
    uint32_t save_every;        /* frames between saved PNGs              */
    long save_matches_frame;    /* -1: none                               */
    const char *mcu_image;      /* --mcu-image (NULL: the build's)        */
    int quantize_serial;        /* --quantize-serial                      */
} options_t;

/* Seeds and frame counts: 32 bits. */
#define U32_MAX_LL 4294967295LL

/* ---- options: one table for the parser and --help -------------------- */

/* Sets an option from its value (NULL for a flag), or fails with exit
 * status 2 (sim_cli_fail). */
typedef void (*opt_set_fn)(options_t *o, const char *name, const char *val);

typedef struct {
    const char *name;    /* "--method"                                      */
    const char *metavar; /* the value in --help; NULL: a flag               */
    const char *help;    /* a '\n' starts a line under the first            */
    opt_set_fn set;
} sim_opt_t;

static void set_method(options_t *o, const char *name, const char *val)
{
    o->cfg.method = (int)sim_cli_int(name, val, 1, 3);
}

static void set_pose(options_t *o, const char *name, const char *val)
{
    double v[3];
    sim_cli_triple(name, val, -SIM_CLI_INF, SIM_CLI_INF, v);
    o->cfg.start.x_m = v[0];
    o->cfg.start.z_m = v[1];
    o->cfg.start.phi_rad = v[2] * PI / 180.0;
}

static void set_normal(options_t *o, const char *name, const char *val)
{
    double *n = o->cfg.normal;
    sim_cli_triple(name, val, -SIM_CLI_INF, SIM_CLI_INF, n);
    if (hypot(hypot(n[0], n[1]), n[2]) < 1e-9) {
        sim_cli_fail("--normal: '%s' is a zero vector", val);
    }
}

static void set_distance(options_t *o, const char *name, const char *val)
{
    o->cfg.distance_m = sim_cli_real(name, val, 0.0, SIM_CLI_INF, SIM_CLI_OPEN);
}

static void set_noise(options_t *o, const char *name, const char *val)
{
    o->cfg.noise_px = sim_cli_real(name, val, 0.0, SIM_CLI_INF, SIM_CLI_OPEN_HI);
}

static void set_outliers(options_t *o, const char *name, const char *val)
{
    o->cfg.outliers = sim_cli_real(name, val, 0.0, 1.0, SIM_CLI_OPEN_HI);
}

static void set_drift(options_t *o, const char *name, const char *val)
{
    o->cfg.drift_deg_per_m = sim_cli_real(name, val, -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN);
}

static void set_focal(options_t *o, const char *name, const char *val)
{
    o->cfg.focal_true_mm = sim_cli_real(name, val, 0.0, SIM_CLI_INF, SIM_CLI_OPEN);
    o->focal_given = 1;
}

static void set_pp_offset(options_t *o, const char *name, const char *val)
{
    o->cfg.pp_offset_px = sim_cli_real(name, val, -SIM_CLI_INF, SIM_CLI_INF, SIM_CLI_OPEN);
}

static void set_seed(options_t *o, const char *name, const char *val)
{
    o->seed32 = (uint32_t)sim_cli_int(name, val, 0, U32_MAX_LL);
    o->cfg.seed = o->seed32;
}

static void set_dt(options_t *o, const char *name, const char *val)
{
    o->cfg.dt_s = sim_cli_real(name, val, 0.0, 10.0, SIM_CLI_OPEN_LO);
}

static void set_latency(options_t *o, const char *name, const char *val)
{
    o->cfg.robot.latency_s = sim_cli_real(name, val, 0.0, 60.0, SIM_CLI_OPEN_HI);
}

/* --accel-limit A,ALPHA: two numbers > 0 into the robot's limits. */
static void set_accel_limit(options_t *o, const char *name, const char *val)
{
    char a[64];
    const char *comma = strchr(val, ',');
    if (comma == NULL || (size_t)(comma - val) >= sizeof(a) || strchr(comma + 1, ',') != NULL) {
        sim_cli_fail("%s: '%.80s' is not A,ALPHA (m/s^2, rad/s^2)", name, val);
    }
    memcpy(a, val, (size_t)(comma - val));
    a[comma - val] = '\0';
    o->cfg.robot.accel_mps2 = sim_cli_real(name, a, 0.0, SIM_CLI_INF, SIM_CLI_OPEN);
    o->cfg.robot.alpha_radps2 = sim_cli_real(name, comma + 1, 0.0, SIM_CLI_INF, SIM_CLI_OPEN);
}

static void set_max_time(options_t *o, const char *name, const char *val)
{
    o->cfg.max_time_s = sim_cli_real(name, val, 0.0, SIM_CLI_INF, SIM_CLI_OPEN);
}

static void set_clip(options_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
    o->cfg.clip = 1;
}

static void set_trace(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->trace_path = val;
}

static void set_record(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->record_path = val;
}

static void set_rosbag(options_t *o, const char *name, const char *val)
{
    (void)name;
#ifndef SPVS_HAVE_ROSBAG
    sim_cli_fail("--rosbag: this build has no rosbag2 writer");
#endif
    o->rosbag_dir = val;
}

static void set_transport(options_t *o, const char *name, const char *val)
{
    static const char *const known[] = {"inproc", "fixed", "lcm", "zenoh", "dds", "mcu"};
    for (size_t k = 0; k < sizeof(known) / sizeof(known[0]); ++k) {
        if (strcmp(val, known[k]) == 0) {
            o->transport = known[k];
            return;
        }
    }
    sim_cli_fail("%s: '%s' is not inproc, fixed, lcm, zenoh, dds or mcu", name, val);
}

static void set_mcu_image(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->mcu_image = val;
}

static void set_quantize_serial(options_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
    o->quantize_serial = 1;
}

static void set_lcm_url(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->lcm_url = val;
}

static void set_zenoh_endpoint(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->zenoh_endpoint = val;
}

static void set_timeout(options_t *o, const char *name, const char *val)
{
    o->timeout_s = sim_cli_real(name, val, 0.0, 3600.0, SIM_CLI_OPEN_LO);
}

static void set_matches_channel(options_t *o, const char *name, const char *val)
{
    if (val[0] == '\0' || strlen(val) > 63) {
        sim_cli_fail("%s: '%s' is not 1..63 characters", name, val);
    }
    o->lcm_matches_channel = val;
}

static void set_keep_last(options_t *o, const char *name, const char *val)
{
    o->keep_last_s = sim_cli_real(name, val, 0.0, 3600.0, SIM_CLI_OPEN_LO);
}

static void set_realtime(options_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
    o->cfg.realtime = 1;
}

static void set_frontend(options_t *o, const char *name, const char *val)
{
    if (strcmp(val, "points") == 0) {
        o->images = 0;
    } else if (strcmp(val, "images") == 0) {
#ifdef SPVS_HAVE_FRONTEND
        o->images = 1;
#else
        sim_cli_fail("%s images: this build has no image front end (OpenCV)", name);
#endif
    } else {
        sim_cli_fail("%s: '%s' is not points or images", name, val);
    }
}

static void set_texture(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->texture = val;
}

static void set_save_frames(options_t *o, const char *name, const char *val)
{
    (void)name;
    o->save_frames_dir = val;
}

static void set_save_every(options_t *o, const char *name, const char *val)
{
    o->save_every = (uint32_t)sim_cli_int(name, val, 1, U32_MAX_LL);
}

static void set_save_matches(options_t *o, const char *name, const char *val)
{
    o->save_matches_frame = (long)sim_cli_int(name, val, 0, U32_MAX_LL);
}

static void set_json(options_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
    o->json = 1;
}

static void set_quiet(options_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
    o->quiet = 1;
}

static void show_help(options_t *o, const char *name, const char *val);

/* Every option, in the order --help lists them, with its default in the
 * help text. */
static const sim_opt_t k_opts[] = {
    {"--method", "1|2|3", "control method (3)", set_method},
    {"--pose", "X,Z,PHI_DEG", "start pose, metres and degrees (-3,-10,-30)", set_pose},
    {"--normal", "NX,NY,NZ", "plane normal, normalised here (0.3,-0.6,-0.75)", set_normal},
    {"--distance", "D_M", "plane distance d > 0, metres (45)", set_distance},
    {"--noise", "SIGMA_PX", "Gaussian image noise, pixels (0)", set_noise},
    {"--outliers", "FRACTION", "mismatched fraction of each frame, [0,1) (0)", set_outliers},
    {"--drift", "DEG_PER_M", "odometry drift in rotation, deg per metre (0)", set_drift},
    {"--focal-mm", "F",
     "TRUE focal length, mm; the controller assumes 6,\n"
     "or 3 with --frontend images (6; images: 3)",
     set_focal},
    {"--pp-offset", "PX", "TRUE principal point x offset, pixels (0)", set_pp_offset},
    {"--seed", "S", "seed of scene, noise and RANSAC, 0..4294967295 (0)", set_seed},
    {"--dt", "S", "control period, seconds (0.1)", set_dt},
    {"--latency", "S", "each command acts S s after its frame was taken (0)", set_latency},
    {"--accel-limit", "A,ALPHA",
     "the robot's v and w follow the command within A m/s^2\n"
     "and ALPHA rad/s^2 (none)",
     set_accel_limit},
    {"--max-time", "S", "stop with status timeout after this, seconds (300)", set_max_time},
    {"--clip", NULL, "match only points inside the 640x480 frame", set_clip},
    {"--trace", "FILE.csv", "write one CSV row per frame", set_trace},
    {"--record", "FILE", "write a binary recording (docs/RECORDING.md)", set_record},
    {"--rosbag", "DIR",
     "write a rosbag2 (MCAP) of the run into the new\n"
     "folder DIR: /spvs/matches, /cmd_vel, /spvs/state",
     set_rosbag},
    {"--transport", "T",
     "inproc (default), lcm, zenoh, dds (ROS 2 names,\n"
     "$ROS_DOMAIN_ID, docs/ROS2.md) or mcu (QEMU,\n"
     "docs/SERIAL.md)",
     set_transport},
    {"--mcu-image", "FILE", "mcu: the application image (the build's)", set_mcu_image},
    {"--quantize-serial", NULL,
     "round frames as the serial link does (1/16 px,\n"
     "ms) before any transport",
     set_quantize_serial},
    {"--lcm-url", "URL", "LCM provider (udpm://239.255.76.67:7667?ttl=0)", set_lcm_url},
    {"--zenoh-endpoint", "E", "Zenoh endpoint (tcp/127.0.0.1:7447)", set_zenoh_endpoint},
    {"--timeout", "S", "transport wait for each command, seconds (2)", set_timeout},
    {"--lcm-matches-channel", "CH", "LCM channel the frames go out on (SPVS_MATCHES)",
     set_matches_channel},
    {"--keep-last", "S",
     "LCM: a frame unanswered within --timeout is no\n"
     "error: drive on the newest command received, for\n"
     "at most S s of frame time, then stop (off)",
     set_keep_last},
    {"--realtime", NULL, "pace frames at dt in wall-clock time", set_realtime},
    {"--frontend", "F",
     "points (default): exact projected points;\n"
     "images: SIFT matches in rendered images",
     set_frontend},
    {"--texture", "FILE",
     "images: a photograph on the plane instead of\n"
     "the procedural texture",
     set_texture},
    {"--save-frames", "DIR",
     "images: write every Nth frame as DIR/frame_NNNNN.png\n"
     "and the target image as DIR/target.png",
     set_save_frames},
    {"--save-every", "N", "images: N for --save-frames (10)", set_save_every},
    {"--save-matches", "FRAME", "images: write DIR/matches_FRAME.png (or ./)", set_save_matches},
    {"--json", NULL, "last stdout line: one JSON object with the result", set_json},
    {"--quiet", NULL, "no human-readable report", set_quiet},
    {"--help", NULL, "this text", show_help},
};
#define N_OPTS (sizeof(k_opts) / sizeof(k_opts[0]))

/* The option column's width in --help (sim_cli_help_option). */
#define HELP_COL 22

static void show_help(options_t *o, const char *name, const char *val)
{
    (void)o;
    (void)name;
    (void)val;
    fputs("usage: spvs-sim [options]\n"
          "Closed-loop simulation of Shortest Path Control (Methods I, II, III).\n"
          "\n",
          stdout);
    for (size_t k = 0; k < N_OPTS; ++k) {
        sim_cli_help_option(stdout, HELP_COL, k_opts[k].name, k_opts[k].metavar, k_opts[k].help);
    }
    fputs("\n"
          "Exit status: 0 run completed (any outcome), 1 link or output error,\n"
          "2 bad options.\n",
          stdout);
    exit(0);
}

static const sim_opt_t *find_opt(const char *name)
{
    for (size_t k = 0; k < N_OPTS; ++k) {
        if (strcmp(k_opts[k].name, name) == 0) {
            return &k_opts[k];
        }
    }
    return NULL;
}

/* The settings that are not an option's alone: the front end's camera,
 * and the checks of combinations and ranges. */
static void finish_options(options_t *o)
{
    if (!o->images && (o->save_frames_dir || o->save_matches_frame >= 0 || o->texture)) {
        sim_cli_fail("--save-frames, --save-matches and --texture need "
                     "--frontend images");
    }
#ifdef SPVS_HAVE_FRONTEND
    /* Images are taken with the front end's wide camera, and the
     * controller is told its focal length (--focal-mm still sets the true
     * one, for calibration errors). */
    if (o->images) {
        o->cfg.focal_assumed_mm = SIM_FRONTEND_FOCAL_MM;
        o->cfg.arrival_sigma_px = SIM_FRONTEND_ARRIVAL_SIGMA_PX;
        if (!o->focal_given) {
            o->cfg.focal_true_mm = SIM_FRONTEND_FOCAL_MM;
        }
    }
#endif
    char err[160];
    if (sim_config_check(&o->cfg, err, sizeof(err)) != 0) {
        sim_cli_fail("%s", err);
    }
}

static void parse_options(int argc, char **argv, options_t *o)
{
    sim_cli_program("spvs-sim");
    memset(o, 0, sizeof(*o));
    sim_config_default(&o->cfg);
    o->transport = "inproc";
    o->lcm_url = "udpm://239.255.76.67:7667?ttl=0";
    o->zenoh_endpoint = "tcp/127.0.0.1:7447";
    o->timeout_s = 2.0;
    o->save_every = 10;
    o->save_matches_frame = -1;

    for (int i = 1; i < argc; ++i) {
        const char *arg = argv[i];
        if (strncmp(arg, "--", 2) != 0) {
            sim_cli_fail("unexpected argument '%s'", arg);
        }
        /* Accept both "--opt value" and "--opt=value". */
        char name[32];
        const char *val = NULL;
        const char *eq = strchr(arg, '=');
        size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
        if (len >= sizeof(name)) {
            sim_cli_fail("unknown option '%.40s'", arg);
        }
        memcpy(name, arg, len);
        name[len] = '\0';
        if (eq) {
            val = eq + 1;
        }
        const sim_opt_t *opt = find_opt(name);
        if (opt == NULL) {
            sim_cli_fail("unknown option '%s'", name);
        }
        if (opt->metavar == NULL && val) {
            sim_cli_fail("%s takes no value", name);
        }
        if (opt->metavar != NULL && !val) {
            if (i + 1 >= argc) {
                sim_cli_fail("%s needs a value", name);
            }
            val = argv[++i];
        }
        opt->set(o, name, val);
    }
    finish_options(o);
}

/* ---- outputs ------------------------------------------------------------ */

typedef struct {
    FILE *trace;
    FILE *record;
    struct sim_rosbag *rosbag;
    char err[160];
    /* The last answered frame's arrival check figures, for --json. */
    spvs_output_t last;
    int has_last;
} sinks_t;

static int on_frame(const sim_frame_t *f, void *user)
{
    sinks_t *s = user;
    const spvs_output_t *o = f->out;
    s->last = *o;
    s->has_last = 1;
    if (s->trace) {
        const spvs_real *H = o->H;
        int bad = fprintf(s->trace,
                          "%.3f,%.6f,%.6f,%.5f,%.6g,%.6g,%d,%d,"
                          "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%u,%u\n",
                          f->t_s, f->pose.x_m, f->pose.z_m,
                          f->pose.phi_rad * 180.0 / PI, (double)o->v,
                          (double)o->w, (int)o->step, (int)o->status,
                          (double)H[0], (double)H[1], (double)H[2],
                          (double)H[6], (double)H[7], (double)H[8],
                          (double)o->e_x_px, (double)o->parallax_px,
                          (unsigned)o->n_inliers, (unsigned)f->n) < 0;
        if (bad) {
            snprintf(s->err, sizeof(s->err), "cannot write the trace file");
            return -1;
        }
    }
#ifdef SPVS_HAVE_ROSBAG
    if (s->rosbag && sim_rosbag_frame(s->rosbag, f->seq, f->t_s, f->m, f->n,
                                      o, s->err, sizeof(s->err)) != 0) {
        return -1;
    }
#endif
    if (s->record) {
        if (sim_record_write_frame(s->record, f->seq, f->t_s, f->m, f->n,
                                   (double)o->v, (double)o->w, o->status,
                                   o->step) != 0) {
            snprintf(s->err, sizeof(s->err), "cannot write the recording");
            return -1;
        }
    }
    return 0;
}

/* A JSON string with the characters JSON requires escaped. */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        if (*p == '"' || *p == '\\') {
            fprintf(f, "\\%c", *p);
        } else if (*p < 0x20) {
            fprintf(f, "\\u%04x", *p);
        } else {
            fputc(*p, f);
        }
    }
    fputc('"', f);
}

/* The arrival check after step 3 (docs/CONTROL.md): the figures of the last
 * check, its statistic and threshold (standard deviations), each
 * direction's mean residual and its standard deviation (pixels), the mean
 * corner transfer and the mean parallax of the remembered off-plane points
 * (pixels, -1: none seen); docs/SIM.md lists the keys. */
static void print_json_arrival(const sinks_t *s)
{
    const spvs_output_t *a = &s->last;
    if (!s->has_last) {
        fputs(",\"arrival\":null", stdout);
        return;
    }
    printf(",\"arrival\":{\"statistic\":%.6g,\"threshold\":%.6g,"
           "\"lateral_px\":%.6g,\"lateral_sd_px\":%.6g,\"depth_px\":%.6g,"
           "\"depth_sd_px\":%.6g,\"h13_px\":%.6g,\"h13_sd_px\":%.6g,"
           "\"corner_px\":%.6g,\"parallax_px\":%.6g,\"frames\":%u,\"reentries\":%u,"
           "\"next_step\":%u}",
           (double)a->arrival_stat, (double)a->arrival_threshold,
           (double)a->arrival_lateral_px, (double)a->arrival_lateral_sd_px,
           (double)a->arrival_depth_px, (double)a->arrival_depth_sd_px,
           (double)a->arrival_h13_px, (double)a->arrival_h13_sd_px,
           (double)a->arrival_corner_px, (double)a->arrival_parallax_px,
           (unsigned)a->arrival_frames, (unsigned)a->arrival_reentries,
           (unsigned)a->arrival_next);
}

static void print_json(const options_t *o, const sim_result_t *r, const sinks_t *s)
{
    const sim_config_t *c = &o->cfg;
    printf("{\"method\":%d,\"status\":\"%s\",\"reason\":", c->method,
           sim_status_str(r->status));
    if (r->reason[0]) {
        json_string(stdout, r->reason);
    } else {
        fputs("null", stdout);
    }
    printf(",\"final_error\":{\"x_m\":%.9g,\"z_m\":%.9g,\"phi_deg\":%.9g}",
           r->err_x_m, r->err_z_m, r->err_phi_deg);
    printf(",\"time_s\":%.9g,\"frames\":%u,\"steps\":[", r->time_s,
           (unsigned)r->frames);
    int first = 1;
    for (int k = 1; k <= 3; ++k) {
        if (!r->started[k]) {
            continue;
        }
        printf("%s{\"step\":%d,\"start_s\":%.9g,\"end_s\":", first ? "" : ",",
               k, r->step_start_s[k]);
        if (r->step_end_s[k] >= 0.0) {
            printf("%.9g}", r->step_end_s[k]);
        } else {
            fputs("null}", stdout);
        }
        first = 0;
    }
    printf("],\"seed\":%u,\"start\":{\"x_m\":%.9g,\"z_m\":%.9g,\"phi_deg\":%.9g}",
           (unsigned)o->seed32, c->start.x_m, c->start.z_m,
           c->start.phi_rad * 180.0 / PI);
    printf(",\"latency_s\":%.9g,\"accel_limit\":", c->robot.latency_s);
    if (c->robot.accel_mps2 > 0.0) {
        printf("{\"accel_mps2\":%.9g,\"alpha_radps2\":%.9g}", c->robot.accel_mps2,
               c->robot.alpha_radps2);
    } else {
        fputs("null", stdout);
    }
    printf(",\"noise_px\":%.9g,\"outliers\":%.9g,\"drift_deg_per_m\":%.9g"
           ",\"focal_mm\":%.9g,\"pp_offset_px\":%.9g,\"dt_s\":%.9g"
           ",\"path_m\":%.9g,\"frontend\":\"%s\",\"transport\":",
           c->noise_px, c->outliers, c->drift_deg_per_m, c->focal_true_mm,
           c->pp_offset_px, c->dt_s, r->path_m,
           o->images ? "images" : "points");
    json_string(stdout, o->transport);
    print_json_arrival(s);
    fputs("}\n", stdout);
}

static void print_settings(const options_t *o)
{
    const sim_config_t *c = &o->cfg;
    printf("spvs-sim: method %d, start (%.3f m, %.3f m, %.2f deg), "
           "plane n=(%.3f,%.3f,%.3f) d=%.3g m, noise %.3g px, outliers %.3g, "
           "drift %.3g deg/m, focal %.3g mm (assumed %.3g), pp offset %.3g px, "
           "seed %u, dt %.3g s, transport %s\n",
           c->method, c->start.x_m, c->start.z_m, c->start.phi_rad * 180.0 / PI,
           c->normal[0], c->normal[1], c->normal[2], c->distance_m, c->noise_px,
           c->outliers, c->drift_deg_per_m, c->focal_true_mm,
           c->focal_assumed_mm, c->pp_offset_px, (unsigned)o->seed32, c->dt_s,
           o->transport);
}

static void print_report(const sim_result_t *r)
{
    for (int k = 1; k <= 3; ++k) {
        if (!r->started[k]) {
            printf("step %d: not reached\n", k);
        } else if (r->step_end_s[k] >= 0.0) {
            printf("step %d: %8.2f s -> %8.2f s\n", k, r->step_start_s[k],
                   r->step_end_s[k]);
        } else {
            printf("step %d: %8.2f s -> (not ended)\n", k, r->step_start_s[k]);
        }
    }
    printf("final error: x %+.4f m, z %+.4f m, phi %+.3f deg\n", r->err_x_m,
           r->err_z_m, r->err_phi_deg);
    printf("status: %s%s%s after %.2f s (%u frames, %.2f m driven)\n",
           sim_status_str(r->status), r->reason[0] ? ": " : "", r->reason,
           r->time_s, (unsigned)r->frames, r->path_m);
}

/* ---- image front end ------------------------------------------------------ */

#ifdef SPVS_HAVE_FRONTEND
typedef struct {
    sim_frontend_t *fe;
    const options_t *o;
    char err[200];
    int failed;
} images_t;

/* sim_config_t.observe: match the rendered frame, then save the pictures
 * asked for.  A picture that cannot be written makes the exit status 1. */
static uint16_t observe_images(void *user, uint32_t seq, const sim_world_t *w,
                               const sim_pose_t *pose, sim_obs_t *obs,
                               uint16_t cap)
{
    images_t *im = user;
    uint16_t n = sim_frontend_observe_cb(im->fe, seq, w, pose, obs, cap);
    const options_t *o = im->o;
    char path[1200];
    const char *dir = o->save_frames_dir ? o->save_frames_dir : ".";
    if (o->save_frames_dir && seq % o->save_every == 0) {
        snprintf(path, sizeof(path), "%s/frame_%05u.png", dir, (unsigned)seq);
        if (sim_frontend_save_frame(im->fe, path, im->err,
                                    (unsigned)sizeof(im->err)) != 0) {
            im->failed = 1;
        }
    }
    if (o->save_matches_frame >= 0 && (long)seq == o->save_matches_frame) {
        snprintf(path, sizeof(path), "%s/matches_%05u.png", dir,
                 (unsigned)seq);
        if (sim_frontend_save_matches(im->fe, path, im->err,
                                      (unsigned)sizeof(im->err)) != 0) {
            im->failed = 1;
        }
    }
    return n;
}
#endif

/* ---- transports ---------------------------------------------------------- */

static int open_link(const options_t *o, sim_link_t *link, char *err,
                     unsigned err_len);

/* The transport, then the serial link's rounding around it when asked. */
static int open_link_q(const options_t *o, sim_link_t *link, char *err,
                       unsigned err_len)
{
    if (open_link(o, link, err, err_len) != 0) {
        return -1;
    }
#ifdef SPVS_HAVE_MCU
    if (o->quantize_serial && sim_link_quantize_wrap(link, err, err_len) != 0) {
        link->close(link->ctx);
        return -1;
    }
#else
    if (o->quantize_serial) {
        sim_cli_fail("--quantize-serial: this build has no serial link");
    }
#endif
    return 0;
}

static int open_link(const options_t *o, sim_link_t *link, char *err,
                     unsigned err_len)
{
    if (strcmp(o->transport, "mcu") == 0) {
#ifdef SPVS_HAVE_MCU
        sim_link_mcu_opts_t mo = { o->mcu_image, o->lcm_url, o->timeout_s,
                                   o->cfg.method, o->seed32,
                                   o->cfg.focal_assumed_mm / o->cfg.pixel_mm,
                                   o->quiet };
        return sim_link_mcu_open(&mo, link, err, err_len);
#else
        sim_cli_fail("--transport mcu: this build has no MCU link");
#endif
    }
    if (strcmp(o->transport, "inproc") == 0 || strcmp(o->transport, "fixed") == 0) {
        spvs_params_t p;
        sim_inproc_params(&p, o->cfg.method,
                          o->cfg.focal_assumed_mm / o->cfg.pixel_mm, o->seed32);
        if (o->cfg.arrival_sigma_px > 0.0) {
            p.ctl.arrival_sigma_px = (spvs_real)o->cfg.arrival_sigma_px;
        }
        if (strcmp(o->transport, "fixed") == 0) {
            return sim_link_fixed_open(&p, link, err, err_len);
        }
        return sim_link_inproc_open(&p, link, err, err_len);
    }
    if (strcmp(o->transport, "lcm") == 0) {
#ifdef SPVS_HAVE_LCM
        sim_link_lcm_opts_t lo = { o->lcm_matches_channel,
                                   o->keep_last_s > 0.0, o->keep_last_s };
        return sim_link_lcm_open_opts(o->lcm_url, o->timeout_s, &lo, link,
                                      err, err_len);
#else
        sim_cli_fail("--transport lcm: this build has no LCM support");
#endif
    }
    if (strcmp(o->transport, "dds") == 0) {
#ifdef SPVS_HAVE_DDS
        return sim_link_dds_open(o->timeout_s, link, err, err_len);
#else
        sim_cli_fail("--transport dds: this build has no DDS support");
#endif
    }
#ifdef SPVS_HAVE_ZENOH
    return sim_link_zenoh_open(o->zenoh_endpoint, o->timeout_s, link, err,
                               err_len);
#else
    sim_cli_fail("--transport zenoh: this build has no Zenoh support");
#endif
    return -1;
}

/* Opens --trace, --record and --rosbag as sinks s asks; fails with exit
 * status 2 (a file that cannot be opened) or returns EXIT_LINK (a header
 * that cannot be written), else 0. */
static int open_sinks(const options_t *o, sinks_t *s)
{
    memset(s, 0, sizeof(*s));
    if (o->trace_path) {
        s->trace = fopen(o->trace_path, "w");
        if (!s->trace) {
            sim_cli_fail("--trace: cannot open '%s': %s", o->trace_path, strerror(errno));
        }
        /* Line-buffered, so that a reader following the trace (the demo's
         * progress lines) sees each frame as it happens. */
        setvbuf(s->trace, NULL, _IOLBF, 0);
        fputs("t,x,z,phi_deg,v,w,step,status,h11,h12,h13,h31,h32,h33,e_x,"
              "parallax,n_inliers,n_matches\n",
              s->trace);
    }
    if (o->record_path) {
        s->record = fopen(o->record_path, "wb");
        if (!s->record) {
            sim_cli_fail("--record: cannot open '%s': %s", o->record_path, strerror(errno));
        }
        if (sim_record_write_header(s->record) != 0) {
            fprintf(stderr, "spvs-sim: cannot write the recording\n");
            return EXIT_LINK;
        }
    }
#ifdef SPVS_HAVE_ROSBAG
    if (o->rosbag_dir) {
        char berr[200];
        s->rosbag = sim_rosbag_open(o->rosbag_dir, berr, sizeof(berr));
        if (!s->rosbag) {
            sim_cli_fail("%s", berr);
        }
    }
#endif
    return 0;
}

/* Closes the sinks; nonzero when one could not be written out. */
static int close_sinks(sinks_t *s)
{
    int bad = 0;
    if (s->trace && fclose(s->trace) != 0) {
        bad = 1;
    }
    if (s->record && fclose(s->record) != 0) {
        bad = 1;
    }
#ifdef SPVS_HAVE_ROSBAG
    if (s->rosbag && sim_rosbag_close(s->rosbag, s->err, sizeof(s->err)) != 0) {
        bad = 1;
    }
#endif
    return bad;
}

#ifdef SPVS_HAVE_FRONTEND
/* --frontend images: the front end on the run's camera and plane, as the
 * loop's source of observations. */
static void open_images(options_t *o, images_t *images)
{
    memset(images, 0, sizeof(*images));
    if (!o->images) {
        return;
    }
    static sim_world_t w;
    char ferr[200];
    if (sim_config_world(&o->cfg, &w, ferr, sizeof(ferr)) != 0) {
        sim_cli_fail("%s", ferr);
    }
    sim_frontend_params_t fp;
    sim_frontend_params_default(&fp);
    fp.seed = o->cfg.seed;
    fp.texture = o->texture;
    images->fe = sim_frontend_create(&fp, &w.cam, &w.plane, ferr, sizeof(ferr));
    if (images->fe == NULL) {
        sim_cli_fail("%s", ferr);
    }
    if (o->save_frames_dir) {
        char tpath[1200];
        snprintf(tpath, sizeof(tpath), "%s/target.png", o->save_frames_dir);
        if (sim_frontend_save_target(images->fe, tpath, ferr, sizeof(ferr)) != 0) {
            sim_cli_fail("--save-frames: %s", ferr);
        }
    }
    images->o = o;
    o->cfg.observe = observe_images;
    o->cfg.observe_user = images;
}

/* The front end's totals (unless quiet), then closes it; nonzero when a
 * frame could not be saved (its message into s->err). */
static int close_images(const options_t *o, images_t *images, sinks_t *s)
{
    if (images->fe == NULL) {
        return 0;
    }
    sim_frontend_totals_t t;
    sim_frontend_totals(images->fe, &t);
    if (!o->quiet) {
        printf("images: %u frames, matches per frame mean %.1f (min %u, "
               "max %u), mismatches %.1f %% (worst frame %.1f %%)\n",
               (unsigned)t.frames, t.frames ? (double)t.matches / t.frames : 0.0,
               (unsigned)t.min_matches, (unsigned)t.max_matches,
               t.matches ? 100.0 * (double)t.mismatches / (double)t.matches : 0.0,
               100.0 * t.max_mismatch_rate);
    }
    sim_frontend_destroy(images->fe);
    images->fe = NULL;
    if (images->failed) {
        snprintf(s->err, sizeof(s->err), "%.150s", images->err);
        return 1;
    }
    return 0;
}
#endif

/* The run's outcome as the exit status, after its summary. */
static int finish_run(const options_t *o, const sim_result_t *res, const sinks_t *s, int out_bad)
{
    if (o->json) {
        print_json(o, res, s);
    }
    fflush(stdout);
    if (res->status == SIM_ABORTED || out_bad) {
        fprintf(stderr, "spvs-sim: %s\n", s->err[0] ? s->err : "cannot write an output file");
        return EXIT_LINK;
    }
    if (res->status == SIM_LINK_ERROR) {
        fprintf(stderr, "spvs-sim: link error: %s\n", res->reason);
        return EXIT_LINK;
    }
    return 0;
}

int main(int argc, char **argv)
{
    options_t o;
    parse_options(argc, argv, &o);

    /* Build the scene once before anything is opened or printed, so that
     * settings that give no usable scene are a plain usage error. */
    {
        static sim_world_t probe;
        char werr[200];
        if (sim_config_world(&o.cfg, &probe, werr, sizeof(werr)) != 0) {
            sim_cli_fail("%s", werr);
        }
    }
    sinks_t sinks;
    if (open_sinks(&o, &sinks) != 0) {
        return EXIT_LINK;
    }
#ifdef SPVS_HAVE_FRONTEND
    images_t images;
    open_images(&o, &images);
#endif
    char err[200] = "";
    sim_link_t link;
    if (open_link_q(&o, &link, err, sizeof(err)) != 0) {
        fprintf(stderr, "spvs-sim: cannot open the %s link: %s\n", o.transport, err);
        return EXIT_LINK;
    }
    if (!o.quiet) {
        print_settings(&o);
        fflush(stdout);
    }

    sim_result_t res;
    int rc = sim_run(&o.cfg, &link, &res, on_frame, &sinks, err, sizeof(err));
    if (link.close) {
        link.close(link.ctx);
    }
    int out_bad = close_sinks(&sinks);
    if (rc != 0) {
        /* The scene could not be built from these settings. */
        fprintf(stderr, "spvs-sim: %s\n", err);
        return EXIT_USAGE;
    }
    if (!o.quiet) {
        print_report(&res);
    }
#ifdef SPVS_HAVE_FRONTEND
    out_bad |= close_images(&o, &images, &sinks);
#endif
    return finish_run(&o, &res, &sinks, out_bad);
}
