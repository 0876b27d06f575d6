/*
 * spvs_camera.cpp - spvs-camera: the camera front end of a real robot
 * (docs/CAMERA.md).
 *
 *   spvs-camera teach --source SRC --out GOAL.png
 *   spvs-camera --goal GOAL.png --source SRC [--method 1|2|3]
 *               [--transport none|lcm|zenoh|dds] [--json] ...
 *
 * Each frame: capture, check (size, dark, blank), detect, match against the
 * goal's features (fixed once: their indices are the core's feature
 * indices), keep at most SPVS_MAX_MATCHES best first and spread over the
 * image, then the core: the estimate of H alone, the controller
 * (--method), or the matches out to a controller across LCM or Zenoh
 * (--transport).  Every frame that is not usable gives its status and a
 * stop command.
 */
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sim/cli.h"
#include "sim/clock.h"
#include "sim/link.h"
#include "source.hpp"
#include "spvs/spvs.h"
#include "vision.hpp"

#ifdef SPVS_HAVE_LCM
#include "sim/link_lcm.h"
#include "wire.h"
#endif
#ifdef SPVS_HAVE_DDS
#include "sim/link_dds.h"
#endif
#ifdef SPVS_HAVE_ZENOH
#include "sim/link_zenoh.h"
#endif

namespace {

constexpr int kExitLink = 1;
constexpr int kFinalStops = 3;
/* The image noise the arrival check is told (as for the simulator's
 * image front end, sim/frontend.h: SIFT matches, not 1 px point noise). */
constexpr double kArrivalSigmaPx = 1.5;

struct Options {
    bool teach = false;
    std::string source, goal, out, calib;
    double focal_px = 0.0;
    int method = 0;
    std::string transport = "none";
    bool json = false;
    bool json_matches = false;
    double dt_s = 0.1;
    long long max_frames = -1;
    long long teach_frame = 0;
    uint32_t seed = 0;
    std::string lcm_url = "udpm://239.255.76.67:7667?ttl=0";
    std::string zenoh_endpoint = "tcp/127.0.0.1:7447";
    double timeout_s = 2.0;
    spvscam::VisionParams vp;
};

/* One option of the command line: the parser and --help read the same
 * table.  metavar nullptr: a flag; a '\n' in help continues the text under
 * its first line. */
struct OptSpec {
    const char *name;
    const char *metavar;
    const char *help;
    void (*set)(Options &o, const char *val);
};

void set_transport(Options &o, const char *val)
{
    o.transport = val;
    if (o.transport != "none" && o.transport != "lcm" && o.transport != "zenoh" &&
        o.transport != "dds") {
        sim_cli_fail("--transport: '%s' is not none, lcm, zenoh or dds", val);
    }
}

void set_half(Options &o, const char *val)
{
    o.vp.half = std::strcmp(val, "auto") == 0 ? -1 : (int)sim_cli_int("--half", val, 0, 1);
}

void set_goal_features(Options &o, const char *val)
{
    o.vp.goal_features = (int)sim_cli_int("--goal-features", val,
                                          spvscam::Vision::kMinGoalFeatures, SPVS_MAX_FEATURES);
}

/* Every option, in the order --help lists them. */
const OptSpec kOpts[] = {
    {"--source", "SRC",
     "/dev/videoN, a video file, a folder of images read\n"
     "in name order, or a pattern DIR/frame_*.png",
     [](Options &o, const char *v) { o.source = v; }},
    {"--goal", "FILE", "the goal image (spvs-camera teach writes one)",
     [](Options &o, const char *v) { o.goal = v; }},
    {"--out", "FILE", "teach: where the goal image is written",
     [](Options &o, const char *v) { o.out = v; }},
    {"--method", "1|2|3",
     "run the controller and publish (v, w); without it\n"
     "each frame's H is estimated only",
     [](Options &o, const char *v) { o.method = (int)sim_cli_int("--method", v, 1, 3); }},
    {"--transport", "T",
     "none (default), lcm, zenoh or dds.  lcm, zenoh or\n"
     "dds without --method: the matches go to a\n"
     "controller (spvs-node, spvs-node --dds for dds,\n"
     "$ROS_DOMAIN_ID) as spvs-sim sends them,\n"
     "and its command comes back; lcm with --method: the\n"
     "command and telemetry are published on SPVS_CMD\n"
     "and SPVS_STATE",
     set_transport},
    {"--focal-px", "F",
     "focal length, pixels; principal point at the image\n"
     "centre, no distortion",
     [](Options &o, const char *v) {
         o.focal_px = sim_cli_real("--focal-px", v, 1.0, 1e6, SIM_CLI_CLOSED);
     }},
    {"--calib", "FILE.yml",
     "OpenCV calibration (camera_matrix,\n"
     "distortion_coefficients); one of the two is needed",
     [](Options &o, const char *v) { o.calib = v; }},
    {"--json", nullptr, "one JSON object per frame on stdout, then a summary",
     [](Options &o, const char *) { o.json = true; }},
    {"--json-matches", nullptr,
     "--json, each frame also with its kept matches \"m\":\n"
     "[feature, x_goal, y_goal, x_cur, y_cur] (centred px)",
     [](Options &o, const char *) { o.json = o.json_matches = true; }},
    {"--dt", "S",
     "frame period of files and folders, seconds (0.1);\n"
     "a device's frames are timed by the clock",
     [](Options &o, const char *v) {
         o.dt_s = sim_cli_real("--dt", v, 0.0, 60.0, SIM_CLI_OPEN_LO);
     }},
    {"--max-frames", "N", "stop after N frames (all)",
     [](Options &o, const char *v) {
         o.max_frames = sim_cli_int("--max-frames", v, 1, 1000000000LL);
     }},
    {"--ratio", "R", "Lowe's ratio test, (0, 1] (0.7)",
     [](Options &o, const char *v) {
         o.vp.ratio = sim_cli_real("--ratio", v, 0.0, 1.0, SIM_CLI_OPEN_LO);
     }},
    {"--features", "N", "features detected per frame, 100..20000 (1500)",
     [](Options &o, const char *v) {
         o.vp.frame_features = (int)sim_cli_int("--features", v, 100, 20000);
     }},
    {"--goal-features", "N", "goal features kept, 50..512 (500)", set_goal_features},
    {"--subpixel", "0|1", "refine matched corners to sub-pixel (1)",
     [](Options &o, const char *v) { o.vp.subpixel = (int)sim_cli_int("--subpixel", v, 0, 1); }},
    {"--half", "auto|0|1", "detect on the halved image (auto: width >= 600)", set_half},
    {"--seed", "S", "RANSAC seed (0)",
     [](Options &o, const char *v) {
         o.seed = (uint32_t)sim_cli_int("--seed", v, 0, 4294967295LL);
     }},
    {"--lcm-url", "URL", "LCM provider (udpm://239.255.76.67:7667?ttl=0)",
     [](Options &o, const char *v) { o.lcm_url = v; }},
    {"--zenoh-endpoint", "E", "Zenoh endpoint (tcp/127.0.0.1:7447)",
     [](Options &o, const char *v) { o.zenoh_endpoint = v; }},
    {"--timeout", "S", "transport wait for each command, seconds (2)",
     [](Options &o, const char *v) {
         o.timeout_s = sim_cli_real("--timeout", v, 0.0, 3600.0, SIM_CLI_OPEN_LO);
     }},
    {"--frame", "N",
     "teach: the frame of the source to keep (0; a\n"
     "device skips 10 frames first)",
     [](Options &o, const char *v) {
         o.teach_frame = sim_cli_int("--frame", v, 0, 1000000000LL);
     }},
    {"--help", nullptr, "this text", nullptr},
};

/* The option column's width in --help (sim_cli_help_option). */
constexpr int kHelpCol = 20;

void usage(FILE *f)
{
    std::fputs("usage: spvs-camera --goal GOAL.png --source SRC [options]\n"
               "       spvs-camera teach --source SRC --out GOAL.png [options]\n"
               "Camera front end of spvs: matches each frame against the goal image and\n"
               "estimates H (or runs the controller) with the core.  docs/CAMERA.md.\n"
               "\n",
               f);
    for (const OptSpec &o : kOpts) {
        sim_cli_help_option(f, kHelpCol, o.name, o.metavar, o.help);
    }
    std::fputs("\n"
               "Exit status: 0 the source ended (or --max-frames), 1 a lost device, a\n"
               "transport or output error, 2 bad options or an unusable goal.\n",
               f);
}

const OptSpec *find_opt(const std::string &name)
{
    for (const OptSpec &o : kOpts) {
        if (name == o.name) {
            return &o;
        }
    }
    return nullptr;
}

Options parse_options(int argc, char **argv)
{
    sim_cli_program("spvs-camera");
    Options o;
    int i = 1;
    if (argc > 1 && std::strcmp(argv[1], "teach") == 0) {
        o.teach = true;
        i = 2;
    }
    for (; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-h") {
            usage(stdout);
            std::exit(0);
        }
        if (arg.rfind("--", 0) != 0) {
            sim_cli_fail("unexpected argument '%s'", arg.c_str());
        }
        const size_t eq = arg.find('=');
        const std::string name = eq != std::string::npos ? arg.substr(0, eq) : arg;
        const OptSpec *spec = find_opt(name);
        if (spec == nullptr) {
            sim_cli_fail("unknown option '%s'", name.c_str());
        }
        if (spec->set == nullptr) {
            usage(stdout);
            std::exit(0);
        }
        const char *val = nullptr;
        if (spec->metavar == nullptr) {
            if (eq != std::string::npos) {
                sim_cli_fail("%s takes no value", name.c_str());
            }
        } else if (eq != std::string::npos) {
            val = argv[i] + eq + 1;
        } else if (i + 1 < argc) {
            val = argv[++i];
        } else {
            sim_cli_fail("%s needs a value", arg.c_str());
        }
        spec->set(o, val);
    }
    if (o.source.empty()) {
        sim_cli_fail("--source is needed");
    }
    if (o.focal_px > 0.0 && !o.calib.empty()) {
        sim_cli_fail("give --focal-px or --calib, not both");
    }
    if (o.teach) {
        if (o.out.empty()) {
            sim_cli_fail("teach: --out GOAL.png is needed");
        }
    } else {
        if (o.goal.empty()) {
            sim_cli_fail("--goal is needed (spvs-camera teach makes one)");
        }
        if (o.focal_px <= 0.0 && o.calib.empty()) {
            sim_cli_fail("--focal-px or --calib is needed");
        }
        if ((o.transport == "zenoh" || o.transport == "dds") && o.method != 0) {
            sim_cli_fail("--transport %s sends the matches to the controller "
                         "(spvs-node): leave out --method", o.transport.c_str());
        }
    }
#ifndef SPVS_HAVE_LCM
    if (o.transport == "lcm") {
        sim_cli_fail("--transport lcm: this build has no LCM support");
    }
#endif
#ifndef SPVS_HAVE_DDS
    if (o.transport == "dds") {
        sim_cli_fail("--transport dds: this build has no DDS support (cyclonedds-dev)");
    }
#endif
#ifndef SPVS_HAVE_ZENOH
    if (o.transport == "zenoh") {
        sim_cli_fail("--transport zenoh: this build has no Zenoh support");
    }
#endif
    return o;
}

std::string intrinsics_for(const Options &o, cv::Size sz,
                           spvscam::Intrinsics &in)
{
    if (!o.calib.empty()) {
        return in.from_file(o.calib);
    }
    /* teach needs no focal length for its check: a nominal one serves. */
    in.from_focal(o.focal_px > 0.0 ? o.focal_px : (double)sz.width, sz);
    return "";
}

/* ---- teach ------------------------------------------------------------- */

/* Frames a device is read before the one kept: exposure and white balance
 * settle over the first few. */
constexpr long long kDeviceSettleFrames = 10;

int run_teach(const Options &o)
{
    spvscam::FrameSource src;
    std::string why = src.open(o.source);
    if (!why.empty()) {
        std::fprintf(stderr, "spvs-camera: %s\n", why.c_str());
        return SIM_CLI_EXIT_USAGE;
    }
    const long long want =
        o.teach_frame + (src.kind() == spvscam::FrameSource::DEVICE
                             ? kDeviceSettleFrames : 0);
    cv::Mat img;
    std::string name;
    long long k = 0;
    for (;;) {
        const spvscam::FrameSource::Result r = src.next(img, name);
        if (r == spvscam::FrameSource::END) {
            std::fprintf(stderr, "spvs-camera: teach: the source ended before "
                         "frame %lld\n", want);
            return SIM_CLI_EXIT_USAGE;
        }
        if (k++ == want) {
            if (r != spvscam::FrameSource::FRAME) {
                std::fprintf(stderr, "spvs-camera: teach: frame %lld cannot "
                             "be read\n", want);
                return SIM_CLI_EXIT_USAGE;
            }
            break;
        }
    }
    spvscam::Intrinsics in;
    why = intrinsics_for(o, img.size(), in);
    if (why.empty()) {
        why = spvscam::teach_check(img, in, o.vp);
    }
    if (!why.empty()) {
        std::fprintf(stderr, "spvs-camera: teach: refused: %s\n", why.c_str());
        return SIM_CLI_EXIT_USAGE;
    }
    bool ok = false;
    try {
        ok = cv::imwrite(o.out, img);
    } catch (const std::exception &) {
        ok = false;
    }
    if (!ok) {
        std::fprintf(stderr, "spvs-camera: teach: cannot write '%s'\n",
                     o.out.c_str());
        return kExitLink;
    }
    spvscam::Vision v;
    (void)v.set_goal(img, in, o.vp);
    std::printf("goal: %s, %dx%d, %d features\n", o.out.c_str(), img.cols,
                img.rows, v.goal_count());
    return 0;
}

/* ---- run ----------------------------------------------------------------- */

/* The core and the transports behind one call per frame. */
struct Core {
    const Options *o = nullptr;
    spvs_params_t p{};
    bool have_link = false;
    sim_link_t link{};
    int last_step = 0;      /* the controller's step after the last frame */
#ifdef SPVS_HAVE_LCM
    lcm_t *lcm = nullptr;   /* --method with --transport lcm: publishing */
#endif

    std::string open(const Options &opt, const spvscam::Intrinsics &in);
    void close();
    /* One frame: local estimate (or controller), then the transport.
     * usable: false for a frame that failed its checks (the core then
     * commands a stop).  link_err: a transport failure, or "". */
    void frame(uint32_t seq, double t_s, const std::vector<spvs_match_t> &m,
               bool usable, spvs_output_t &out, spvs_output_t &remote,
               std::string &link_err);
};

spvs_t g_core; /* large: static, as the core expects */

/* Set by SIGINT and SIGTERM: the run ends after the frame in hand, with
 * its summary and a last stop command. */
volatile std::sig_atomic_t g_stop = 0;

void on_signal(int)
{
    g_stop = 1;
}

/* A string as JSON wants it inside quotes. */
std::string json_escape(const std::string &in)
{
    std::string out;
    for (unsigned char c : in) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += (char)c;
        } else if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", c);
            out += buf;
        } else {
            out += (char)c;
        }
    }
    return out;
}

std::string Core::open(const Options &opt, const spvscam::Intrinsics &in)
{
    o = &opt;
    spvs_params_default(&p, (spvs_method_t)(opt.method ? opt.method : 1));
    p.ctl.alpha_x = (spvs_real)in.K(0, 0);
    p.ctl.alpha_y = (spvs_real)in.K(1, 1);
    p.ctl.arrival_sigma_px = (spvs_real)kArrivalSigmaPx;
    p.seed = opt.seed;
    if (spvs_init(&g_core, &p) != SPVS_OK) {
        return "the core refused its parameters (focal length?)";
    }
    char err[240] = "";
    if (opt.transport == "lcm" && opt.method == 0) {
#ifdef SPVS_HAVE_LCM
        if (sim_link_lcm_open(opt.lcm_url.c_str(), opt.timeout_s, &link, err,
                              sizeof(err)) != 0) {
            return std::string("cannot open the LCM link: ") + err;
        }
        have_link = true;
#endif
    } else if (opt.transport == "lcm") {
#ifdef SPVS_HAVE_LCM
        lcm = lcm_create(opt.lcm_url.c_str());
        if (lcm == nullptr) {
            return "cannot open LCM at '" + opt.lcm_url + "'";
        }
#endif
    } else if (opt.transport == "dds") {
#ifdef SPVS_HAVE_DDS
        if (sim_link_dds_open(opt.timeout_s, &link, err, sizeof(err)) != 0) {
            return std::string("cannot open the DDS link: ") + err;
        }
        have_link = true;
#endif
    } else if (opt.transport == "zenoh") {
#ifdef SPVS_HAVE_ZENOH
        if (sim_link_zenoh_open(opt.zenoh_endpoint.c_str(), opt.timeout_s,
                                &link, err, sizeof(err)) != 0) {
            return std::string("cannot open the Zenoh link: ") + err;
        }
        have_link = true;
#endif
    }
    return "";
}

void Core::close()
{
#ifdef SPVS_HAVE_LCM
    /* The robot's last word from this program is a stop, sent
     * kFinalStops times 10 ms apart since a datagram can be lost. */
    if (lcm != nullptr) {
        spvs_cmd_t cmd;
        spvs_wire_cmd_stop(&cmd, -1, 0, SPVS_OK, last_step);
        for (int k = 0; k < kFinalStops; ++k) {
            (void)spvs_wire_publish_cmd(lcm, &cmd);
            sim_clock_sleep_until(sim_clock_now_s() + 0.01);
        }
    }
#endif
    if (have_link && link.close != nullptr) {
        link.close(link.ctx);
    }
    have_link = false;
#ifdef SPVS_HAVE_LCM
    if (lcm != nullptr) {
        lcm_destroy(lcm);
        lcm = nullptr;
    }
#endif
}

void Core::frame(uint32_t seq, double t_s, const std::vector<spvs_match_t> &m,
                 bool usable, spvs_output_t &out, spvs_output_t &remote,
                 std::string &link_err)
{
    std::memset(&out, 0, sizeof(out));
    std::memset(&remote, 0, sizeof(remote));
    link_err.clear();
    const uint16_t n = usable ? (uint16_t)m.size() : 0;
    /* The whole update runs with or without --method: the off-plane
     * memory it keeps (the goal features once seen off the plane) is part
     * of the estimate, since near the goal their parallax falls under the
     * inlier threshold and, refitted as plane points, they would bias H.
     * A frame that failed its checks goes in with no matches: the
     * controller answers with a stop and keeps its timing. */
    out.status = (int16_t)spvs_update(&g_core, m.data(), n, (spvs_real)t_s,
                                      &out);
    last_step = out.step;
    if (o->method == 0) {
        /* Estimate only: no command, and the frame's status is the
         * estimate's (the step logic's statuses mean nothing without a
         * robot that follows the commands). */
        out.v = out.w = 0;
        if (out.h_valid) {
            out.status = SPVS_OK;
        }
    }
#ifdef SPVS_HAVE_LCM
    if (lcm != nullptr) {
        spvs_cmd_t cmd;
        spvs_state_t st;
        const int64_t ut = (int64_t)std::llround(t_s * 1e6);
        spvs_wire_state_from_output(&st, seq, ut, &out);
        spvs_wire_cmd_from_output(&cmd, seq, ut, &out);
        if (spvs_wire_publish_state(lcm, &st) != 0 ||
            spvs_wire_publish_cmd(lcm, &cmd) != 0) {
            link_err = "LCM publish failed";
        }
    }
#endif
    if (have_link) {
        char err[240] = "";
        if (link.exchange(link.ctx, seq, t_s, m.data(), n, &remote, err,
                          sizeof(err)) != 0) {
            link_err = err[0] ? err : "transport failure";
            remote.v = remote.w = 0;
        }
    }
}

/* Totals for the summary. */
struct Totals {
    long long frames = 0, usable = 0, with_h = 0, matches = 0;
    long long min_matches = -1, max_matches = 0;
    double capture_ms = 0, detect_ms = 0, match_ms = 0, core_ms = 0;
    /* Stability: of the goal features matched in one frame, those matched
     * again in the next. */
    long long stay_num = 0, stay_den = 0;
    std::set<uint16_t> last_feats;
    bool have_last = false;
};

void print_h(const spvs_output_t &out, bool valid)
{
    if (!valid) {
        std::fputs("null", stdout);
        return;
    }
    std::fputc('[', stdout);
    for (int i = 0; i < 9; ++i) {
        std::printf("%s%.9g", i ? "," : "", (double)out.H[i]);
    }
    std::fputc(']', stdout);
}

void print_frame_json(const Options &o, long long frame, const std::string &name,
                      const spvscam::FrameMatches &fm, const std::string &status,
                      const spvs_output_t &out, const spvs_output_t &remote,
                      bool h_valid, const double ms[4])
{
    std::printf("{\"frame\":%lld,\"file\":\"%s\",\"keypoints\":%d,"
                "\"candidates\":%d,\"matches\":%zu,\"inliers\":%d,"
                "\"status\":\"%s\",\"h\":",
                frame, json_escape(name).c_str(), fm.keypoints, fm.candidates, fm.m.size(),
                h_valid ? (int)out.n_inliers : 0, status.c_str());
    print_h(out, h_valid);
    if (o.method != 0) {
        std::printf(",\"v\":%.9g,\"w\":%.9g,\"step\":%d", (double)out.v,
                    (double)out.w, (int)out.step);
    } else if (o.transport != "none") {
        std::printf(",\"v\":%.9g,\"w\":%.9g,\"step\":%d,\"remote_status\":\"%s\"",
                    (double)remote.v, (double)remote.w, (int)remote.step,
                    spvs_status_str(remote.status));
    }
    if (o.json_matches) {
        std::fputs(",\"m\":[", stdout);
        for (size_t i = 0; i < fm.m.size(); ++i) {
            const spvs_match_t &q = fm.m[i];
            std::printf("%s[%u,%.4f,%.4f,%.4f,%.4f]", i ? "," : "",
                        (unsigned)q.feature, (double)q.x_tgt, (double)q.y_tgt,
                        (double)q.x_cur, (double)q.y_cur);
        }
        std::fputc(']', stdout);
    }
    std::printf(",\"ms\":{\"capture\":%.3f,\"detect\":%.3f,\"match\":%.3f,"
                "\"core\":%.3f}}\n", ms[0], ms[1], ms[2], ms[3]);
}

void print_summary(const Options &o, const Totals &t, double wall_s,
                   double cpu_s, const char *end, int goal_features)
{
    const double nf = t.frames > 0 ? (double)t.frames : 1.0;
    if (o.json) {
        std::printf("{\"summary\":{\"frames\":%lld,\"usable\":%lld,"
                    "\"with_h\":%lld,\"end\":\"%s\",\"goal_features\":%d,"
                    "\"wall_s\":%.3f,\"cpu_s\":%.3f,\"fps\":%.2f,"
                    "\"matches_mean\":%.1f,"
                    "\"matches_min\":%lld,\"matches_max\":%lld,"
                    "\"stability\":%.4f,\"ms_per_frame\":{\"capture\":%.3f,"
                    "\"detect\":%.3f,\"match\":%.3f,\"core\":%.3f}}}\n",
                    t.frames, t.usable, t.with_h, end, goal_features, wall_s,
                    cpu_s, wall_s > 0 ? t.frames / wall_s : 0.0,
                    t.usable ? (double)t.matches / (double)t.usable : 0.0,
                    t.min_matches < 0 ? 0 : t.min_matches, t.max_matches,
                    t.stay_den ? (double)t.stay_num / (double)t.stay_den : 0.0,
                    t.capture_ms / nf, t.detect_ms / nf, t.match_ms / nf,
                    t.core_ms / nf);
    } else {
        std::printf("%lld frames (%lld usable, %lld with H) in %.2f s: %.1f "
                    "fps; matches mean %.1f; stability %.3f; ms per frame: "
                    "capture %.2f, detect %.2f, match %.2f, core %.2f; %s\n",
                    t.frames, t.usable, t.with_h, wall_s,
                    wall_s > 0 ? t.frames / wall_s : 0.0,
                    t.usable ? (double)t.matches / (double)t.usable : 0.0,
                    t.stay_den ? (double)t.stay_num / (double)t.stay_den : 0.0,
                    t.capture_ms / nf, t.detect_ms / nf, t.match_ms / nf,
                    t.core_ms / nf, end);
    }
}

void count_frame(Totals &t, const spvscam::FrameMatches &fm, bool usable,
                 bool h_valid)
{
    t.frames++;
    std::set<uint16_t> feats;
    if (usable) {
        t.usable++;
        const long long n = (long long)fm.m.size();
        t.matches += n;
        t.min_matches = t.min_matches < 0 ? n : std::min(t.min_matches, n);
        t.max_matches = std::max(t.max_matches, n);
        for (const spvs_match_t &m : fm.m) {
            feats.insert(m.feature);
        }
    }
    t.with_h += h_valid ? 1 : 0;
    if (t.have_last) {
        t.stay_den += (long long)t.last_feats.size();
        for (uint16_t f : t.last_feats) {
            t.stay_num += feats.count(f) ? 1 : 0;
        }
    }
    t.last_feats.swap(feats);
    t.have_last = true;
}

/* The goal's features, the intrinsics and the source, or a usage error
 * (exit status 2) with the reason. */
void open_inputs(const Options &o, spvscam::Intrinsics &in,
                 spvscam::Vision &vis, spvscam::FrameSource &src)
{
    cv::Mat goal_raw, goal;
    try {
        goal_raw = cv::imread(o.goal, cv::IMREAD_UNCHANGED);
    } catch (const std::exception &) {
        goal_raw.release();
    }
    if (goal_raw.empty()) {
        sim_cli_fail("--goal: cannot read the image '%s'", o.goal.c_str());
    }
    spvscam::to_grey8(goal_raw, goal);
    std::string why = intrinsics_for(o, goal.size(), in);
    if (!why.empty()) {
        sim_cli_fail("--calib: %s", why.c_str());
    }
    why = vis.set_goal(goal, in, o.vp);
    if (!why.empty()) {
        sim_cli_fail("--goal: %s", why.c_str());
    }
    why = src.open(o.source);
    if (!why.empty()) {
        sim_cli_fail("--source: %s", why.c_str());
    }
}

int run(const Options &o)
{
    spvscam::Intrinsics in;
    spvscam::Vision vis;
    spvscam::FrameSource src;
    open_inputs(o, in, vis, src);
    Core core;
    const std::string why = core.open(o, in);
    if (!why.empty()) {
        std::fprintf(stderr, "spvs-camera: %s\n", why.c_str());
        core.close();
        return kExitLink;
    }

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    Totals t;
    const double t_start = sim_clock_now_s();
    /* Processor time of all threads: the figure that does not depend on
     * what else the machine runs. */
    const std::clock_t cpu0 = std::clock();
    const char *end = "source_ended";
    int rc = 0;
    for (long long frame = 0; o.max_frames < 0 || frame < o.max_frames;
         ++frame) {
        if (g_stop) {
            end = "interrupted";
            break;
        }
        double ms[4] = { 0, 0, 0, 0 };
        double t0 = sim_clock_now_s();
        cv::Mat img;
        std::string name;
        const spvscam::FrameSource::Result r = src.next(img, name);
        ms[0] = (sim_clock_now_s() - t0) * 1e3;
        if (r == spvscam::FrameSource::END) {
            if (src.kind() == spvscam::FrameSource::DEVICE) {
                end = "lost_device";
                rc = kExitLink;
            }
            break;
        }
        /* Frame time: the clock for a device, frame x dt for files. */
        const double t_s = src.kind() == spvscam::FrameSource::DEVICE
                               ? t0 - t_start
                               : (double)frame * o.dt_s;
        std::string status;
        if (r == spvscam::FrameSource::UNREADABLE) {
            status = "unreadable_frame";
        } else if (r == spvscam::FrameSource::FAILED) {
            status = "capture_failed";
        } else {
            status = spvscam::check_frame(img, vis.size());
        }
        spvscam::FrameMatches fm;
        const bool usable = status.empty();
        if (usable) {
            try {
                vis.frame(img, fm, ms[1], ms[2]);
            } catch (const std::exception &) {
                fm = spvscam::FrameMatches();
                status = "vision_error";
            }
        }
        t0 = sim_clock_now_s();
        spvs_output_t out, remote;
        std::string link_err;
        core.frame((uint32_t)frame, t_s, fm.m, status.empty(), out, remote,
                   link_err);
        ms[3] = (sim_clock_now_s() - t0) * 1e3;
        if (status.empty()) {
            status = spvs_status_str(out.status);
        }
        if (!link_err.empty()) {
            status = "transport_error";
            std::fprintf(stderr, "spvs-camera: frame %lld: %s\n", frame,
                         link_err.c_str());
        }
        const bool h_valid = out.h_valid != 0;
        t.capture_ms += ms[0];
        t.detect_ms += ms[1];
        t.match_ms += ms[2];
        t.core_ms += ms[3];
        count_frame(t, fm, usable, h_valid);
        if (o.json) {
            print_frame_json(o, frame, name, fm, status, out, remote, h_valid,
                             ms);
        }
    }
    core.close();
    print_summary(o, t, sim_clock_now_s() - t_start,
                  (double)(std::clock() - cpu0) / CLOCKS_PER_SEC, end,
                  vis.goal_count());
    if (std::fflush(stdout) != 0) {
        return kExitLink;
    }
    return rc;
}

} // namespace

int main(int argc, char **argv)
{
    const Options o = parse_options(argc, argv);
    try {
        return o.teach ? run_teach(o) : run(o);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "spvs-camera: %s\n", e.what());
        return kExitLink;
    }
}
