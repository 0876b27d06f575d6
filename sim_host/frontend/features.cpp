/* features.cpp - sub-pixel refinement and descriptor matching shared by
 * the front ends (features.hpp). */
#include "features.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace simfe {

/* Move keypoints to the sub-pixel corner (cv::cornerSubPix, 7x7 window).
 * A keypoint found at a coarse scale is placed to within that scale's
 * pixel, 1..2 px of the full image (SIFT on the halved image, ORB on its
 * upper pyramid levels); the textures' corners are polygon vertices, which
 * a projective map sends to vertices, so refining both images puts both
 * ends of a match on the same scene point.  A keypoint that the refinement
 * moves by more than 1.5 px was not on a clean corner: it keeps the
 * detector's position. */
void refine_corners(const cv::Mat &img, std::vector<cv::KeyPoint> &kp)
{
    if (kp.empty()) {
        return;
    }
    std::vector<cv::Point2f> pts;
    pts.reserve(kp.size());
    for (const cv::KeyPoint &k : kp) {
        pts.push_back(k.pt);
    }
    cv::cornerSubPix(img, pts, cv::Size(3, 3), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT |
                                          cv::TermCriteria::EPS,
                                      20, 0.01));
    for (size_t i = 0; i < kp.size(); ++i) {
        const cv::Point2f d = pts[i] - kp[i].pt;
        if (std::isfinite(pts[i].x) && std::isfinite(pts[i].y) &&
            d.dot(d) <= 2.25f) {
            kp[i].pt = pts[i];
        }
    }
}

void match_descriptors(const cv::Mat &desc_cur, const cv::Mat &desc_tgt,
                       int norm, double ratio, bool cross_check,
                       std::vector<cv::DMatch> &cand)
{
    cand.clear();
    if (desc_cur.empty() || desc_tgt.empty()) {
        return;
    }
    /* One distance matrix, current x target, serves both directions: the
     * two nearest targets of each current feature (ratio test) and the
     * nearest current feature of each target (mutual check). */
    cv::Mat dist;
    cv::batchDistance(desc_cur, desc_tgt, dist,
                      norm == cv::NORM_L2 ? CV_32F : CV_32S, cv::noArray(),
                      norm);
    if (dist.type() != CV_32F) {
        dist.convertTo(dist, CV_32F);
    }
    const int nc = dist.rows, nt = dist.cols;
    std::vector<int> best_cur_of_tgt((size_t)nt, -1);
    std::vector<float> best_d_of_tgt((size_t)nt, INFINITY);
    for (int i = 0; i < nc; ++i) {
        const float *d = dist.ptr<float>(i);
        int j1 = -1;
        float d1 = INFINITY, d2 = INFINITY;
        for (int j = 0; j < nt; ++j) {
            if (d[j] < d1) {
                d2 = d1;
                d1 = d[j];
                j1 = j;
            } else if (d[j] < d2) {
                d2 = d[j];
            }
            if (d[j] < best_d_of_tgt[(size_t)j]) {
                best_d_of_tgt[(size_t)j] = d[j];
                best_cur_of_tgt[(size_t)j] = i;
            }
        }
        /* With a single neighbour there is nothing to compare against:
         * such a match is ambiguous by construction and is dropped. */
        if (j1 >= 0 && nt >= 2 && d1 < ratio * d2) {
            cand.emplace_back(i, j1, d1);
        }
    }
    if (cross_check) {
        cand.erase(std::remove_if(cand.begin(), cand.end(),
                                  [&](const cv::DMatch &m) {
                                      return best_cur_of_tgt[(size_t)m.trainIdx] !=
                                             m.queryIdx;
                                  }),
                   cand.end());
    }
    std::stable_sort(cand.begin(), cand.end(),
                     [](const cv::DMatch &a, const cv::DMatch &b) {
                         return a.distance < b.distance;
                     });
    /* One match per target feature: the best of each. */
    std::vector<uint8_t> used((size_t)desc_tgt.rows, 0);
    size_t k = 0;
    for (size_t i = 0; i < cand.size(); ++i) {
        const int t = cand[i].trainIdx;
        if (!used[(size_t)t]) {
            used[(size_t)t] = 1;
            cand[k++] = cand[i];
        }
    }
    cand.resize(k);
}

std::vector<size_t> spread_best(const std::vector<cv::Point2f> &pt,
                                size_t cap, cv::Size img, int cells_x,
                                int cells_y)
{
    std::vector<size_t> out;
    if (cap == 0 || pt.empty() || cells_x < 1 || cells_y < 1 ||
        img.width < 1 || img.height < 1) {
        return out;
    }
    const size_t cells = (size_t)cells_x * (size_t)cells_y;
    const size_t per_cell = (cap + cells - 1) / cells;
    std::vector<size_t> in_cell(cells, 0);
    std::vector<uint8_t> taken(pt.size(), 0);
    for (size_t i = 0; i < pt.size() && out.size() < cap; ++i) {
        const int gx = std::min(cells_x - 1, std::max(0, (int)(pt[i].x * cells_x / img.width)));
        const int gy = std::min(cells_y - 1, std::max(0, (int)(pt[i].y * cells_y / img.height)));
        size_t &cnt = in_cell[(size_t)gy * (size_t)cells_x + (size_t)gx];
        if (cnt < per_cell) {
            ++cnt;
            taken[i] = 1;
            out.push_back(i);
        }
    }
    for (size_t i = 0; i < pt.size() && out.size() < cap; ++i) {
        if (!taken[i]) {
            out.push_back(i);
        }
    }
    return out;
}

} // namespace simfe
