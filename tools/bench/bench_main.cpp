/*
 * bench_main.cpp - spvs-bench: times the core's homography estimator against
 * OpenCV (and ViSP when built) on the same synthetic cases.  The whole-process
 * comparison (closed-loop homing run) is spvs-bench-homing, homing.cpp.
 *
 * The case matrix: pose family (homing, fig5, grazing; hombench.h) x N x
 * mismatch share x noise, 72 cases.
 *
 * Modes (one per run; docs/BENCHMARKS.md gives the commands behind its tables):
 *   --generate FILE            write the case matrix as a HOMBENCH v1 file
 *   --cases FILE --json        time estimators on every record of FILE and
 *                              print one JSON line per (case_id, estimator)
 *   --full                     generate the matrix in memory, time every
 *                              estimator, print JSON lines (--json) or tables
 *   --short                    CI mode: one case, few repeats, JSON lines
 *   --callgrind EST            run EST for --count K estimates (instruction
 *                              counts: run with K and with 0, subtract)
 * Options: --repeats K, --estimators a,b|all, --order turns|blocks,
 *   --between none|frame, --case ID, --family F[,F], --instances I, --poses P,
 *   --seed S, --n N, --mismatch F, --sigma PX, --count K, --warmup K.
 * Bad options print one line on stderr and exit with status 2.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "estimators.h"
#include "frame_work.h"
#include "hombench.h"
#include "sim/cli.h"

namespace {

using bench::Estimator;

/* The matrix: pose family (hombench.h: homing, fig5, grazing) x N x
 * mismatch fraction x noise sigma; case_id = ((iFamily * 4 + iN) * 3 +
 * iMismatch) * 2 + iSigma, so the homing family keeps ids 0-23. */
const uint32_t kNs[] = {50, 100, 200, 500};
const double kMismatch[] = {0.0, 0.2, 0.5};
const double kSigma[] = {0.0, 1.0};
const int kCellsPerFamily = 4 * 3 * 2;
const int kCases = (int)HB_FAMILIES * kCellsPerFamily;

/* The chi-square 0.99 quantile with two degrees of freedom, -2 ln 0.01: the
 * per-record view statistic inliers_over_sampson_99. */
const double kChi2Two99 = 9.2103403719761836;

struct Options {
    std::string mode;
    std::string file;
    std::string callgrind_est;
    std::string jsonl_path;
    bool json = false;
    bool per_record = false;
    bool blocks = false;
    bool frame = false;
    int repeats = -1;
    int warmup = -1;
    std::vector<std::string> estimators;
    uint32_t instances = 8;
    uint32_t poses = 8;
    uint64_t seed = 1;
    int only_case = -1;
    std::vector<bool> families = std::vector<bool>(HB_FAMILIES, true);
    uint32_t n = 100;
    double mismatch = 0.2;
    double sigma = 1.0;
    long count = 1000;
};

/* Option values through the edge's CLI helper (sim/cli.h): a bad one is a
 * one-line error naming the option, exit status 2. */
double parse_double(const char *opt, const char *s, double lo, double hi)
{
    return sim_cli_real(opt, s, lo, hi, SIM_CLI_CLOSED);
}

long parse_long(const char *opt, const char *s, long lo, long hi)
{
    return (long)sim_cli_int(opt, s, lo, hi);
}

/* A two-way option: false for `off`, true for `on`. */
bool parse_choice(const char *opt, const char *s, const char *off, const char *on)
{
    if (!std::strcmp(s, off))
        return false;
    if (!std::strcmp(s, on))
        return true;
    sim_cli_fail("%s takes %s or %s, not '%s'", opt, off, on, s);
}

std::vector<std::string> split_list(const std::string &s)
{
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        size_t comma = s.find(',', start);
        if (comma == std::string::npos)
            comma = s.size();
        if (comma > start)
            out.push_back(s.substr(start, comma - start));
        start = comma + 1;
    }
    return out;
}

/* A list of pose families (hombench.h's names) or `all`. */
std::vector<bool> parse_families(const char *opt, const char *s)
{
    std::vector<bool> on(HB_FAMILIES, !std::strcmp(s, "all"));
    if (on[0])
        return on;
    for (const auto &name : split_list(s)) {
        uint32_t f = 0;
        while (f < HB_FAMILIES && name != hb_family_name(f))
            f++;
        if (f == HB_FAMILIES)
            sim_cli_fail("%s takes homing, fig5, grazing or all, not '%s'", opt, name.c_str());
        on[f] = true;
    }
    if (std::find(on.begin(), on.end(), true) == on.end())
        sim_cli_fail("%s needs a comma-separated list of families", opt);
    return on;
}

/* One option of the command line: the parser and --help read the same
 * table.  metavar nullptr: a flag; a mode is one of the exclusive modes;
 * a '\n' in help continues the text under its first line. */
struct OptSpec {
    const char *name;
    const char *metavar;
    bool mode;
    const char *help;
    void (*set)(Options &o, const char *opt, const char *val);
};

void set_mode(Options &o, const char *m)
{
    if (!o.mode.empty())
        sim_cli_fail("only one mode per run (%s and %s)", o.mode.c_str(), m);
    o.mode = m;
}

/* A mode that names a file: --generate FILE, --cases FILE. */
void set_mode_file(Options &o, const char *opt, const char *v)
{
    set_mode(o, opt);
    o.file = v;
}

void set_estimators(Options &o, const char *, const char *v)
{
    o.estimators = split_list(v);
    if (o.estimators.empty())
        sim_cli_fail("--estimators needs a comma-separated list");
}

/* Every option, in the order --help lists them. */
const OptSpec kOpts[] = {
    {"--generate", "FILE", true, "write the case matrix (HOMBENCH v1)", set_mode_file},
    {"--cases", "FILE", true,
     "time estimators on FILE, one JSON line per (case_id,\n"
     "estimator); needs --json",
     set_mode_file},
    {"--full", nullptr, true, "whole matrix, tables (or JSON lines with --json)",
     [](Options &o, const char *opt, const char *) { set_mode(o, opt); }},
    {"--short", nullptr, true, "CI mode: one case, few repeats, JSON lines",
     [](Options &o, const char *opt, const char *) { set_mode(o, opt); }},
    {"--callgrind", "EST", true, "EST for --count K estimates at --n, --mismatch, --sigma",
     [](Options &o, const char *opt, const char *v) {
         set_mode(o, opt);
         o.callgrind_est = v;
     }},
    {"--json", nullptr, false, "JSON lines instead of tables",
     [](Options &o, const char *, const char *) { o.json = true; }},
    {"--repeats", "K", false, "timed estimates per record and estimator",
     [](Options &o, const char *opt, const char *v) {
         o.repeats = (int)parse_long(opt, v, 1, 100000);
     }},
    {"--warmup", "K", false, "untimed estimates per estimator before timing",
     [](Options &o, const char *opt, const char *v) {
         o.warmup = (int)parse_long(opt, v, 0, 100000);
     }},
    {"--estimators", "a,b|all", false, "estimators (default: spvs for --cases, all otherwise)",
     set_estimators},
    {"--order", "turns|blocks", false,
     "on each record, estimators take turns repeat by repeat\n"
     "(default), or each runs its repeats back to back",
     [](Options &o, const char *opt, const char *v) {
         o.blocks = parse_choice(opt, v, "turns", "blocks");
     }},
    {"--between", "none|frame", false,
     "untimed work before every timed estimate: nothing\n"
     "(default), or one camera frame's feature extraction\n"
     "(ORB, 500 features, 640x480) after which the matches\n"
     "are handed over afresh: every estimator starts cold",
     [](Options &o, const char *opt, const char *v) {
         o.frame = parse_choice(opt, v, "none", "frame");
     }},
    {"--case", "ID", false,
     "with --generate or --full: only case ID of the matrix\n"
     "(0-71, ((iFamily * 4 + iN) * 3 + iMismatch) * 2 + iSigma;\n"
     "15 = homing, N 200, 20 %, 1 px; 39 = fig5, 63 = grazing)",
     [](Options &o, const char *opt, const char *v) {
         o.only_case = (int)parse_long(opt, v, 0, kCases - 1);
     }},
    {"--family", "F[,F]|all", false,
     "with --generate or --full: only these pose families:\n"
     "homing (P poses along the run from (-3, -10, -30 deg)),\n"
     "fig5 (P along each of the six Figure 5 runs),\n"
     "grazing (the goal image's centre 60-100 deg off the\n"
     "optical axis, P angles at each Figure 5 start)",
     [](Options &o, const char *opt, const char *v) { o.families = parse_families(opt, v); }},
    {"--instances", "I", false, "case generation: random instances per case (8)",
     [](Options &o, const char *opt, const char *v) {
         o.instances = (uint32_t)parse_long(opt, v, 1, 10000);
     }},
    {"--poses", "P", false, "case generation: poses per start (8)",
     [](Options &o, const char *opt, const char *v) {
         o.poses = (uint32_t)parse_long(opt, v, 1, (long)HB_POSE_STRIDE - 1);
     }},
    {"--seed", "S", false, "case generation: seed (1)",
     [](Options &o, const char *opt, const char *v) {
         o.seed = (uint64_t)parse_long(opt, v, 0, 2147483647L);
     }},
    {"--per-record", nullptr, false,
     "also print one JSON line per (record, estimator) on stderr:\n"
     "the pose, its view (off_axis_deg, inliers_over_3px) and\n"
     "the estimator's successes and median corner error",
     [](Options &o, const char *, const char *) { o.per_record = true; }},
    {"--jsonl", "FILE", false, "with --full: also write the JSON lines to FILE",
     [](Options &o, const char *, const char *v) { o.jsonl_path = v; }},
    {"--n", "N", false, "callgrind mode: matches (100)",
     [](Options &o, const char *opt, const char *v) {
         o.n = (uint32_t)parse_long(opt, v, 4, (long)HB_MAX_N);
     }},
    {"--mismatch", "F", false, "callgrind mode: mismatched share (0.2)",
     [](Options &o, const char *opt, const char *v) { o.mismatch = parse_double(opt, v, 0.0, 0.9); }},
    {"--sigma", "PX", false, "callgrind mode: noise, pixels (1)",
     [](Options &o, const char *opt, const char *v) { o.sigma = parse_double(opt, v, 0.0, 100.0); }},
    {"--count", "K", false, "callgrind mode: estimates (1000)",
     [](Options &o, const char *opt, const char *v) {
         o.count = parse_long(opt, v, 0, 100000000L);
     }},
    {"--help", nullptr, false, "this text", nullptr},
};

/* The option column's width in --help (sim_cli_help_option). */
constexpr int kHelpCol = 23;

void print_help()
{
    std::printf("usage: spvs-bench MODE [options]\n");
    for (int section = 0; section < 2; section++) {
        std::printf(section == 0 ? "modes:\n" : "options:\n");
        for (const OptSpec &o : kOpts) {
            if (o.mode != (section == 0))
                continue;
            sim_cli_help_option(stdout, kHelpCol, o.name, o.metavar, o.help);
        }
    }
    std::printf("estimators in this build:");
    for (const auto &e : bench::available_estimators())
        std::printf(" %s", e.c_str());
    std::printf("\n");
}

Options parse(int argc, char **argv)
{
    sim_cli_program("spvs-bench");
    Options o;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!std::strcmp(a, "-h")) {
            print_help();
            std::exit(0);
        }
        const OptSpec *spec = nullptr;
        for (const OptSpec &s : kOpts)
            if (!std::strcmp(a, s.name))
                spec = &s;
        if (spec == nullptr)
            sim_cli_fail("unknown option '%s'", a);
        if (spec->set == nullptr) {
            print_help();
            std::exit(0);
        }
        const char *v = nullptr;
        if (spec->metavar != nullptr) {
            if (i + 1 >= argc)
                sim_cli_fail("%s needs a value", a);
            v = argv[++i];
        }
        spec->set(o, spec->name, v);
    }
    if (o.mode.empty())
        sim_cli_fail("no mode given");
    if (o.only_case >= 0 && o.mode != "--generate" && o.mode != "--full")
        sim_cli_fail("--case goes with --generate or --full");
    const bool all_families =
        std::find(o.families.begin(), o.families.end(), false) == o.families.end();
    if (!all_families && o.mode != "--generate" && o.mode != "--full")
        sim_cli_fail("--family goes with --generate or --full");
    if (o.only_case >= 0 && !o.families[(size_t)(o.only_case / kCellsPerFamily)])
        sim_cli_fail("--case %d is a %s case, outside --family", o.only_case,
                     hb_family_name((uint32_t)(o.only_case / kCellsPerFamily)));
    if (o.mode == "--cases" && !o.json)
        sim_cli_fail("--cases prints JSON lines only: add --json");
    if (o.estimators.empty() || (o.estimators.size() == 1 && o.estimators[0] == "all")) {
        if (o.mode == "--cases" && o.estimators.empty())
            o.estimators = {"spvs"};
        else
            o.estimators = bench::available_estimators();
    }
    for (const auto &e : o.estimators)
        if (!bench::make_estimator(e))
            sim_cli_fail("unknown or unavailable estimator '%s'", e.c_str());
    return o;
}

/* ---- case generation --------------------------------------------------- */

uint64_t record_seed(uint64_t base, uint32_t case_id, uint32_t inst, uint32_t pose)
{
    /* Mix the ids so that neighbouring records get unrelated streams. */
    hb_rng_t r;
    hb_rng_seed(&r, base ^ ((uint64_t)case_id << 40) ^ ((uint64_t)inst << 20) ^ pose);
    return hb_rng_next(&r);
}

/* Every record of one cell: `instances` draws of each of the family's
 * poses (hb_family_pose). */
bool generate_case(hb_set_t &set, uint32_t case_id, uint32_t family, uint32_t n,
                   double mismatch, double sigma, uint32_t instances, uint32_t poses,
                   uint64_t seed)
{
    const uint32_t per = hb_family_poses(family, poses);
    for (uint32_t inst = 0; inst < instances; inst++)
        for (uint32_t k = 0; k < per; k++) {
            hb_record_t &rec = set.rec[set.count];
            double x, z, phi;
            uint32_t pose_id;
            if (hb_family_pose(&set.scene, family, k, poses, &x, &z, &phi, &pose_id) != 0)
                return false;
            if (hb_record_alloc(&rec, n) != 0)
                return false;
            set.count++;
            rec.case_id = case_id;
            rec.instance = inst;
            rec.pose = pose_id;
            if (hb_generate(&set.scene, n, mismatch, sigma, x, z, phi,
                            record_seed(seed, case_id, inst, pose_id), &rec) != 0)
                return false;
        }
    return true;
}

/* The whole matrix over the chosen families, or only case only_case when it
 * is >= 0. */
bool generate_matrix(hb_set_t &set, uint32_t instances, uint32_t poses, uint64_t seed,
                     int only_case, const std::vector<bool> &families)
{
    hb_scene_default(&set.scene);
    size_t total = 0;
    for (uint32_t f = 0; f < HB_FAMILIES; f++)
        if (families[f])
            total += (size_t)kCellsPerFamily * instances * hb_family_poses(f, poses);
    set.rec = (hb_record_t *)std::calloc(total, sizeof(hb_record_t));
    set.count = 0;
    if (!set.rec)
        return false;
    uint32_t id = 0;
    for (uint32_t f = 0; f < HB_FAMILIES; f++)
        for (uint32_t n : kNs)
            for (double m : kMismatch)
                for (double s : kSigma) {
                    const uint32_t case_id = id++;
                    if (!families[f] || (only_case >= 0 && case_id != (uint32_t)only_case))
                        continue;
                    if (!generate_case(set, case_id, f, n, m, s, instances, poses, seed))
                        return false;
                }
    return true;
}

/* ---- timing ------------------------------------------------------------ */

struct Cell {
    uint32_t case_id = 0, n = 0;
    double mismatch = 0, sigma = 0;
    uint32_t records = 0;
    std::vector<double> us;      /* one per timed estimate              */
    std::vector<double> err_px;  /* corner error of estimates returning H */
    std::vector<double> err_tgt; /* the same in target-image pixels       */
    uint32_t estimates = 0, successes = 0, returned = 0;
    /* How the estimates were timed (run_set). */
    const char *order = "turns";
    const char *between = "none";
};

/* Interpolated quantile; infinite when it falls on or next to an infinite
 * value (a failed estimate's error). */
double quantile(std::vector<double> v, double q)
{
    if (v.empty())
        return NAN;
    std::sort(v.begin(), v.end());
    double pos = q * (double)(v.size() - 1);
    size_t lo = (size_t)std::floor(pos);
    size_t hi = std::min(lo + 1, v.size() - 1);
    if (pos == (double)lo)
        return v[lo];
    if (!std::isfinite(v[hi]))
        return v[hi];
    return v[lo] + (pos - (double)lo) * (v[hi] - v[lo]);
}

struct Summary {
    double median_us, q1_us, q3_us, success_rate, mean_err, median_err, mean_err_ok;
    double median_err_all; /* over every estimate, a failed one as infinite */
    double median_err_tgt; /* the same in target-image pixels             */
};

Summary summarise(const Cell &c)
{
    Summary s;
    s.median_us = quantile(c.us, 0.5);
    s.q1_us = quantile(c.us, 0.25);
    s.q3_us = quantile(c.us, 0.75);
    s.success_rate = c.estimates ? (double)c.successes / c.estimates : 0.0;
    double sum = 0, sum_ok = 0;
    size_t n_fin = 0, n_ok = 0;
    for (double e : c.err_px) {
        if (std::isfinite(e)) {
            sum += e;
            n_fin++;
        }
        if (e < 2.0) {
            sum_ok += e;
            n_ok++;
        }
    }
    s.mean_err = n_fin ? sum / n_fin : NAN;
    s.median_err = quantile(c.err_px, 0.5);
    s.mean_err_ok = n_ok ? sum_ok / n_ok : NAN;
    std::vector<double> all = c.err_px;
    all.resize(std::max<size_t>(all.size(), c.estimates), INFINITY);
    s.median_err_all = quantile(all, 0.5);
    all = c.err_tgt;
    all.resize(std::max<size_t>(all.size(), c.estimates), INFINITY);
    s.median_err_tgt = quantile(all, 0.5);
    return s;
}

std::string jnum(double v, const char *fmt = "%.4g")
{
    if (!std::isfinite(v))
        return "null";
    char b[64];
    std::snprintf(b, sizeof b, fmt, v);
    return b;
}

std::string json_line(const std::string &est, const Cell &c)
{
    Summary s = summarise(c);
    const char *family = hb_family_name(c.case_id / (uint32_t)kCellsPerFamily);
    char b[1280];
    std::snprintf(b, sizeof b,
                  "{\"case_id\": %u, \"family\": %s%s%s, \"estimator\": \"%s\", \"N\": %u, "
                  "\"mismatch\": %s, "
                  "\"sigma_px\": %s, \"records\": %u, \"estimates\": %u, \"median_us\": %s, "
                  "\"q1_us\": %s, \"q3_us\": %s, \"iqr_us\": %s, \"success_rate\": %s, "
                  "\"returned_rate\": %s, \"mean_corner_err_px\": %s, "
                  "\"median_corner_err_px\": %s, \"mean_corner_err_ok_px\": %s, "
                  "\"median_corner_err_all_px\": %s, \"median_corner_err_tgt_px\": %s, "
                  "\"order\": \"%s\", \"between\": \"%s\"}",
                  c.case_id, family ? "\"" : "", family ? family : "null", family ? "\"" : "",
                  est.c_str(), c.n, jnum(c.mismatch).c_str(), jnum(c.sigma).c_str(),
                  c.records, c.estimates, jnum(s.median_us).c_str(), jnum(s.q1_us).c_str(),
                  jnum(s.q3_us).c_str(), jnum(s.q3_us - s.q1_us).c_str(),
                  jnum(s.success_rate).c_str(),
                  jnum(c.estimates ? (double)c.returned / c.estimates : 0.0).c_str(),
                  jnum(s.mean_err).c_str(), jnum(s.median_err).c_str(),
                  jnum(s.mean_err_ok).c_str(), jnum(s.median_err_all).c_str(),
                  jnum(s.median_err_tgt).c_str(), c.order, c.between);
    return b;
}

using Results = std::vector<std::pair<uint32_t, std::map<std::string, Cell>>>;

/* Time every estimator on every record.  Records run in file order.  On
 * each record the estimators take turns, repeat by repeat, so that slow
 * drifts of the machine (frequency, other load) hit all of them alike; each
 * estimate then starts where the other estimators have just run (caches and
 * branch predictors hold their code and data).  With `blocks` each
 * estimator instead runs its repeats back to back, as in a loop that runs
 * only it, and the estimators' order turns by one from record to record.
 * With `frame`, one frame's feature extraction (FrameWork) runs before every
 * timed estimate and the estimator's input is prepared again after it, so
 * every estimator starts from the same cold caches and predictors, as on a
 * robot (neither is timed). */
/* One line per (record, estimator) for --per-record: the record's pose and
 * view, and what the estimator made of it over its repeats. */
void print_record_line(const hb_scene_t &sc, const hb_record_t &rec, uint32_t r,
                       const std::string &name, const std::vector<double> &errs,
                       const std::vector<double> &errs_tgt, const std::vector<double> &us,
                       uint32_t estimates)
{
    uint32_t ok = 0;
    for (double e : errs)
        ok += e < 2.0;
    std::vector<double> all = errs;
    all.resize(std::max<size_t>(all.size(), estimates), INFINITY);
    std::vector<double> all_tgt = errs_tgt;
    all_tgt.resize(std::max<size_t>(all_tgt.size(), estimates), INFINITY);
    const char *family = hb_family_name(rec.case_id / (uint32_t)kCellsPerFamily);
    const bool strided = family && rec.case_id >= (uint32_t)kCellsPerFamily;
    std::fprintf(stderr,
                 "{\"record\": %u, \"case_id\": %u, \"family\": %s%s%s, \"instance\": %u, "
                 "\"pose\": %u, \"start\": %s, \"x_m\": %.3f, \"z_m\": %.3f, "
                 "\"phi_deg\": %.2f, \"off_axis_deg\": %s, \"inliers_over_3px\": %.4f, "
                 "\"inliers_over_sampson_99\": %.4f, "
                 "\"N\": %u, \"mismatch\": %s, \"sigma_px\": %s, \"estimator\": \"%s\", "
                 "\"estimates\": %u, \"successes\": %u, \"median_us\": %s, "
                 "\"median_corner_err_all_px\": %s, \"median_corner_err_tgt_px\": %s}\n",
                 r, rec.case_id, family ? "\"" : "", family ? family : "null",
                 family ? "\"" : "", rec.instance, rec.pose,
                 strided ? std::to_string(rec.pose / HB_POSE_STRIDE).c_str() : "null", rec.x_m,
                 rec.z_m, rec.phi_rad * 180.0 / M_PI,
                 jnum(hb_off_axis(&sc, rec.x_m, rec.z_m, rec.phi_rad) * 180.0 / M_PI, "%.2f")
                     .c_str(),
                 hb_inliers_over(&rec, bench::kInlierPx),
                 hb_inliers_over_sampson(&rec, rec.sigma_px, kChi2Two99), rec.n, jnum(rec.mismatch).c_str(),
                 jnum(rec.sigma_px).c_str(), name.c_str(), estimates, ok,
                 jnum(quantile(us, 0.5), "%.2f").c_str(), jnum(quantile(all, 0.5)).c_str(),
                 jnum(quantile(all_tgt, 0.5)).c_str());
}

Results run_set(const hb_set_t &set, const std::vector<std::string> &names, int repeats,
                int warmup, bool per_record, bool blocks, bool frame, bool progress)
{
    using clock = std::chrono::steady_clock;
    std::vector<std::unique_ptr<Estimator>> est;
    for (const auto &n : names)
        est.push_back(bench::make_estimator(n));

    /* Warm-up on the first record: caches, lazy initialisation, branch
     * predictors. */
    double Hw[9];
    for (auto &e : est)
        if (e->prepare(set.rec[0]))
            for (int k = 0; k < warmup; k++)
                (void)e->estimate(Hw);

    std::unique_ptr<bench::FrameWork> work;
    if (frame)
        work.reset(new bench::FrameWork());

    Results res;
    std::map<uint32_t, size_t> pos;
    bool warned_capacity = false;
    for (uint32_t r = 0; r < set.count; r++) {
        const hb_record_t &rec = set.rec[r];
        auto it = pos.find(rec.case_id);
        if (it == pos.end()) {
            it = pos.emplace(rec.case_id, res.size()).first;
            res.emplace_back(rec.case_id, std::map<std::string, Cell>());
            if (progress) {
                const char *family = hb_family_name(rec.case_id / (uint32_t)kCellsPerFamily);
                std::fprintf(stderr,
                             "spvs-bench: case %u (%s, N %u, %.0f %% mismatches, %g px), "
                             "from record %u of %u\n",
                             rec.case_id, family ? family : "?", rec.n, 100.0 * rec.mismatch,
                             rec.sigma_px, r + 1, set.count);
            }
        }
        auto &cells = res[it->second].second;
        std::vector<bool> ready(est.size());
        for (size_t e = 0; e < est.size(); e++) {
            ready[e] = est[e]->prepare(rec);
            if (!ready[e] && !warned_capacity) {
                std::fprintf(stderr, "spvs-bench: note: %s cannot take record %u (N=%u); counted as failed\n",
                             est[e]->name(), r, rec.n);
                warned_capacity = true;
            }
            Cell &c = cells[names[e]];
            if (c.records == 0) {
                c.case_id = rec.case_id;
                c.n = rec.n;
                c.mismatch = rec.mismatch;
                c.sigma = rec.sigma_px;
                c.order = blocks ? "blocks" : "turns";
                c.between = frame ? "frame" : "none";
            }
            c.records++;
        }
        /* Estimate number q of this record: repeat q / n_est of estimator
         * q % n_est (turns), or repeat q % repeats of estimator q / repeats
         * counted from this record's first (blocks). */
        const size_t n_est = est.size();
        const size_t total = n_est * (size_t)repeats;
        /* This record's errors and times, per estimator (--per-record). */
        std::vector<std::vector<double>> rec_err(n_est), rec_tgt(n_est), rec_us(n_est);
        for (size_t q = 0; q < total; q++) {
            const size_t e = blocks ? (q / (size_t)repeats + r) % n_est : q % n_est;
            Cell &c = cells[names[e]];
            c.estimates++;
            if (!ready[e])
                continue;
            double H[9];
            if (work) {
                (void)work->run();
                (void)est[e]->prepare(rec);
            }
            auto t0 = clock::now();
            bool ok = est[e]->estimate(H);
            auto t1 = clock::now();
            c.us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
            rec_us[e].push_back(c.us.back());
            if (!ok)
                continue;
            c.returned++;
            double err = hb_corner_err(&set.scene, rec.H, H);
            c.err_px.push_back(err);
            rec_err[e].push_back(err);
            c.err_tgt.push_back(hb_corner_err_tgt(&set.scene, rec.H, H));
            rec_tgt[e].push_back(c.err_tgt.back());
            if (err < 2.0)
                c.successes++;
        }
        if (per_record)
            for (size_t e = 0; e < n_est; e++)
                print_record_line(set.scene, rec, r, names[e], rec_err[e], rec_tgt[e], rec_us[e],
                                  (uint32_t)repeats);
    }
    return res;
}

void print_json(const Results &res, const std::vector<std::string> &names, FILE *f)
{
    for (const auto &cr : res)
        for (const auto &n : names) {
            auto it = cr.second.find(n);
            if (it != cr.second.end())
                std::fprintf(f, "%s\n", json_line(n, it->second).c_str());
        }
    std::fflush(f);
}

void print_tables(const Results &res, const std::vector<std::string> &names)
{
    std::printf("| N | mismatch | sigma px | estimator | median us | IQR us | success | "
                "median err px | mean err (ok) px | peer/ours time |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto &cr : res) {
        const auto &cells = cr.second;
        auto ours = cells.find("spvs");
        double ours_med = ours != cells.end() ? summarise(ours->second).median_us : NAN;
        for (const auto &n : names) {
            auto it = cells.find(n);
            if (it == cells.end())
                continue;
            const Cell &c = it->second;
            Summary s = summarise(c);
            std::printf("| %u | %.1f | %.0f | %s | %.1f | %.1f | %.1f %% | %s | %s | %s |\n", c.n,
                        c.mismatch, c.sigma, n.c_str(), s.median_us, s.q3_us - s.q1_us,
                        100.0 * s.success_rate, jnum(s.median_err, "%.3f").c_str(),
                        jnum(s.mean_err_ok, "%.3f").c_str(),
                        n == "spvs" ? "1" : jnum(s.median_us / ours_med, "%.1f").c_str());
        }
    }

    /* Compact view: ours against the fastest OpenCV estimator whose success
     * rate is at least ours. */
    std::printf("\n| N | mismatch | sigma px | ours us (success) | fastest OpenCV at >= our success | "
                "its us (success) | speed-up | ours vs cv_ransac |\n");
    std::printf("|---|---|---|---|---|---|---|---|\n");
    for (const auto &cr : res) {
        const auto &cells = cr.second;
        auto ours = cells.find("spvs");
        if (ours == cells.end())
            continue;
        Summary so = summarise(ours->second);
        std::string best;
        Summary sb{};
        double best_us = INFINITY;
        for (const auto &kv : cells) {
            if (kv.first.rfind("cv_", 0) != 0)
                continue;
            Summary s = summarise(kv.second);
            if (s.success_rate + 1e-12 >= so.success_rate && s.median_us < best_us) {
                best_us = s.median_us;
                best = kv.first;
                sb = s;
            }
        }
        auto rans = cells.find("cv_ransac");
        double rans_us = rans != cells.end() ? summarise(rans->second).median_us : NAN;
        const Cell &c = ours->second;
        std::printf("| %u | %.1f | %.0f | %.1f (%.1f %%) | %s | %s | %s | %s |\n", c.n, c.mismatch,
                    c.sigma, so.median_us, 100.0 * so.success_rate,
                    best.empty() ? "none" : best.c_str(),
                    best.empty() ? "-"
                                 : (jnum(sb.median_us, "%.1f") + " (" +
                                    jnum(100.0 * sb.success_rate, "%.1f") + " %)")
                                       .c_str(),
                    best.empty() ? "-" : (jnum(sb.median_us / so.median_us, "%.1f") + "x").c_str(),
                    (jnum(rans_us / so.median_us, "%.1f") + "x").c_str());
    }
}

int mode_callgrind(const Options &o)
{
    /* One estimator, K estimates, cycling over a few records of one case.
     * The records are generated and prepared whatever K is, so a run with
     * K = 0 measures everything but the estimates. */
    hb_set_t set{};
    hb_scene_default(&set.scene);
    const uint32_t poses = 6;
    set.rec = (hb_record_t *)std::calloc(poses, sizeof(hb_record_t));
    if (!set.rec ||
        !generate_case(set, 0, HB_FAMILY_HOMING, o.n, o.mismatch, o.sigma, 1, poses, o.seed)) {
        std::fprintf(stderr, "spvs-bench: case generation failed\n");
        hb_set_free(&set);
        return 1;
    }
    std::vector<std::unique_ptr<Estimator>> est;
    for (uint32_t r = 0; r < set.count; r++) {
        est.push_back(bench::make_estimator(o.callgrind_est));
        if (!est.back()->prepare(set.rec[r])) {
            std::fprintf(stderr, "spvs-bench: %s cannot take N=%u\n", o.callgrind_est.c_str(), o.n);
            hb_set_free(&set);
            return 1;
        }
    }
    long ok = 0;
    for (long k = 0; k < o.count; k++) {
        uint32_t r = (uint32_t)(k % set.count);
        double H[9];
        if (est[r]->estimate(H) && hb_corner_err(&set.scene, set.rec[r].H, H) < 2.0)
            ok++;
    }
    std::printf("{\"estimator\": \"%s\", \"N\": %u, \"estimates\": %ld, \"successes\": %ld}\n",
                o.callgrind_est.c_str(), o.n, o.count, ok);
    hb_set_free(&set);
    return 0;
}

} // namespace

int main(int argc, char **argv)
{
    Options o = parse(argc, argv);
    /* One thread everywhere: OpenCV's own pool off. */
    cv::setNumThreads(1);
    char err[256] = "";

    if (o.mode == "--generate") {
        hb_set_t set{};
        if (!generate_matrix(set, o.instances, o.poses, o.seed, o.only_case, o.families)) {
            std::fprintf(stderr, "spvs-bench: case generation failed\n");
            hb_set_free(&set);
            return 1;
        }
        int rc = hb_write(o.file.c_str(), &set, err, sizeof err);
        if (rc != 0)
            std::fprintf(stderr, "spvs-bench: %s\n", err);
        else
            std::fprintf(stderr, "spvs-bench: wrote %u records to %s\n", set.count, o.file.c_str());
        hb_set_free(&set);
        return rc == 0 ? 0 : 1;
    }
    if (o.mode == "--cases") {
        hb_set_t set{};
        if (hb_read(o.file.c_str(), &set, err, sizeof err) != 0) {
            std::fprintf(stderr, "spvs-bench: %s\n", err);
            return 1;
        }
        Results res = run_set(set, o.estimators, o.repeats > 0 ? o.repeats : 5,
                              o.warmup >= 0 ? o.warmup : 20, o.per_record, o.blocks, o.frame,
                              true);
        print_json(res, o.estimators, stdout);
        hb_set_free(&set);
        return 0;
    }
    if (o.mode == "--full" || o.mode == "--short") {
        hb_set_t set{};
        bool ok;
        if (o.mode == "--short") {
            /* N = 200, 20 % mismatches, 1 px noise: the headline case. */
            hb_scene_default(&set.scene);
            set.rec = (hb_record_t *)std::calloc(2 * 6, sizeof(hb_record_t));
            ok = set.rec && generate_case(set, 15, HB_FAMILY_HOMING, 200, 0.2, 1.0, 2, 6, o.seed);
        } else {
            ok = generate_matrix(set, o.instances, o.poses, o.seed, o.only_case, o.families);
        }
        if (!ok) {
            std::fprintf(stderr, "spvs-bench: case generation failed\n");
            hb_set_free(&set);
            return 1;
        }
        int repeats = o.repeats > 0 ? o.repeats : (o.mode == "--short" ? 3 : 5);
        int warmup = o.warmup >= 0 ? o.warmup : (o.mode == "--short" ? 3 : 20);
        Results res =
            run_set(set, o.estimators, repeats, warmup, o.per_record, o.blocks, o.frame,
                    o.mode == "--full");
        if (!o.jsonl_path.empty()) {
            FILE *f = std::fopen(o.jsonl_path.c_str(), "w");
            if (!f) {
                std::fprintf(stderr, "spvs-bench: cannot write %s\n", o.jsonl_path.c_str());
                hb_set_free(&set);
                return 1;
            }
            print_json(res, o.estimators, f);
            std::fclose(f);
        }
        if (o.json || o.mode == "--short")
            print_json(res, o.estimators, stdout);
        else
            print_tables(res, o.estimators);
        hb_set_free(&set);
        return 0;
    }
    if (o.mode == "--callgrind")
        return mode_callgrind(o);
    return 2;
}
