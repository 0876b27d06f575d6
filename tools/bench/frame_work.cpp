/*
 * frame_work.cpp - one frame's feature extraction (frame_work.h).
 */
#include "frame_work.h"

#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace bench {

namespace {

/* A camera frame's size and the features a front end asks for. */
constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr int kFeatures = 500;

} // namespace

struct FrameWork::Impl {
    cv::Mat image;
    cv::Ptr<cv::ORB> orb;
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
};

FrameWork::FrameWork() : impl_(new Impl())
{
    /* A fixed texture: uniform noise (seeded) blurred to corner-like blobs,
     * with a few filled shapes for edges; ORB finds its full quota on it. */
    cv::Mat img(kHeight, kWidth, CV_8U);
    cv::RNG rng(7);
    rng.fill(img, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(img, img, cv::Size(5, 5), 1.5);
    for (int k = 0; k < 40; k++) {
        cv::Point c(rng.uniform(0, kWidth), rng.uniform(0, kHeight));
        cv::rectangle(img, c, c + cv::Point(rng.uniform(8, 60), rng.uniform(8, 60)),
                      cv::Scalar(rng.uniform(0, 256)), cv::FILLED);
    }
    impl_->image = img;
    impl_->orb = cv::ORB::create(kFeatures);
}

FrameWork::~FrameWork() = default;

int FrameWork::run()
{
    impl_->keypoints.clear();
    impl_->orb->detectAndCompute(impl_->image, cv::noArray(), impl_->keypoints,
                                 impl_->descriptors);
    return (int)impl_->keypoints.size();
}

} // namespace bench
