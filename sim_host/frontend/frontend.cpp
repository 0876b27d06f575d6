/* frontend.cpp - features (SIFT by default, or ORB), ratio-test matching
 * and the C interface of the image front end (sim/frontend.h). */
#include "sim/frontend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "features.hpp"
#include "frontend_internal.hpp"
#include "sim/clock.h"
#include "spvs/spvs_config.h"

namespace {

constexpr int kMinTargetFeatures = 16;
constexpr int kSiftLayers = 3;  /* OpenCV's and Lowe's default      */
constexpr int kMaxLevels = 16;
constexpr int kGridX = 8; /* target keypoint spreading grid */
constexpr int kGridY = 6;
constexpr uint32_t kTargetSeq = 0xffffffffu; /* sensor noise of the target */

/* Milliseconds since t0_s on the edge's monotonic clock (sim/clock.h). */
double ms_since(double t0_s)
{
    return (sim_clock_now_s() - t0_s) * 1e3;
}

void set_err(char *err, unsigned len, const char *msg)
{
    if (err != nullptr && len > 0) {
        std::snprintf(err, len, "%s", msg);
    }
}

} // namespace

struct sim_frontend {
    sim_frontend_params_t p;
    simfe::Scene scene;
    cv::Ptr<cv::Feature2D> det_tgt;
    cv::Ptr<cv::Feature2D> det_cur;
    int norm = cv::NORM_HAMMING;   /* descriptor distance            */

    cv::Mat img_tgt;
    std::vector<cv::KeyPoint> kp_tgt;
    cv::Mat desc_tgt;
    std::vector<cv::Vec3d> X_tgt;  /* ray-cast 3D point of each feature */
    std::vector<int> hit_tgt;      /* surface index, -1 for none        */

    cv::Mat img_cur;
    std::vector<cv::KeyPoint> kp_cur;
    cv::Mat desc_cur;
    std::vector<cv::DMatch> kept;  /* queryIdx: current, trainIdx: target */
    std::vector<uint8_t> kept_bad;
    bool have_cur = false;

    cv::Mat mapx, mapy, depth;     /* render work buffers */
    sim_frontend_frame_stats_t last{};
    sim_frontend_totals_t tot{};
};

namespace {

/* Render at `pose` with the sensor noise of frame `seq`. */
void render_frame(sim_frontend *f, const sim_pose_t &pose, uint32_t seq,
                  cv::Mat &img)
{
    f->scene.render(pose, img, f->mapx, f->mapy, f->depth);
    if (f->p.image_noise > 0.0) {
        cv::Mat noise(img.size(), CV_16S);
        cv::RNG rng(f->p.seed * 0x9e3779b97f4a7c15ULL + seq + 1u);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, f->p.image_noise);
        cv::Mat sum;
        img.convertTo(sum, CV_16S);
        sum += noise;
        sum.convertTo(img, CV_8U); /* saturates to 0..255 */
    }
}

/* The image the detector works on: the image itself, or (detect_half) its
 * half made with pixel-area averaging. */
const cv::Mat &detector_image(const sim_frontend *f, const cv::Mat &img,
                              cv::Mat &half)
{
    if (!f->p.detect_half) {
        return img;
    }
    cv::resize(img, half, cv::Size(img.cols / 2, img.rows / 2), 0, 0,
               cv::INTER_AREA);
    return half;
}

/* Keypoints between the detector's image and the full image: half-image
 * pixel i averages full pixels 2i and 2i + 1, centred at 2i + 0.5. */
void keypoints_to_full(const sim_frontend *f, std::vector<cv::KeyPoint> &kp)
{
    if (!f->p.detect_half) {
        return;
    }
    for (cv::KeyPoint &k : kp) {
        k.pt = k.pt * 2.0f + cv::Point2f(0.5f, 0.5f);
        k.size *= 2.0f;
    }
}

void keypoints_to_half(const sim_frontend *f, std::vector<cv::KeyPoint> &kp)
{
    if (!f->p.detect_half) {
        return;
    }
    for (cv::KeyPoint &k : kp) {
        k.pt = (k.pt - cv::Point2f(0.5f, 0.5f)) * 0.5f;
        k.size *= 0.5f;
    }
}

/* Keypoints of the target image: the strongest keypoints spread over a
 * grid of kGridX x kGridY cells (each cell keeps its best share first, the
 * rest goes to the strongest left over), at most target_features, then
 * described.  Spreading them keeps features near the image borders, which
 * are all that stays in view when the robot looks far to one side. */
bool describe_target(sim_frontend *f)
{
    std::vector<cv::KeyPoint> all;
    cv::Mat half;
    const cv::Mat &dimg = detector_image(f, f->img_tgt, half);
    f->det_tgt->detect(dimg, all);
    keypoints_to_full(f, all);
    std::stable_sort(all.begin(), all.end(),
                     [](const cv::KeyPoint &a, const cv::KeyPoint &b) {
                         return a.response > b.response;
                     });
    std::vector<cv::Point2f> pts;
    pts.reserve(all.size());
    for (const cv::KeyPoint &k : all) {
        pts.push_back(k.pt);
    }
    std::vector<cv::KeyPoint> kp;
    for (size_t i : simfe::spread_best(pts, (size_t)f->p.target_features,
                                       cv::Size(SIM_FRONTEND_WIDTH,
                                                SIM_FRONTEND_HEIGHT),
                                       kGridX, kGridY)) {
        kp.push_back(all[i]);
    }
    keypoints_to_half(f, kp);
    f->det_tgt->compute(dimg, kp, f->desc_tgt);
    keypoints_to_full(f, kp);
    if (f->p.subpixel) {
        simfe::refine_corners(f->img_tgt, kp);
    }
    f->kp_tgt = kp;
    if ((int)kp.size() < kMinTargetFeatures) {
        return false;
    }
    const sim_pose_t origin = { 0.0, 0.0, 0.0 };
    f->X_tgt.assign(kp.size(), cv::Vec3d(0, 0, 0));
    f->hit_tgt.assign(kp.size(), -1);
    for (size_t i = 0; i < kp.size(); ++i) {
        double X[3];
        int s = f->scene.cast(origin, kp[i].pt.x - SIM_FRONTEND_WIDTH / 2.0,
                              kp[i].pt.y - SIM_FRONTEND_HEIGHT / 2.0, X);
        f->hit_tgt[i] = s;
        if (s >= 0) {
            f->X_tgt[i] = cv::Vec3d(X[0], X[1], X[2]);
        }
    }
    return true;
}

/* Current -> target matches that pass the ratio test (and the mutual best
 * check), one per target feature, best max_matches by descriptor distance
 * (simfe::match_descriptors). */
void match(sim_frontend *f)
{
    std::vector<cv::DMatch> cand;
    simfe::match_descriptors(f->desc_cur, f->desc_tgt, f->norm, f->p.ratio,
                             f->p.cross_check != 0, cand);
    if ((int)cand.size() > f->p.max_matches) {
        cand.resize((size_t)f->p.max_matches);
    }
    f->kept = cand;
}

} // namespace

extern "C" {

void sim_frontend_params_default(sim_frontend_params_t *p)
{
    p->seed = 0;
    p->n_objects = 10;
    p->obj_zmin_m = 12.0;
    p->obj_zmax_m = 35.0;
    p->target_features = 500;
    p->current_features = 1500;
    p->ratio = 0.7;
    p->cross_check = 1;
    p->max_matches = SPVS_MAX_MATCHES;
    p->mismatch_px = 3.0;
    p->image_noise = 1.5;
    p->subpixel = 1;
    p->detector = SIM_FRONTEND_SIFT;
    p->levels = kSiftLayers;
    p->detect_half = 1;
    p->texture = nullptr;
}

/* The parameters and camera checked: "" when usable, else why not
 * (into msg, msg_len bytes). */
static void check_params(const sim_frontend_params_t *p, const sim_camera_t *cam, char *msg,
                         size_t msg_len)
{
    if (p->n_objects < 0 || p->n_objects > SIM_FRONTEND_MAX_OBJECTS) {
        std::snprintf(msg, msg_len, "front end: objects must be 0..%d, got %d",
                      SIM_FRONTEND_MAX_OBJECTS, p->n_objects);
    } else if (!(p->obj_zmin_m > SIM_MIN_DEPTH_M) ||
               !(p->obj_zmax_m > p->obj_zmin_m) || !std::isfinite(p->obj_zmax_m)) {
        std::snprintf(msg, msg_len,
                      "front end: object depths need 0.1 < zmin < zmax, finite");
    } else if (p->target_features < kMinTargetFeatures ||
               p->target_features > SPVS_MAX_FEATURES) {
        std::snprintf(msg, msg_len,
                      "front end: target features must be %d..%d, got %d",
                      kMinTargetFeatures, SPVS_MAX_FEATURES, p->target_features);
    } else if (p->current_features < 16 || p->current_features > 20000) {
        std::snprintf(msg, msg_len,
                      "front end: current features must be 16..20000, got %d",
                      p->current_features);
    } else if (!(p->ratio > 0.0 && p->ratio <= 1.0)) {
        std::snprintf(msg, msg_len, "front end: ratio must be in (0, 1]");
    } else if (p->max_matches < 1 || p->max_matches > SPVS_MAX_MATCHES) {
        std::snprintf(msg, msg_len,
                      "front end: max matches must be 1..%d, got %d",
                      SPVS_MAX_MATCHES, p->max_matches);
    } else if (!(p->mismatch_px > 0.0) || !std::isfinite(p->mismatch_px) ||
               !(p->image_noise >= 0.0) || !std::isfinite(p->image_noise)) {
        std::snprintf(msg, msg_len,
                      "front end: mismatch distance and noise must be finite, >= 0");
    } else if (p->detector != SIM_FRONTEND_ORB &&
               p->detector != SIM_FRONTEND_SIFT &&
               p->detector != SIM_FRONTEND_AKAZE) {
        std::snprintf(msg, msg_len,
                      "front end: detector must be ORB, SIFT or AKAZE, got %d",
                      p->detector);
    } else if (p->levels < 1 || p->levels > kMaxLevels ||
               (p->detect_half != 0 && p->detect_half != 1)) {
        std::snprintf(msg, msg_len,
                      "front end: levels must be 1..%d and detect_half 0 or 1",
                      kMaxLevels);
    } else if (cam->width_px != SIM_FRONTEND_WIDTH ||
               cam->height_px != SIM_FRONTEND_HEIGHT ||
               !(cam->alpha_x_px > 0.0) || !(cam->alpha_y_px > 0.0)) {
        std::snprintf(msg, msg_len,
                      "front end: the camera must be 640x480 with positive focal");
    } else {
        msg[0] = '\0';
    }
}

sim_frontend_t *sim_frontend_create(const sim_frontend_params_t *p,
                                    const sim_camera_t *cam,
                                    const sim_plane_t *pl, char *err,
                                    unsigned err_len)
{
    if (p == nullptr || cam == nullptr || pl == nullptr) {
        set_err(err, err_len, "front end: no parameters, camera or plane");
        return nullptr;
    }
    char msg[200];
    check_params(p, cam, msg, sizeof(msg));
    if (msg[0] != '\0') {
        set_err(err, err_len, msg);
        return nullptr;
    }

    sim_frontend *f = nullptr;
    try {
        f = new sim_frontend();
        f->p = *p;
        std::string why = f->scene.build(*cam, *pl, p->seed, p->n_objects,
                                         p->obj_zmin_m, p->obj_zmax_m,
                                         p->texture ? p->texture : "");
        if (!why.empty()) {
            std::snprintf(msg, sizeof(msg), "front end: %s", why.c_str());
            set_err(err, err_len, msg);
            delete f;
            return nullptr;
        }
        /* The target asks for six times what it keeps, so that the
         * spreading grid has corners to choose from in every cell.
         * SIFT (the default): its descriptor, a histogram of gradient
         * orientations pooled over a 4 x 4 grid, changes slowly under the
         * foreshortening that a turn of 30..60 deg in front of an oblique
         * plane brings; ORB's binary tests of pixel pairs do not, and
         * from the Figure 5 poses ORB keeps too few plane matches (see
         * docs/RESULTS_IMAGES.md).  Detecting on the halved image
         * (detect_half) skips SIFT's costly doubled first octave and keeps
         * the blobs of 2 px and more that survive the approach; the matched
         * points are then refined on the full image. */
        if (p->detector == SIM_FRONTEND_SIFT) {
            f->det_tgt = cv::SIFT::create(p->target_features * 6, p->levels);
            f->det_cur = cv::SIFT::create(p->current_features, p->levels);
            f->norm = cv::NORM_L2;
        } else if (p->detector == SIM_FRONTEND_AKAZE) {
            f->det_tgt = cv::AKAZE::create();
            f->det_cur = cv::AKAZE::create();
        } else {
            /* levels of 1.2: four span a 2x change of scale. */
            f->det_tgt = cv::ORB::create(p->target_features * 6, 1.2f,
                                         p->levels);
            f->det_cur = cv::ORB::create(p->current_features, 1.2f, p->levels);
        }
        const sim_pose_t origin = { 0.0, 0.0, 0.0 };
        render_frame(f, origin, kTargetSeq, f->img_tgt);
        if (!describe_target(f)) {
            std::snprintf(msg, sizeof(msg),
                          "front end: the target image gives %zu features, "
                          "fewer than %d (is the plane in view?)",
                          f->kp_tgt.size(), kMinTargetFeatures);
            set_err(err, err_len, msg);
            delete f;
            return nullptr;
        }
        f->tot.min_matches = UINT16_MAX;
        return f;
    } catch (const std::exception &e) {
        std::snprintf(msg, sizeof(msg), "front end: %s", e.what());
        set_err(err, err_len, msg);
        delete f;
        return nullptr;
    }
}

void sim_frontend_destroy(sim_frontend_t *f)
{
    delete f;
}

uint16_t sim_frontend_observe(sim_frontend_t *f, uint32_t seq,
                              const sim_pose_t *pose, sim_obs_t *obs,
                              uint16_t cap, sim_frontend_frame_stats_t *st)
{
    if (f == nullptr || pose == nullptr || obs == nullptr) {
        return 0;
    }
    sim_frontend_frame_stats_t s{};
    s.seq = seq;
    uint16_t n = 0;
    if (!std::isfinite(pose->x_m) || !std::isfinite(pose->z_m) ||
        !std::isfinite(pose->phi_rad)) {
        f->have_cur = false;
        f->kept.clear();
    } else {
        try {
            double t0 = sim_clock_now_s();
            render_frame(f, *pose, seq, f->img_cur);
            s.render_ms = ms_since(t0);
            t0 = sim_clock_now_s();
            f->kp_cur.clear();
            cv::Mat half;
            f->det_cur->detectAndCompute(detector_image(f, f->img_cur, half),
                                         cv::noArray(), f->kp_cur, f->desc_cur);
            keypoints_to_full(f, f->kp_cur);
            match(f);
            if (f->p.subpixel) {
                /* Only the matched keypoints need it. */
                std::vector<cv::KeyPoint> km;
                for (const cv::DMatch &m : f->kept) {
                    km.push_back(f->kp_cur[(size_t)m.queryIdx]);
                }
                simfe::refine_corners(f->img_cur, km);
                for (size_t i = 0; i < km.size(); ++i) {
                    f->kp_cur[(size_t)f->kept[i].queryIdx].pt = km[i].pt;
                }
            }
            s.match_ms = ms_since(t0);
            f->have_cur = true;
        } catch (const std::exception &) {
            /* An OpenCV failure on one frame is a frame without matches:
             * the controller then stops safely. */
            f->have_cur = false;
            f->kept.clear();
        }
        s.n_keypoints = (uint16_t)std::min<size_t>(f->kp_cur.size(), UINT16_MAX);
    }

    f->kept_bad.assign(f->kept.size(), 0);
    const double cx = SIM_FRONTEND_WIDTH / 2.0, cy = SIM_FRONTEND_HEIGHT / 2.0;
    for (size_t i = 0; i < f->kept.size() && n < cap; ++i) {
        const cv::DMatch &m = f->kept[i];
        const cv::KeyPoint &kt = f->kp_tgt[(size_t)m.trainIdx];
        const cv::KeyPoint &kc = f->kp_cur[(size_t)m.queryIdx];
        sim_obs_t &o = obs[n];
        o.feature = (uint16_t)m.trainIdx;
        o.x_tgt = kt.pt.x - cx;
        o.y_tgt = kt.pt.y - cy;
        o.x_cur = kc.pt.x - cx;
        o.y_cur = kc.pt.y - cy;
        int hit = f->hit_tgt[(size_t)m.trainIdx];
        o.on_plane = hit == 0 ? 1 : 0;
        /* The truth: where the feature's 3D point projects in this camera. */
        bool bad = true;
        if (hit >= 0) {
            const cv::Vec3d &X = f->X_tgt[(size_t)m.trainIdx];
            double Xa[3] = { X[0], X[1], X[2] }, p[2];
            if (sim_project(&f->scene.cam, pose, Xa, p, nullptr) == 0) {
                bad = std::hypot(p[0] - o.x_cur, p[1] - o.y_cur) >
                      f->p.mismatch_px;
            }
        }
        o.mismatched = bad ? 1 : 0;
        f->kept_bad[i] = o.mismatched;
        s.n_mismatches = (uint16_t)(s.n_mismatches + o.mismatched);
        s.n_offplane = (uint16_t)(s.n_offplane + (o.on_plane ? 0 : 1));
        ++n;
    }
    f->kept.resize(n);
    f->kept_bad.resize(n);
    s.n_matches = n;

    f->last = s;
    sim_frontend_totals_t &t = f->tot;
    t.frames++;
    t.matches += n;
    t.mismatches += s.n_mismatches;
    t.min_matches = std::min(t.min_matches, n);
    t.max_matches = std::max(t.max_matches, n);
    if (n > 0) {
        t.max_mismatch_rate =
            std::max(t.max_mismatch_rate, (double)s.n_mismatches / n);
    }
    t.render_ms += s.render_ms;
    t.match_ms += s.match_ms;
    if (st != nullptr) {
        *st = s;
    }
    return n;
}

uint16_t sim_frontend_observe_cb(void *user, uint32_t seq,
                                 const sim_world_t *w, const sim_pose_t *pose,
                                 sim_obs_t *obs, uint16_t cap)
{
    (void)w;
    return sim_frontend_observe((sim_frontend_t *)user, seq, pose, obs, cap,
                                nullptr);
}

void sim_frontend_last(const sim_frontend_t *f, sim_frontend_frame_stats_t *st)
{
    *st = f->last;
}

void sim_frontend_totals(const sim_frontend_t *f, sim_frontend_totals_t *t)
{
    *t = f->tot;
    if (t->frames == 0) {
        t->min_matches = 0;
    }
}

void sim_frontend_reset_totals(sim_frontend_t *f)
{
    f->tot = sim_frontend_totals_t{};
    f->tot.min_matches = UINT16_MAX;
}

uint16_t sim_frontend_target_count(const sim_frontend_t *f)
{
    return (uint16_t)f->kp_tgt.size();
}

int sim_frontend_target_point(const sim_frontend_t *f, uint16_t i,
                              double p_tgt[2], double X[3], int *on_plane)
{
    if (f == nullptr || i >= f->kp_tgt.size() || f->hit_tgt[i] < 0) {
        return -1;
    }
    p_tgt[0] = f->kp_tgt[i].pt.x - SIM_FRONTEND_WIDTH / 2.0;
    p_tgt[1] = f->kp_tgt[i].pt.y - SIM_FRONTEND_HEIGHT / 2.0;
    for (int k = 0; k < 3; ++k) {
        X[k] = f->X_tgt[i][k];
    }
    if (on_plane != nullptr) {
        *on_plane = f->hit_tgt[i] == 0 ? 1 : 0;
    }
    return 0;
}

static int write_png(const cv::Mat &img, const char *path, char *err,
                     unsigned err_len)
{
    char msg[300];
    try {
        if (path != nullptr && cv::imwrite(path, img)) {
            return 0;
        }
    } catch (const std::exception &) {
        /* reported below */
    }
    std::snprintf(msg, sizeof(msg), "cannot write the image '%s'",
                  path ? path : "(null)");
    set_err(err, err_len, msg);
    return -1;
}

int sim_frontend_save_target(const sim_frontend_t *f, const char *path,
                             char *err, unsigned err_len)
{
    return write_png(f->img_tgt, path, err, err_len);
}

int sim_frontend_save_frame(const sim_frontend_t *f, const char *path,
                            char *err, unsigned err_len)
{
    if (!f->have_cur) {
        set_err(err, err_len, "no frame rendered yet");
        return -1;
    }
    return write_png(f->img_cur, path, err, err_len);
}

int sim_frontend_save_matches(const sim_frontend_t *f, const char *path,
                              char *err, unsigned err_len)
{
    if (!f->have_cur) {
        set_err(err, err_len, "no frame rendered yet");
        return -1;
    }
    cv::Mat both, tgt, cur;
    cv::cvtColor(f->img_tgt, tgt, cv::COLOR_GRAY2BGR);
    cv::cvtColor(f->img_cur, cur, cv::COLOR_GRAY2BGR);
    cv::hconcat(tgt, cur, both);
    const cv::Point2f shift((float)SIM_FRONTEND_WIDTH, 0.0f);
    /* Correct matches first, mismatches on top so that they stay visible. */
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t i = 0; i < f->kept.size(); ++i) {
            if (f->kept_bad[i] != pass) {
                continue;
            }
            const cv::Point2f a = f->kp_tgt[(size_t)f->kept[i].trainIdx].pt;
            const cv::Point2f b = f->kp_cur[(size_t)f->kept[i].queryIdx].pt + shift;
            const cv::Scalar col = pass ? cv::Scalar(0, 0, 255)
                                        : cv::Scalar(0, 200, 0);
            cv::line(both, a, b, col, 1, cv::LINE_AA);
            cv::circle(both, a, 3, col, 1, cv::LINE_AA);
            cv::circle(both, b, 3, col, 1, cv::LINE_AA);
        }
    }
    return write_png(both, path, err, err_len);
}

int sim_frontend_opencv_h(const sim_obs_t *obs, uint16_t n, double thresh_px,
                          double H[9])
{
    if (obs == nullptr || n < 4 || !(thresh_px > 0.0)) {
        return -1;
    }
    try {
        std::vector<cv::Point2d> src, dst;
        for (uint16_t i = 0; i < n; ++i) {
            src.emplace_back(obs[i].x_tgt, obs[i].y_tgt);
            dst.emplace_back(obs[i].x_cur, obs[i].y_cur);
        }
        cv::Mat Hm = cv::findHomography(src, dst, cv::RANSAC, thresh_px);
        if (Hm.empty() || std::fabs(Hm.at<double>(2, 2)) < 1e-12) {
            return -1;
        }
        for (int i = 0; i < 9; ++i) {
            H[i] = Hm.at<double>(i / 3, i % 3) / Hm.at<double>(2, 2);
        }
        return 0;
    } catch (const std::exception &) {
        return -1;
    }
}

} // extern "C"
