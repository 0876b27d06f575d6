/*
 * features.hpp - the feature pieces of the image front end that do not
 * depend on the rendered scene: sub-pixel corner refinement and
 * ratio-test / mutual-best matching of descriptors.  Shared by the
 * simulator's front end (frontend.cpp) and the camera program
 * (sim_host/camera/).  C++ with OpenCV, at the edge.
 */
#ifndef SIM_FRONTEND_FEATURES_HPP
#define SIM_FRONTEND_FEATURES_HPP

#include <vector>

#include <opencv2/core.hpp>

namespace simfe {

/* Move keypoints to the sub-pixel corner (cv::cornerSubPix, 7x7 window) on
 * the 8-bit grey image img; a keypoint that the refinement moves by more
 * than 1.5 px keeps the detector's position.  Bound: 20 iterations per
 * keypoint. */
void refine_corners(const cv::Mat &img, std::vector<cv::KeyPoint> &kp);

/* Matches of current descriptors (rows of desc_cur) to target descriptors
 * (rows of desc_tgt) under norm (cv::NORM_L2 or cv::NORM_HAMMING): each
 * current feature's nearest target when it passes Lowe's ratio test
 * (nearest < ratio x second nearest) and, with cross_check, when it is
 * also the target's nearest current feature; at most one match per
 * target feature.  cand gets them sorted by distance, best first
 * (queryIdx: current, trainIdx: target).  Bound: one n_cur x n_tgt
 * distance matrix. */
void match_descriptors(const cv::Mat &desc_cur, const cv::Mat &desc_tgt,
                       int norm, double ratio, bool cross_check,
                       std::vector<cv::DMatch> &cand);

/* Spreading over the image: of n points given best first (pt[i], pixel
 * coordinates in an image of size img), the indices of at most cap of
 * them: first each cell of a cells_x x cells_y grid takes its best points
 * up to an equal share (cap over the cells, rounded up), then the best
 * points left fill what remains.  Features spread over the image keep the
 * view's borders, which are all that stays in sight when the camera
 * looks far to one side.  Bound: two passes over the n points. */
std::vector<size_t> spread_best(const std::vector<cv::Point2f> &pt,
                                size_t cap, cv::Size img, int cells_x,
                                int cells_y);

} // namespace simfe

#endif /* SIM_FRONTEND_FEATURES_HPP */
