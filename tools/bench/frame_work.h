/*
 * frame_work.h - the work a robot's vision pipeline does between two
 * estimates, for timing the estimators from a cold start (spvs-bench
 * --between frame).
 *
 * On a robot the estimator runs once per camera frame, after the frame's
 * features were found and matched: other code has just run, and its data and
 * code have pushed the estimator's out of the caches and its branches out of
 * the predictors.  FrameWork stands for that work with one frame's feature
 * extraction: OpenCV's ORB (500 features) on a fixed 640 x 480 textured
 * image, one thread.  Every estimator is timed after the same work, so each
 * starts as cold as on the robot; the matches are then handed over afresh
 * (prepare), as a matcher that just wrote them would.
 */
#ifndef SPVS_BENCH_FRAME_WORK_H
#define SPVS_BENCH_FRAME_WORK_H

#include <memory>

namespace bench {

class FrameWork {
public:
    FrameWork();
    ~FrameWork();
    FrameWork(const FrameWork &) = delete;
    FrameWork &operator=(const FrameWork &) = delete;
    /* One frame's feature extraction; returns the number of features found
     * (the same on every call: the image is fixed). */
    int run();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace bench

#endif
