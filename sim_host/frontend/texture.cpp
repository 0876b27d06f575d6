/* texture.cpp - procedural textures for the rendered scene
 * (frontend_internal.hpp).  Everything is drawn from one cv::RNG seeded
 * from the run's seed, so the same seed gives the same texels. */
#include "frontend_internal.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace simfe {

namespace {

/* SplitMix64 finaliser: decorrelates the seeds of the different textures. */
uint64_t mix(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

/* A smooth random background: a coarse grid of random grey levels in
 * [lo, hi) blown up with bicubic interpolation.  It gives no corners of its
 * own, only slow shading, as real surfaces have. */
cv::Mat smooth_field(cv::RNG &rng, int w, int h, int cells, int lo, int hi)
{
    cv::Mat coarse(cells, cells, CV_8U);
    rng.fill(coarse, cv::RNG::UNIFORM, lo, hi);
    cv::Mat out;
    cv::resize(coarse, out, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
    return out;
}

/* `count` shapes of about `scale` texels: axis-aligned rectangles, rotated
 * blocks and triangles, each of one random grey level.  Corners
 * of every orientation and contrast, at the size of `scale`. */
void draw_shapes(cv::Mat &tex, cv::RNG &rng, int count, double scale)
{
    for (int k = 0; k < count; ++k) {
        double cx = rng.uniform(0.0, (double)tex.cols);
        double cy = rng.uniform(0.0, (double)tex.rows);
        double sw = scale * rng.uniform(0.4, 1.6);
        double sh = scale * rng.uniform(0.4, 1.6);
        int grey = rng.uniform(0, 256);
        int kind = rng.uniform(0, 10);
        if (kind < 6) {
            cv::rectangle(tex, cv::Point2d(cx - sw / 2, cy - sh / 2),
                          cv::Point2d(cx + sw / 2, cy + sh / 2),
                          cv::Scalar(grey), cv::FILLED, cv::LINE_AA);
        } else if (kind < 9) {
            double a = rng.uniform(0.0, CV_PI);
            double ca = std::cos(a), sa = std::sin(a);
            cv::Point pts[4];
            const double sx[4] = { -0.5, 0.5, 0.5, -0.5 };
            const double sy[4] = { -0.5, -0.5, 0.5, 0.5 };
            for (int i = 0; i < 4; ++i) {
                double px = sx[i] * sw, py = sy[i] * sh;
                pts[i] = cv::Point((int)std::lround(cx + ca * px - sa * py),
                                   (int)std::lround(cy + sa * px + ca * py));
            }
            cv::fillConvexPoly(tex, pts, 4, cv::Scalar(grey), cv::LINE_AA);
        } else {
            /* A triangle: corners of acute and obtuse angles.  Periodic
             * patterns (checkers) are left out on purpose: their corners all
             * look alike and would only breed mismatches. */
            cv::Point pts[3];
            for (int i = 0; i < 3; ++i) {
                pts[i] = cv::Point((int)std::lround(cx + rng.uniform(-0.7, 0.7) * sw),
                                   (int)std::lround(cy + rng.uniform(-0.7, 0.7) * sh));
            }
            cv::fillConvexPoly(tex, pts, 3, cv::Scalar(grey), cv::LINE_AA);
        }
    }
}

} // namespace

cv::Mat make_plane_texture(uint64_t seed, int w, int h)
{
    cv::RNG rng(mix(seed ^ 0x706c616e65ULL));
    cv::Mat tex = smooth_field(rng, w, h, 24, 70, 190);
    /* Three scales, coarse first so that finer shapes sit on top: about
     * 19, 8 and 3.4 m across (one texel is 12 cm), 15..130 pixels of the
     * 400 px camera at the plane's usual 50..100 m.
     * Each scale covers about half of the texture, so shapes overlap in
     * random arrangements that make each corner's neighbourhood unique. */
    const double area = (double)w * (double)h;
    draw_shapes(tex, rng, (int)(0.5 * area / (160.0 * 160.0)), 160.0);
    draw_shapes(tex, rng, (int)(0.5 * area / (64.0 * 64.0)), 64.0);
    draw_shapes(tex, rng, (int)(0.5 * area / (28.0 * 28.0)), 28.0);
    /* Band-limit the texels so that bilinear sampling at up to ~2 texels per
     * pixel does not alias into features that flicker from frame to
     * frame. */
    cv::GaussianBlur(tex, tex, cv::Size(0, 0), 1.2);
    return tex;
}

cv::Mat make_object_texture(uint64_t seed, int size)
{
    cv::RNG rng(mix(seed ^ 0x6f626a656374ULL));
    cv::Mat tex = smooth_field(rng, size, size, 6, 70, 190);
    const double area = (double)size * (double)size;
    const double big = size / 4.0, small = size / 9.0;
    draw_shapes(tex, rng, (int)(area / (big * big)), big);
    draw_shapes(tex, rng, (int)(area / (small * small)), small);
    cv::GaussianBlur(tex, tex, cv::Size(0, 0), 0.8);
    return tex;
}

std::string load_plane_texture(const std::string &path, int w, int h,
                               cv::Mat &out)
{
    cv::Mat img;
    try {
        img = cv::imread(path, cv::IMREAD_GRAYSCALE);
    } catch (const std::exception &) {
        img.release();
    }
    if (img.empty() || img.cols < 2 || img.rows < 2) {
        return "cannot read the texture image '" + path + "'";
    }
    /* Cover the whole plane, aspect kept: the larger of the two scales,
     * then the centre cut out.  A photograph is upsampled here (Debian's
     * are 640..1000 px across); the plane's usual 1..2 texels per pixel
     * then show each photograph pixel over a few image pixels. */
    const double k = std::max((double)w / img.cols, (double)h / img.rows);
    const int sw = std::max(w, (int)std::ceil(img.cols * k));
    const int sh = std::max(h, (int)std::ceil(img.rows * k));
    cv::Mat big;
    cv::resize(img, big, cv::Size(sw, sh), 0, 0, cv::INTER_LINEAR);
    big(cv::Rect((sw - w) / 2, (sh - h) / 2, w, h)).copyTo(out);
    return "";
}

} // namespace simfe
