/*
 * homing.cpp - spvs-bench-homing: the whole-process comparison.
 *
 * One closed-loop homing run of the simulator (sim_host's sim_run: scene,
 * camera, noise, kinematics; DESIGN.md section 5's defaults) is timed end to
 * end twice: with the core's pipeline behind the in-process link
 * (spvs_update), and with a link in which OpenCV's findHomography estimates H
 * while the core's own stages do the rest (spvs_update_with_h: the frame
 * check, the inliers of that H, the off-plane memory and candidates, the
 * epipole and its median, the controller), on the same matches and with the
 * same parameters.  Only the estimate of H differs between the two loops.
 *
 * usage: spvs-bench-homing [--method 1|2|3] [--noise PX] [--outliers F]
 *                          [--seed S] [--runs R] [--cv-method NAME] [--json]
 * Bad options: one line on stderr, exit status 2.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

extern "C" {
#include "sim/cli.h"
#include "sim/link_inproc.h"
#include "sim/sim.h"
#include "spvs/spvs.h"
}

namespace {

/* The OpenCV link: H from cv::findHomography, then the core's pipeline
 * after H (spvs_update_with_h). */
struct CvLink {
    int method = cv::USAC_DEFAULT;
    spvs_params_t p{};
    spvs_t core{};
    std::vector<cv::Point2f> src, dst;
    std::vector<uint8_t> inl;
};

int cv_exchange(void *ctx, uint32_t seq, double t_s, const spvs_match_t *m, uint16_t n,
                spvs_output_t *out, char *err, unsigned err_len)
{
    (void)seq;
    (void)err;
    (void)err_len;
    CvLink &L = *static_cast<CvLink *>(ctx);
    spvs_real H[9];
    bool have = false;
    if (n >= 4 && n <= SPVS_MAX_MATCHES) {
        L.src.resize(n);
        L.dst.resize(n);
        for (uint16_t i = 0; i < n; i++) {
            L.src[i] = cv::Point2f((float)m[i].x_tgt, (float)m[i].y_tgt);
            L.dst[i] = cv::Point2f((float)m[i].x_cur, (float)m[i].y_cur);
        }
        cv::Mat Hm;
        try {
            Hm = cv::findHomography(L.src, L.dst, L.method, (double)spvs_inlier_px(&L.p), L.inl, 2000,
                                    (double)L.p.confidence);
        } catch (const cv::Exception &) {
            Hm.release();
        }
        if (!Hm.empty() && std::fabs(Hm.at<double>(1, 1)) > 1e-12) {
            /* The core's convention: h22 (row 1, column 1) = 1. */
            const double h22 = Hm.at<double>(1, 1);
            for (int k = 0; k < 9; k++)
                H[k] = (spvs_real)(Hm.at<double>(k / 3, k % 3) / h22);
            have = true;
        }
    }
    /* Without an H the core is handed a degenerate one, so that it stops
     * the robot and keeps its frame-time bookkeeping as on any bad frame. */
    if (!have)
        for (int k = 0; k < 9; k++)
            H[k] = std::nan("");
    /* The status travels in out->status, as on every link. */
    const int rc = spvs_update_with_h(&L.core, m, n, (spvs_real)t_s, H, out);
    (void)rc;
    return 0;
}

void cv_close(void *ctx) { delete static_cast<CvLink *>(ctx); }

int cv_method_of(const std::string &name)
{
    if (name == "cv_ransac")
        return cv::RANSAC;
    if (name == "cv_usac_default")
        return cv::USAC_DEFAULT;
    if (name == "cv_usac_fast")
        return cv::USAC_FAST;
    if (name == "cv_usac_accurate")
        return cv::USAC_ACCURATE;
    if (name == "cv_usac_prosac")
        return cv::USAC_PROSAC;
    if (name == "cv_usac_magsac")
        return cv::USAC_MAGSAC;
    return -1;
}

struct Loop {
    std::string name;
    std::vector<double> wall_ms;
    sim_result_t res{};
};

} // namespace

int main(int argc, char **argv)
{
    sim_config_t cfg;
    sim_config_default(&cfg);
    int runs = 5;
    bool json = false;
    std::string cv_name = "cv_usac_default";
    sim_cli_program("spvs-bench-homing");
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        auto val = [&]() -> const char * {
            if (i + 1 >= argc)
                sim_cli_fail("%s needs a value", a);
            return argv[++i];
        };
        if (!std::strcmp(a, "--method"))
            cfg.method = (int)sim_cli_int(a, val(), 1, 3);
        else if (!std::strcmp(a, "--noise"))
            cfg.noise_px = sim_cli_real(a, val(), 0, 100, SIM_CLI_CLOSED);
        else if (!std::strcmp(a, "--outliers"))
            cfg.outliers = sim_cli_real(a, val(), 0, 0.9, SIM_CLI_CLOSED);
        else if (!std::strcmp(a, "--seed"))
            cfg.seed = (uint64_t)sim_cli_int(a, val(), 0, 4294967295LL);
        else if (!std::strcmp(a, "--runs"))
            runs = (int)sim_cli_int(a, val(), 1, 1000);
        else if (!std::strcmp(a, "--cv-method"))
            cv_name = val();
        else if (!std::strcmp(a, "--json"))
            json = true;
        else if (!std::strcmp(a, "--help")) {
            std::printf("usage: spvs-bench-homing [--method 1|2|3] [--noise PX] [--outliers F] "
                        "[--seed S] [--runs R] [--cv-method NAME] [--json]\n");
            return 0;
        } else
            sim_cli_fail("unknown option '%s'", a);
    }
    const int cv_method = cv_method_of(cv_name);
    if (cv_method < 0)
        sim_cli_fail("unknown --cv-method '%s'", cv_name.c_str());
    char err[256] = "";
    if (sim_config_check(&cfg, err, sizeof err) != 0)
        sim_cli_fail("%s", err);
    cv::setNumThreads(1);

    spvs_params_t p;
    sim_inproc_params(&p, cfg.method, cfg.focal_assumed_mm / cfg.pixel_mm, (uint32_t)cfg.seed);

    Loop loops[2];
    loops[0].name = "spvs";
    loops[1].name = cv_name;
    /* One untimed run of each warms caches and OpenCV's lazy set-up; then the
     * two loops alternate so that machine drift hits both alike. */
    for (int k = -1; k < runs; k++)
        for (int li = 0; li < 2; li++) {
            sim_link_t link;
            if (li == 0) {
                if (sim_link_inproc_open(&p, &link, err, sizeof err) != 0) {
                    std::fprintf(stderr, "spvs-bench-homing: %s\n", err);
                    return 1;
                }
            } else {
                CvLink *L = new CvLink();
                L->method = cv_method;
                L->p = p;
                if (spvs_init(&L->core, &p) != SPVS_OK) {
                    std::fprintf(stderr, "spvs-bench-homing: parameters rejected\n");
                    delete L;
                    return 1;
                }
                link.ctx = L;
                link.exchange = cv_exchange;
                link.close = cv_close;
            }
            sim_result_t res;
            auto t0 = std::chrono::steady_clock::now();
            int rc = sim_run(&cfg, &link, &res, nullptr, nullptr, err, sizeof err);
            auto t1 = std::chrono::steady_clock::now();
            link.close(link.ctx);
            if (rc != 0) {
                std::fprintf(stderr, "spvs-bench-homing: %s\n", err);
                return 1;
            }
            if (k >= 0) {
                loops[li].wall_ms.push_back(
                    std::chrono::duration<double, std::milli>(t1 - t0).count());
                loops[li].res = res;
            }
        }

    double med[2];
    if (!json) {
        std::printf("| loop | status | frames | final x m | final z m | final phi deg | "
                    "wall ms (median of %d) | min..max ms | us/frame |\n", runs);
        std::printf("|---|---|---|---|---|---|---|---|---|\n");
    }
    for (int li = 0; li < 2; li++) {
        auto w = loops[li].wall_ms;
        std::sort(w.begin(), w.end());
        med[li] = w[w.size() / 2];
        const sim_result_t &r = loops[li].res;
        if (json)
            std::printf("{\"loop\": \"%s\", \"method\": %d, \"noise_px\": %g, \"outliers\": %g, "
                        "\"status\": \"%s\", \"frames\": %u, \"final_error\": {\"x_m\": %.5f, "
                        "\"z_m\": %.5f, \"phi_deg\": %.4f}, \"wall_ms_median\": %.3f, "
                        "\"wall_ms_min\": %.3f, \"wall_ms_max\": %.3f, \"runs\": %d}\n",
                        loops[li].name.c_str(), cfg.method, cfg.noise_px, cfg.outliers,
                        sim_status_str(r.status), r.frames, r.err_x_m, r.err_z_m, r.err_phi_deg,
                        med[li], w.front(), w.back(), runs);
        else
            std::printf("| %s | %s | %u | %.4f | %.4f | %.3f | %.1f | %.1f..%.1f | %.1f |\n",
                        loops[li].name.c_str(), sim_status_str(r.status), r.frames, r.err_x_m,
                        r.err_z_m, r.err_phi_deg, med[li], w.front(), w.back(),
                        1e3 * med[li] / (r.frames ? r.frames : 1));
    }
    if (!json)
        std::printf("\nwhole run, %s / spvs wall time: %.1fx\n", cv_name.c_str(), med[1] / med[0]);
    return 0;
}
