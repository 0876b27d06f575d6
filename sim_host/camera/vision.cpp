/* vision.cpp - intrinsics, goal features and per-frame matches
 * (vision.hpp). */
#include "vision.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "features.hpp"
#include "sim/clock.h"

namespace spvscam {

namespace {

constexpr int kGridX = 8;   /* spreading grid of goal features and matches */
constexpr int kGridY = 6;
constexpr int kSiftLayers = 3;
constexpr int kHalfMinWidth = 600;
/* Teach: the goal's features must reach this many cells of a 4 x 3 grid. */
constexpr int kTeachCellsX = 4;
constexpr int kTeachCellsY = 3;
constexpr int kTeachMinCells = 9;
constexpr int kTeachMinPerCell = 3;

double ms_since(double t0_s)
{
    return (sim_clock_now_s() - t0_s) * 1e3;
}

} // namespace

void Intrinsics::from_focal(double f_px, cv::Size sz)
{
    K = cv::Matx33d(f_px, 0.0, sz.width / 2.0, 0.0, f_px, sz.height / 2.0,
                    0.0, 0.0, 1.0);
    dist.release();
    width = height = 0;
}

std::string Intrinsics::from_file(const std::string &path)
{
    std::FILE *probe = std::fopen(path.c_str(), "rb");
    if (probe == nullptr) {
        return "cannot read the calibration file '" + path + "'";
    }
    std::fclose(probe);
    try {
        cv::FileStorage fs(path, cv::FileStorage::READ);
        if (!fs.isOpened()) {
            return "cannot read the calibration file '" + path + "'";
        }
        cv::Mat k, d;
        fs["camera_matrix"] >> k;
        fs["distortion_coefficients"] >> d;
        if (k.rows != 3 || k.cols != 3) {
            return "'" + path + "' has no 3x3 camera_matrix";
        }
        k.convertTo(k, CV_64F);
        K = cv::Matx33d((const double *)k.data);
        if (!(K(0, 0) > 0.0) || !(K(1, 1) > 0.0) || !std::isfinite(K(0, 2)) ||
            !std::isfinite(K(1, 2))) {
            return "'" + path + "': camera_matrix needs positive focal lengths";
        }
        dist.release();
        if (!d.empty()) {
            d.convertTo(dist, CV_64F);
        }
        width = height = 0;
        if (!fs["image_width"].empty()) {
            fs["image_width"] >> width;
            fs["image_height"] >> height;
        }
    } catch (const std::exception &e) {
        return "cannot read the calibration file '" + path + "': " + e.what();
    }
    return "";
}

void Intrinsics::centre(const std::vector<cv::Point2f> &px,
                        std::vector<cv::Point2f> &out) const
{
    out.resize(px.size());
    if (px.empty()) {
        return;
    }
    std::vector<cv::Point2f> u;
    const std::vector<cv::Point2f> *src = &px;
    if (!dist.empty()) {
        /* Undistorted and mapped back through K: pixels of the ideal
         * pinhole camera with the same K. */
        cv::undistortPoints(px, u, cv::Mat(K), dist, cv::noArray(),
                            cv::Mat(K));
        src = &u;
    }
    const float cx = (float)K(0, 2), cy = (float)K(1, 2);
    for (size_t i = 0; i < px.size(); ++i) {
        out[i] = (*src)[i] - cv::Point2f(cx, cy);
    }
}

void Vision::detect(const cv::Ptr<cv::Feature2D> &det, const cv::Mat &img,
                    std::vector<cv::KeyPoint> &kp, cv::Mat *desc) const
{
    /* As in the simulator's front end: on the halved image SIFT skips its
     * costly doubled first octave; keypoints are mapped back (half-image
     * pixel i averages full pixels 2i and 2i + 1). */
    cv::Mat half;
    const cv::Mat *d = &img;
    if (half_) {
        cv::resize(img, half, cv::Size(img.cols / 2, img.rows / 2), 0, 0,
                   cv::INTER_AREA);
        d = &half;
    }
    if (desc != nullptr) {
        det->detectAndCompute(*d, cv::noArray(), kp, *desc);
    } else {
        det->detect(*d, kp);
    }
    if (half_) {
        for (cv::KeyPoint &k : kp) {
            k.pt = k.pt * 2.0f + cv::Point2f(0.5f, 0.5f);
            k.size *= 2.0f;
        }
    }
}

void Vision::goal_like_keypoints(const cv::Mat &img,
                                 std::vector<cv::KeyPoint> &kp) const
{
    std::vector<cv::KeyPoint> all;
    detect(det_goal_, img, all, nullptr);
    std::stable_sort(all.begin(), all.end(),
                     [](const cv::KeyPoint &a, const cv::KeyPoint &b) {
                         return a.response > b.response;
                     });
    std::vector<cv::Point2f> pts;
    for (const cv::KeyPoint &k : all) {
        pts.push_back(k.pt);
    }
    kp.clear();
    for (size_t i : simfe::spread_best(pts, (size_t)p_.goal_features,
                                       img.size(), kGridX, kGridY)) {
        kp.push_back(all[i]);
    }
}

std::string Vision::set_goal(const cv::Mat &goal, const Intrinsics &in,
                             const VisionParams &p)
{
    p_ = p;
    in_ = in;
    size_ = goal.size();
    if (in.width > 0 && (in.width != size_.width || in.height != size_.height)) {
        char msg[160];
        std::snprintf(msg, sizeof(msg),
                      "the calibration is for %dx%d images, the goal is %dx%d",
                      in.width, in.height, size_.width, size_.height);
        return msg;
    }
    half_ = p.half == 1 || (p.half < 0 && goal.cols >= kHalfMinWidth);
    /* The goal asks for six times what it keeps, so that the spreading
     * grid has features to choose from in every cell. */
    det_goal_ = cv::SIFT::create(p.goal_features * 6, kSiftLayers);
    det_frame_ = cv::SIFT::create(p.frame_features, kSiftLayers);
    goal_like_keypoints(goal, kp_goal_);
    if ((int)kp_goal_.size() < kMinGoalFeatures) {
        char msg[160];
        std::snprintf(msg, sizeof(msg),
                      "the goal image gives %zu features, fewer than %d",
                      kp_goal_.size(), kMinGoalFeatures);
        return msg;
    }
    /* Describe at the detector's scale, then refine on the full image. */
    std::vector<cv::KeyPoint> kd = kp_goal_;
    cv::Mat half;
    const cv::Mat *d = &goal;
    if (half_) {
        cv::resize(goal, half, cv::Size(goal.cols / 2, goal.rows / 2), 0, 0,
                   cv::INTER_AREA);
        d = &half;
        for (cv::KeyPoint &k : kd) {
            k.pt = (k.pt - cv::Point2f(0.5f, 0.5f)) * 0.5f;
            k.size *= 0.5f;
        }
    }
    det_goal_->compute(*d, kd, desc_goal_);
    if (kd.size() != kp_goal_.size()) {
        return "the goal's features could not all be described";
    }
    if (p.subpixel) {
        simfe::refine_corners(goal, kp_goal_);
    }
    std::vector<cv::Point2f> px;
    for (const cv::KeyPoint &k : kp_goal_) {
        px.push_back(k.pt);
    }
    in_.centre(px, goal_c_);
    return "";
}

void Vision::frame(const cv::Mat &img, FrameMatches &out, double &detect_ms,
                   double &match_ms)
{
    out = FrameMatches();
    double t0 = sim_clock_now_s();
    std::vector<cv::KeyPoint> kp;
    cv::Mat desc;
    detect(det_frame_, img, kp, &desc);
    detect_ms = ms_since(t0);
    t0 = sim_clock_now_s();
    out.keypoints = (int)kp.size();
    std::vector<cv::DMatch> cand;
    simfe::match_descriptors(desc, desc_goal_, cv::NORM_L2, p_.ratio, true,
                             cand);
    out.candidates = (int)cand.size();
    /* More candidates than the core takes is a normal frame: the best,
     * spread over the image, go on. */
    std::vector<cv::Point2f> pos;
    for (const cv::DMatch &m : cand) {
        pos.push_back(kp[(size_t)m.queryIdx].pt);
    }
    std::vector<size_t> keep = simfe::spread_best(
        pos, (size_t)p_.max_matches, img.size(), kGridX, kGridY);
    std::vector<cv::KeyPoint> km;
    for (size_t i : keep) {
        km.push_back(kp[(size_t)cand[i].queryIdx]);
    }
    if (p_.subpixel) {
        simfe::refine_corners(img, km);
    }
    std::vector<cv::Point2f> px, c;
    for (const cv::KeyPoint &k : km) {
        px.push_back(k.pt);
    }
    in_.centre(px, c);
    for (size_t j = 0; j < keep.size(); ++j) {
        const int t = cand[keep[j]].trainIdx;
        spvs_match_t m;
        m.x_tgt = (spvs_real)goal_c_[(size_t)t].x;
        m.y_tgt = (spvs_real)goal_c_[(size_t)t].y;
        m.x_cur = (spvs_real)c[j].x;
        m.y_cur = (spvs_real)c[j].y;
        m.feature = (uint16_t)t;
        out.m.push_back(m);
    }
    match_ms = ms_since(t0);
}

std::string check_frame(const cv::Mat &img, cv::Size want)
{
    if (img.size() != want) {
        return "size_mismatch";
    }
    cv::Scalar mean, sd;
    cv::meanStdDev(img, mean, sd);
    if (mean[0] < 12.0) {
        return "dark_frame";
    }
    if (sd[0] < 3.0) {
        return "blank_frame";
    }
    return "";
}

std::string teach_check(const cv::Mat &img,
                        const Intrinsics &in, const VisionParams &p)
{
    char msg[240];
    const std::string fc = check_frame(img, img.size());
    if (fc == "dark_frame") {
        return "the image is too dark (mean grey below 12 of 255): light the "
               "scene or open the lens";
    }
    if (fc == "blank_frame") {
        return "the image is nearly uniform (grey deviation below 3): is the "
               "lens covered, or the camera facing a blank wall?";
    }
    Vision probe;
    const std::string why = probe.set_goal(img, in, p);
    if (!why.empty()) {
        std::snprintf(msg, sizeof(msg),
                      "%s: point the camera at a textured, planar part of the "
                      "scene", why.c_str());
        return msg;
    }
    std::vector<cv::KeyPoint> kp;
    probe.goal_like_keypoints(img, kp);
    int cells[kTeachCellsX * kTeachCellsY] = {};
    for (const cv::KeyPoint &k : kp) {
        const int gx = std::min(kTeachCellsX - 1, (int)(k.pt.x * kTeachCellsX / img.cols));
        const int gy = std::min(kTeachCellsY - 1, (int)(k.pt.y * kTeachCellsY / img.rows));
        cells[gy * kTeachCellsX + gx]++;
    }
    int covered = 0;
    for (int c : cells) {
        covered += c >= kTeachMinPerCell ? 1 : 0;
    }
    if (covered < kTeachMinCells) {
        std::snprintf(msg, sizeof(msg),
                      "the features cover only %d of the %d cells of a %dx%d "
                      "grid (need %d with %d features each): the texture is "
                      "bunched in part of the view; frame more of the plane",
                      covered, kTeachCellsX * kTeachCellsY, kTeachCellsX,
                      kTeachCellsY, kTeachMinCells, kTeachMinPerCell);
        return msg;
    }
    return "";
}

} // namespace spvscam
