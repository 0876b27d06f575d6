/*
 * estimators.cpp - ours (the core's planar 3-point RANSAC + refit), OpenCV's
 * findHomography (RANSAC and the USAC family), and ViSP's vpHomography::ransac
 * when the build found ViSP.
 */
#include "estimators.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#ifdef SPVS_BENCH_HAVE_VISP
#include <visp3/vision/vpHomography.h>
#endif

extern "C" {
#include "spvs/spvs.h"
}

namespace bench {
namespace {

/* Ours.  The instance is large (its buffers are sized by SPVS_MAX_MATCHES),
 * so it lives on the heap of the bench, never on the stack. */
class SpvsEstimator : public Estimator {
public:
    SpvsEstimator() : s_(new spvs_t())
    {
        spvs_params_t p;
        spvs_params_default(&p, SPVS_METHOD_III);
        /* Parity with the peers: 0.999 confidence, and 1 px noise, which
         * puts our threshold on the Sampson error at 3.03 px against their
         * 3 px on the reprojection error.  The hypothesis cap stays the
         * core's default. */
        p.noise_px = (spvs_real)(kInlierPx / 3.0);
        p.confidence = (spvs_real)kConfidence;
        ok_ = spvs_init(s_.get(), &p) == SPVS_OK;
        if (!ok_)
            std::fprintf(stderr, "spvs-bench: spvs_init rejected the parameters\n");
    }
    const char *name() const override { return "spvs"; }
    bool prepare(const hb_record_t &rec) override
    {
        if (!ok_ || rec.n > SPVS_MAX_MATCHES)
            return false;
        m_.resize(rec.n);
        for (uint32_t i = 0; i < rec.n; i++) {
            m_[i].x_tgt = (spvs_real)rec.pts[i][0];
            m_[i].y_tgt = (spvs_real)rec.pts[i][1];
            m_[i].x_cur = (spvs_real)rec.pts[i][2];
            m_[i].y_cur = (spvs_real)rec.pts[i][3];
            m_[i].feature = (uint16_t)i;
        }
        return true;
    }
    bool estimate(double H[9]) override
    {
        spvs_output_t out;
        int st = spvs_estimate_h(s_.get(), m_.data(), (uint16_t)m_.size(), &out);
        if (st != SPVS_OK || !out.h_valid)
            return false;
        for (int i = 0; i < 9; i++)
            H[i] = (double)out.H[i];
        return true;
    }

private:
    std::unique_ptr<spvs_t> s_;
    std::vector<spvs_match_t> m_;
    bool ok_ = false;
};

/* OpenCV's findHomography with one of its robust methods.  Points are given
 * as float pairs, the form a feature pipeline hands over. */
class OpenCvEstimator : public Estimator {
public:
    OpenCvEstimator(const char *name, int method) : name_(name), method_(method) {}
    const char *name() const override { return name_; }
    bool prepare(const hb_record_t &rec) override
    {
        src_.resize(rec.n);
        dst_.resize(rec.n);
        for (uint32_t i = 0; i < rec.n; i++) {
            src_[i] = cv::Point2f((float)rec.pts[i][0], (float)rec.pts[i][1]);
            dst_[i] = cv::Point2f((float)rec.pts[i][2], (float)rec.pts[i][3]);
        }
        return true;
    }
    bool estimate(double H[9]) override
    {
        cv::Mat Hm;
        try {
            /* maxIters stays OpenCV's default (2000). */
            Hm = cv::findHomography(src_, dst_, method_, kInlierPx, cv::noArray(),
                                    2000, kConfidence);
        } catch (const cv::Exception &) {
            return false;
        }
        if (Hm.empty() || Hm.rows != 3 || Hm.cols != 3)
            return false;
        Hm.convertTo(Hm, CV_64F);
        for (int i = 0; i < 9; i++)
            H[i] = Hm.at<double>(i / 3, i % 3);
        return true;
    }

private:
    const char *name_;
    int method_;
    std::vector<cv::Point2f> src_, dst_;
};

#ifdef SPVS_BENCH_HAVE_VISP
/* ViSP's vpHomography::ransac.  It has no adaptive stopping: it runs until
 * nbInliersConsensus inliers are found or 1000 trials pass, and fails when the
 * consensus is not reached.  We ask for 40 % of the matches, below the true
 * inlier share of every generated case, so a caller who knows only a bound on
 * the mismatch rate could make the same choice. */
class VispEstimator : public Estimator {
public:
    const char *name() const override { return "visp_ransac"; }
    bool prepare(const hb_record_t &rec) override
    {
        xb_.resize(rec.n);
        yb_.resize(rec.n);
        xa_.resize(rec.n);
        ya_.resize(rec.n);
        for (uint32_t i = 0; i < rec.n; i++) {
            xb_[i] = rec.pts[i][0];
            yb_[i] = rec.pts[i][1];
            xa_[i] = rec.pts[i][2];
            ya_[i] = rec.pts[i][3];
        }
        consensus_ = (unsigned)std::ceil(0.4 * rec.n);
        if (consensus_ < 4)
            consensus_ = 4;
        return rec.n >= 4;
    }
    bool estimate(double H[9]) override
    {
        vpHomography aHb;
        std::vector<bool> inl;
        double residual = 0;
        bool ok = false;
        try {
            ok = vpHomography::ransac(xb_, yb_, xa_, ya_, aHb, inl, residual, consensus_,
                                      kInlierPx, true);
        } catch (...) {
            return false;
        }
        if (!ok)
            return false;
        for (int i = 0; i < 9; i++)
            H[i] = aHb[(unsigned)(i / 3)][(unsigned)(i % 3)];
        return true;
    }

private:
    std::vector<double> xb_, yb_, xa_, ya_;
    unsigned consensus_ = 4;
};
#endif

struct CvMethod {
    const char *name;
    int method;
};

const CvMethod kCvMethods[] = {
    {"cv_ransac", cv::RANSAC},
    {"cv_usac_default", cv::USAC_DEFAULT},
    {"cv_usac_fast", cv::USAC_FAST},
    {"cv_usac_accurate", cv::USAC_ACCURATE},
    {"cv_usac_prosac", cv::USAC_PROSAC},
    {"cv_usac_magsac", cv::USAC_MAGSAC},
};

} // namespace

std::vector<std::string> available_estimators()
{
    std::vector<std::string> v{"spvs"};
    for (const auto &m : kCvMethods)
        v.emplace_back(m.name);
#ifdef SPVS_BENCH_HAVE_VISP
    v.emplace_back("visp_ransac");
#endif
    return v;
}

std::unique_ptr<Estimator> make_estimator(const std::string &name)
{
    if (name == "spvs")
        return std::unique_ptr<Estimator>(new SpvsEstimator());
    for (const auto &m : kCvMethods)
        if (name == m.name)
            return std::unique_ptr<Estimator>(new OpenCvEstimator(m.name, m.method));
#ifdef SPVS_BENCH_HAVE_VISP
    if (name == "visp_ransac")
        return std::unique_ptr<Estimator>(new VispEstimator());
#endif
    return nullptr;
}

} // namespace bench
