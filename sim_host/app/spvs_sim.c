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

static const char *const usage_text =
    "usage: spvs-sim [options]\n"
    "Closed-loop simulation of Shortest Path Control (Methods I, II, III).\n"
    "\n"
    "  --method 1|2|3        control method (3)\n"
    "  --pose X,Z,PHI_DEG    start pose, metres and degrees (-3,-10,-30)\n"
    "  --normal NX,NY,NZ     plane normal, normalised here (0.3,-0.6,-0.75)\n"
    "  --distance D_M        plane distance d > 0, metres (45)\n"
    "  --noise SIGMA_PX      Gaussian image noise, pixels (0)\n"
    "  --outliers FRACTION   mismatched fraction of each frame, [0,1) (0)\n"
    "  --drift DEG_PER_M     odometry drift in rotation, deg per metre (0)\n"
    "  --focal-mm F          TRUE focal length, mm; the controller assumes 6,\n"
    "                        or 3 with --frontend images (6; images: 3)\n"
    "  --pp-offset PX        TRUE principal point x offset, pixels (0)\n"
    "  --seed S              seed of scene, noise and RANSAC, 0..4294967295 (0)\n"
    "  --dt S                control period, seconds (0.1)\n"
    "  --max-time S          stop with status timeout after this, seconds (300)\n"
    "  --clip                match only points inside the 640x480 frame\n"
    "  --trace FILE.csv      write one CSV row per frame\n"
    "  --record FILE         write a binary recording (docs/RECORDING.md)\n"
    "  --transport T         inproc (default), lcm, zenoh or mcu (QEMU,\n"
    "                        docs/SERIAL.md)\n"
    "  --mcu-image FILE      mcu: the application image (the build's)\n"
    "  --quantize-serial     round frames as the serial link does (1/16 px,\n"
    "                        ms) before any transport\n"
    "  --lcm-url URL         LCM provider (udpm://239.255.76.67:7667?ttl=0)\n"
    "  --zenoh-endpoint E    Zenoh endpoint (tcp/127.0.0.1:7447)\n"
    "  --timeout S           transport wait for each command, seconds (2)\n"
    "  --lcm-matches-channel CH  LCM channel the frames go out on (SPVS_MATCHES)\n"
    "  --keep-last S         LCM: a frame unanswered within --timeout is no\n"
    "                        error: drive on the newest command received, for\n"
    "                        at most S s of frame time, then stop (off)\n"
    "  --realtime            pace frames at dt in wall-clock time\n"
    "  --frontend F          points (default): exact projected points;\n"
    "                        images: SIFT matches in rendered images\n"
    "  --texture FILE        images: a photograph on the plane instead of\n"
    "                        the procedural texture\n"
    "  --save-frames DIR     images: write every Nth frame as DIR/frame_NNNNN.png\n"
    "                        and the target image as DIR/target.png\n"
    "  --save-every N        images: N for --save-frames (10)\n"
    "  --save-matches FRAME  images: write DIR/matches_FRAME.png (or ./)\n"
    "  --json                last stdout line: one JSON object with the result\n"
    "  --quiet               no human-readable report\n"
    "  --help                this text\n"
    "\n"
    "Exit status: 0 run completed (any outcome), 1 link or output error,\n"
    "2 bad options.\n";

/* Seeds and frame counts: 32 bits. */
#define U32_MAX_LL 4294967295LL

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

        /* Flags first: they take no value. */
        static const char *const flags[] = { "--help", "--json", "--quiet",
                                             "--clip", "--realtime",
                                             "--quantize-serial" };
        int is_flag = 0;
        for (size_t k = 0; k < sizeof(flags) / sizeof(flags[0]); ++k) {
            if (strcmp(name, flags[k]) == 0) {
                is_flag = 1;
            }
        }
        if (is_flag) {
            if (val) {
                sim_cli_fail("%s takes no value", name);
            }
            if (strcmp(name, "--help") == 0) {
                fputs(usage_text, stdout);
                exit(0);
            } else if (strcmp(name, "--json") == 0) {
                o->json = 1;
            } else if (strcmp(name, "--quiet") == 0) {
                o->quiet = 1;
            } else if (strcmp(name, "--clip") == 0) {
                o->cfg.clip = 1;
            } else if (strcmp(name, "--quantize-serial") == 0) {
                o->quantize_serial = 1;
            } else {
                o->cfg.realtime = 1;
            }
            continue;
        }

        static const char *const valued[] = {
            "--method", "--pose", "--normal", "--distance", "--noise",
            "--outliers", "--drift", "--focal-mm", "--pp-offset", "--seed",
            "--dt", "--max-time", "--trace", "--record", "--transport",
            "--lcm-url", "--zenoh-endpoint", "--timeout",
            "--lcm-matches-channel", "--keep-last", "--frontend",
            "--save-frames", "--save-every", "--save-matches", "--mcu-image",
            "--texture" };
        int known = 0;
        for (size_t k = 0; k < sizeof(valued) / sizeof(valued[0]); ++k) {
            if (strcmp(name, valued[k]) == 0) {
                known = 1;
            }
        }
        if (!known) {
            sim_cli_fail("unknown option '%s'", name);
        }
        if (!val) {
            if (i + 1 >= argc) {
                sim_cli_fail("%s needs a value", name);
            }
            val = argv[++i];
        }

        sim_config_t *c = &o->cfg;
        if (strcmp(name, "--method") == 0) {
            c->method = (int)sim_cli_int(name, val, 1, 3);
        } else if (strcmp(name, "--pose") == 0) {
            double v[3];
            sim_cli_triple(name, val, -SIM_CLI_INF, SIM_CLI_INF, v);
            c->start.x_m = v[0];
            c->start.z_m = v[1];
            c->start.phi_rad = v[2] * PI / 180.0;
        } else if (strcmp(name, "--normal") == 0) {
            sim_cli_triple(name, val, -SIM_CLI_INF, SIM_CLI_INF, c->normal);
            if (hypot(hypot(c->normal[0], c->normal[1]), c->normal[2]) <
                1e-9) {
                sim_cli_fail("--normal: '%s' is a zero vector", val);
            }
        } else if (strcmp(name, "--distance") == 0) {
            c->distance_m = sim_cli_real(name, val, 0.0, SIM_CLI_INF,
                                         SIM_CLI_OPEN);
        } else if (strcmp(name, "--noise") == 0) {
            c->noise_px = sim_cli_real(name, val, 0.0, SIM_CLI_INF,
                                       SIM_CLI_OPEN_HI);
        } else if (strcmp(name, "--outliers") == 0) {
            c->outliers = sim_cli_real(name, val, 0.0, 1.0, SIM_CLI_OPEN_HI);
        } else if (strcmp(name, "--drift") == 0) {
            c->drift_deg_per_m = sim_cli_real(name, val, -SIM_CLI_INF,
                                              SIM_CLI_INF, SIM_CLI_OPEN);
        } else if (strcmp(name, "--focal-mm") == 0) {
            c->focal_true_mm = sim_cli_real(name, val, 0.0, SIM_CLI_INF,
                                            SIM_CLI_OPEN);
            o->focal_given = 1;
        } else if (strcmp(name, "--pp-offset") == 0) {
            c->pp_offset_px = sim_cli_real(name, val, -SIM_CLI_INF,
                                           SIM_CLI_INF, SIM_CLI_OPEN);
        } else if (strcmp(name, "--seed") == 0) {
            o->seed32 = (uint32_t)sim_cli_int(name, val, 0, U32_MAX_LL);
            c->seed = o->seed32;
        } else if (strcmp(name, "--dt") == 0) {
            c->dt_s = sim_cli_real(name, val, 0.0, 10.0, SIM_CLI_OPEN_LO);
        } else if (strcmp(name, "--max-time") == 0) {
            c->max_time_s = sim_cli_real(name, val, 0.0, SIM_CLI_INF,
                                         SIM_CLI_OPEN);
        } else if (strcmp(name, "--trace") == 0) {
            o->trace_path = val;
        } else if (strcmp(name, "--record") == 0) {
            o->record_path = val;
        } else if (strcmp(name, "--transport") == 0) {
            if (strcmp(val, "inproc") != 0 && strcmp(val, "fixed") != 0 &&
                strcmp(val, "lcm") != 0 && strcmp(val, "zenoh") != 0 &&
                strcmp(val, "mcu") != 0) {
                sim_cli_fail("--transport: '%s' is not inproc, fixed, lcm, zenoh or mcu", val);
            }
            o->transport = val;
        } else if (strcmp(name, "--lcm-url") == 0) {
            o->lcm_url = val;
        } else if (strcmp(name, "--mcu-image") == 0) {
            o->mcu_image = val;
        } else if (strcmp(name, "--zenoh-endpoint") == 0) {
            o->zenoh_endpoint = val;
        } else if (strcmp(name, "--frontend") == 0) {
            if (strcmp(val, "points") == 0) {
                o->images = 0;
            } else if (strcmp(val, "images") == 0) {
#ifdef SPVS_HAVE_FRONTEND
                o->images = 1;
#else
                sim_cli_fail("--frontend images: this build has no image "
                            "front end (OpenCV)");
#endif
            } else {
                sim_cli_fail("--frontend: '%s' is not points or images", val);
            }
        } else if (strcmp(name, "--texture") == 0) {
            o->texture = val;
        } else if (strcmp(name, "--save-frames") == 0) {
            o->save_frames_dir = val;
        } else if (strcmp(name, "--save-every") == 0) {
            o->save_every = (uint32_t)sim_cli_int(name, val, 1, U32_MAX_LL);
        } else if (strcmp(name, "--save-matches") == 0) {
            o->save_matches_frame = (long)sim_cli_int(name, val, 0, U32_MAX_LL);
        } else if (strcmp(name, "--timeout") == 0) {
            o->timeout_s = sim_cli_real(name, val, 0.0, 3600.0,
                                        SIM_CLI_OPEN_LO);
        } else if (strcmp(name, "--lcm-matches-channel") == 0) {
            if (val[0] == '\0' || strlen(val) > 63) {
                sim_cli_fail("--lcm-matches-channel: '%s' is not 1..63 "
                            "characters", val);
            }
            o->lcm_matches_channel = val;
        } else if (strcmp(name, "--keep-last") == 0) {
            o->keep_last_s = sim_cli_real(name, val, 0.0, 3600.0,
                                          SIM_CLI_OPEN_LO);
        }
    }
    if (!o->images && (o->save_frames_dir || o->save_matches_frame >= 0 ||
                       o->texture)) {
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
    /* Whatever the single checks missed (combinations, ranges). */
    char err[160];
    if (sim_config_check(&o->cfg, err, sizeof(err)) != 0) {
        sim_cli_fail("%s", err);
    }
}

/* ---- outputs ------------------------------------------------------------ */

typedef struct {
    FILE *trace;
    FILE *record;
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
 * check, pixels of mean corner transfer, and the mean parallax of the
 * remembered off-plane points (pixels, -1: none seen). */
static void print_json_arrival(const sinks_t *s)
{
    const spvs_output_t *a = &s->last;
    if (!s->has_last) {
        fputs(",\"arrival\":null", stdout);
        return;
    }
    printf(",\"arrival\":{\"corner_px\":%.6g,\"bound_px\":%.6g,\"lateral_px\":%.6g"
           ",\"depth_px\":%.6g,\"h13_px\":%.6g,\"parallax_px\":%.6g"
           ",\"frames\":%u,\"reentries\":%u,\"next_step\":%u}",
           (double)a->arrival_corner_px, (double)a->arrival_bound_px,
           (double)a->arrival_lateral_px, (double)a->arrival_depth_px,
           (double)a->arrival_h13_px, (double)a->arrival_parallax_px,
           (unsigned)a->arrival_frames,
           (unsigned)a->arrival_reentries, (unsigned)a->arrival_next);
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
#ifdef SPVS_HAVE_ZENOH
    return sim_link_zenoh_open(o->zenoh_endpoint, o->timeout_s, link, err,
                               err_len);
#else
    sim_cli_fail("--transport zenoh: this build has no Zenoh support");
#endif
    return -1;
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
    memset(&sinks, 0, sizeof(sinks));
    if (o.trace_path) {
        sinks.trace = fopen(o.trace_path, "w");
        if (!sinks.trace) {
            sim_cli_fail("--trace: cannot open '%s': %s", o.trace_path,
                        strerror(errno));
        }
        /* Line-buffered, so that a reader following the trace (the demo's
         * progress lines) sees each frame as it happens. */
        setvbuf(sinks.trace, NULL, _IOLBF, 0);
        fputs("t,x,z,phi_deg,v,w,step,status,h11,h12,h13,h31,h32,h33,e_x,"
              "parallax,n_inliers,n_matches\n", sinks.trace);
    }
    if (o.record_path) {
        sinks.record = fopen(o.record_path, "wb");
        if (!sinks.record) {
            sim_cli_fail("--record: cannot open '%s': %s", o.record_path,
                        strerror(errno));
        }
        if (sim_record_write_header(sinks.record) != 0) {
            fprintf(stderr, "spvs-sim: cannot write the recording\n");
            return EXIT_LINK;
        }
    }

#ifdef SPVS_HAVE_FRONTEND
    images_t images;
    memset(&images, 0, sizeof(images));
    if (o.images) {
        static sim_world_t w;
        char ferr[200];
        if (sim_config_world(&o.cfg, &w, ferr, sizeof(ferr)) != 0) {
            sim_cli_fail("%s", ferr);
        }
        sim_frontend_params_t fp;
        sim_frontend_params_default(&fp);
        fp.seed = o.cfg.seed;
        fp.texture = o.texture;
        images.fe = sim_frontend_create(&fp, &w.cam, &w.plane, ferr,
                                        sizeof(ferr));
        if (images.fe == NULL) {
            sim_cli_fail("%s", ferr);
        }
        images.o = &o;
        if (o.save_frames_dir) {
            char tpath[1200];
            snprintf(tpath, sizeof(tpath), "%s/target.png", o.save_frames_dir);
            if (sim_frontend_save_target(images.fe, tpath, ferr,
                                         sizeof(ferr)) != 0) {
                sim_cli_fail("--save-frames: %s", ferr);
            }
        }
        o.cfg.observe = observe_images;
        o.cfg.observe_user = &images;
    }
#endif

    char err[200] = "";
    sim_link_t link;
    if (open_link_q(&o, &link, err, sizeof(err)) != 0) {
        fprintf(stderr, "spvs-sim: cannot open the %s link: %s\n",
                o.transport, err);
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
    int out_bad = 0;
    if (sinks.trace && fclose(sinks.trace) != 0) {
        out_bad = 1;
    }
    if (sinks.record && fclose(sinks.record) != 0) {
        out_bad = 1;
    }
    if (rc != 0) {
        /* The scene could not be built from these settings. */
        fprintf(stderr, "spvs-sim: %s\n", err);
        return EXIT_USAGE;
    }
    if (!o.quiet) {
        print_report(&res);
    }
#ifdef SPVS_HAVE_FRONTEND
    if (images.fe != NULL) {
        sim_frontend_totals_t t;
        sim_frontend_totals(images.fe, &t);
        if (!o.quiet) {
            printf("images: %u frames, matches per frame mean %.1f (min %u, "
                   "max %u), mismatches %.1f %% (worst frame %.1f %%)\n",
                   (unsigned)t.frames,
                   t.frames ? (double)t.matches / t.frames : 0.0,
                   (unsigned)t.min_matches, (unsigned)t.max_matches,
                   t.matches ? 100.0 * (double)t.mismatches / (double)t.matches
                             : 0.0,
                   100.0 * t.max_mismatch_rate);
        }
        sim_frontend_destroy(images.fe);
        images.fe = NULL;
        if (images.failed) {
            out_bad = 1;
            snprintf(sinks.err, sizeof(sinks.err), "%.150s", images.err);
        }
    }
#endif
    if (o.json) {
        print_json(&o, &res, &sinks);
    }
    fflush(stdout);
    if (res.status == SIM_ABORTED || out_bad) {
        fprintf(stderr, "spvs-sim: %s\n",
                sinks.err[0] ? sinks.err : "cannot write an output file");
        return EXIT_LINK;
    }
    if (res.status == SIM_LINK_ERROR) {
        fprintf(stderr, "spvs-sim: link error: %s\n", res.reason);
        return EXIT_LINK;
    }
    return 0;
}
