/*
 * estimators.h - the homography estimators the benchmark compares, behind one
 * small interface: prepare the input of one record in the estimator's native
 * form (not timed), then estimate H (timed).
 *
 * Every estimator returns H_cur_tgt in centred pixels; scale is irrelevant to
 * the corner error the benchmark scores.
 */
#ifndef SPVS_BENCH_ESTIMATORS_H
#define SPVS_BENCH_ESTIMATORS_H

#include <memory>
#include <string>
#include <vector>

#include "hombench.h"

namespace bench {

class Estimator {
public:
    virtual ~Estimator() = default;
    /* Short stable name used in JSON output ("spvs", "cv_usac_default", ...). */
    virtual const char *name() const = 0;
    /* Convert one record's matches to the estimator's own input (untimed).
     * Returns false when the record cannot be given to this estimator (e.g.
     * more matches than the core's build accepts); it then counts as a
     * failed estimate. */
    virtual bool prepare(const hb_record_t &rec) = 0;
    /* Estimate H from the prepared input (the timed call).  Writes H_cur_tgt
     * (row-major, centred pixels) and returns true when the estimator
     * produced a homography. */
    virtual bool estimate(double H[9]) = 0;
};

/* Every estimator this build has, in table order (ours first). */
std::vector<std::string> available_estimators();

/* Create an estimator by name; nullptr when the name is unknown or not built. */
std::unique_ptr<Estimator> make_estimator(const std::string &name);

/* The RANSAC settings every estimator gets: inlier threshold in pixels and
 * confidence. */
constexpr double kInlierPx = 3.0;
constexpr double kConfidence = 0.999;

} // namespace bench

#endif
