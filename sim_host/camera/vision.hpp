/*
 * vision.hpp - spvs-camera's image side: the camera's intrinsics, the goal
 * image's features, and each frame's matches against them, handed to the
 * core as spvs_match_t (pixels, undistorted, centred on the principal
 * point).  Detection is SIFT as in the simulator's front end; matching and
 * sub-pixel refinement are the front end's own (sim_host/frontend/
 * features.hpp).
 */
#ifndef SPVS_CAMERA_VISION_HPP
#define SPVS_CAMERA_VISION_HPP

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "spvs/spvs.h"

namespace spvscam {

/* K and the distortion of the camera.  With only a focal length the
 * principal point is the image centre (w/2, h/2) and there is no
 * distortion. */
struct Intrinsics {
    cv::Matx33d K;
    cv::Mat dist;            /* empty: none                                */
    int width = 0;           /* from the calibration file, 0: not given   */
    int height = 0;

    /* From --focal-px for images of size sz. */
    void from_focal(double f_px, cv::Size sz);
    /* From an OpenCV calibration file (camera_matrix,
     * distortion_coefficients, optionally image_width / image_height, as
     * OpenCV's calibration sample writes them).  Returns "" or a reason. */
    std::string from_file(const std::string &path);

    /* Pixel points -> undistorted pixels centred on the principal point. */
    void centre(const std::vector<cv::Point2f> &px,
                std::vector<cv::Point2f> &out) const;
};

/* Settings of detection and matching. */
struct VisionParams {
    int goal_features = 500;     /* kept on the goal, <= SPVS_MAX_FEATURES  */
    int frame_features = 1500;   /* detected on each frame                  */
    double ratio = 0.7;          /* Lowe's ratio test                       */
    int max_matches = SPVS_MAX_MATCHES; /* kept per frame                   */
    int subpixel = 1;            /* refine matched corners on the full image */
    int half = -1;               /* detect on the halved image: 1, 0, or -1
                                    for images at least 600 px wide          */
};

/* Per-frame counts of the image side. */
struct FrameMatches {
    int keypoints = 0;
    int candidates = 0;          /* passed the ratio and mutual checks     */
    std::vector<spvs_match_t> m; /* kept, best first                       */
};

class Vision {
public:
    /* Detects and describes the goal image (grey).  Returns "" or a reason
     * (fewer than min_goal_features features, a calibration of another
     * size). */
    std::string set_goal(const cv::Mat &goal, const Intrinsics &in,
                         const VisionParams &p);

    /* Features of an image, spread over it (the goal's choice), for the
     * teach check. */
    void goal_like_keypoints(const cv::Mat &img,
                             std::vector<cv::KeyPoint> &kp) const;

    /* One frame: detect (detect_ms), match and keep (match_ms). */
    void frame(const cv::Mat &img, FrameMatches &out, double &detect_ms,
               double &match_ms);

    cv::Size size() const { return size_; }
    int goal_count() const { return (int)kp_goal_.size(); }

    static constexpr int kMinGoalFeatures = 50;

private:
    void detect(const cv::Ptr<cv::Feature2D> &det, const cv::Mat &img,
                std::vector<cv::KeyPoint> &kp, cv::Mat *desc) const;

    VisionParams p_;
    Intrinsics in_;
    cv::Size size_;
    bool half_ = false;
    cv::Ptr<cv::Feature2D> det_goal_;
    cv::Ptr<cv::Feature2D> det_frame_;
    std::vector<cv::KeyPoint> kp_goal_;
    std::vector<cv::Point2f> goal_c_;   /* centred, undistorted            */
    cv::Mat desc_goal_;
};

/* The frame checks before detection: "" for a usable frame, else the
 * status: "size_mismatch", "dark_frame" (mean grey below 12 of 255) or
 * "blank_frame" (grey standard deviation below 3: a lens cap, a wall). */
std::string check_frame(const cv::Mat &img, cv::Size want);

/* The teach check: "" when img makes a usable goal, else what is wrong
 * (too dark, too blank, too few features, features bunched in part of the
 * image). */
std::string teach_check(const cv::Mat &img,
                        const Intrinsics &in, const VisionParams &p);

} // namespace spvscam

#endif /* SPVS_CAMERA_VISION_HPP */
