/*
 * hombench.c - HOMBENCH v1 reader and writer, and the synthetic case
 * generator (see hombench.h).
 */
#include "hombench.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HB_HEADER_BYTES 80u   /* magic 8 + 2 x u32 + 8 x f64          */
#define HB_REC_FIXED_BYTES 144u /* 6 x u32 + u64 + 14 x f64            */
#define HB_TWO_PI 6.283185307179586

/* ---- random numbers ---------------------------------------------------- */

void hb_rng_seed(hb_rng_t *r, uint64_t seed) { r->state = seed; }

uint64_t hb_rng_next(hb_rng_t *r)
{
    uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double hb_rng_uniform(hb_rng_t *r, double lo, double hi)
{
    /* 53 random bits give every double in [0, 1) on the 2^-53 grid. */
    double u = (double)(hb_rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
    return lo + (hi - lo) * u;
}

double hb_rng_normal(hb_rng_t *r)
{
    /* Box-Muller; 1 - u keeps the logarithm's argument in (0, 1]. */
    double u1 = 1.0 - hb_rng_uniform(r, 0.0, 1.0);
    double u2 = hb_rng_uniform(r, 0.0, 1.0);
    return sqrt(-2.0 * log(u1)) * cos(HB_TWO_PI * u2);
}

/* ---- geometry ---------------------------------------------------------- */

void hb_scene_default(hb_scene_t *sc)
{
    const double n[3] = {0.3, -0.6, -0.75};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    sc->alpha_x = 800.0;
    sc->alpha_y = 800.0;
    sc->width_px = 640.0;
    sc->height_px = 480.0;
    for (int i = 0; i < 3; i++)
        sc->normal[i] = n[i] / len;
    sc->d_m = 45.0;
}

void hb_true_h(const hb_scene_t *sc, double x_m, double z_m, double phi_rad,
               double H[9])
{
    const double c = cos(phi_rad), s = sin(phi_rad);
    const double R[9] = {c, 0, s, 0, 1, 0, -s, 0, c}; /* eq. (3) */
    const double cv[3] = {x_m, 0.0, z_m};
    double A[9], M[9];
    /* A = I + c n^T / d, M = R A (the bracket of eq. 2). */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            A[3 * i + j] = (i == j ? 1.0 : 0.0) + cv[i] * sc->normal[j] / sc->d_m;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            M[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] +
                           R[3 * i + 2] * A[6 + j];
    /* H = K M K^-1 with K = diag(ax, ay, 1): entry (i, j) scales by k_i / k_j. */
    const double k[3] = {sc->alpha_x, sc->alpha_y, 1.0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            H[3 * i + j] = M[3 * i + j] * k[i] / k[j];
    const double h22 = H[4];
    for (int i = 0; i < 9; i++)
        H[i] /= h22;
}

int hb_apply_h(const double H[9], double x, double y, double *xo, double *yo)
{
    double w = H[6] * x + H[7] * y + H[8];
    if (!(w > 1e-12))
        return -1;
    *xo = (H[0] * x + H[1] * y + H[2]) / w;
    *yo = (H[3] * x + H[4] * y + H[5]) / w;
    return 0;
}

/* The four corners of the seen rectangle and H_est with w > 0 for points
 * in front (a negative overall scale flips the sign of w).  Returns 0, or
 * -1 when H_est is not finite or nothing is seen. */
static int corners_and_h(const hb_scene_t *sc, const double H_true[9],
                         const double H_est[9], double cx[4], double cy[4],
                         double He[9])
{
    double r[4];
    for (int i = 0; i < 9; i++)
        if (!isfinite(H_est[i]))
            return -1;
    if (hb_view_region(sc, H_true, r) != 0)
        return -1;
    cx[0] = r[0], cx[1] = r[1], cx[2] = r[1], cx[3] = r[0];
    cy[0] = r[2], cy[1] = r[2], cy[2] = r[3], cy[3] = r[3];
    /* Both H are only defined up to scale; dehomogenising removes it, but a
     * negative overall scale flips the sign of w, so normalise it first:
     * w > 0 at the rectangle's centre, which the true H maps in front (in a
     * view over 90 deg off-axis, h33 itself is negative). */
    const double xm = 0.5 * (r[0] + r[1]), ym = 0.5 * (r[2] + r[3]);
    double sgn = (H_est[6] * xm + H_est[7] * ym + H_est[8] < 0.0) ? -1.0 : 1.0;
    for (int i = 0; i < 9; i++)
        He[i] = sgn * H_est[i];
    return 0;
}

double hb_corner_err(const hb_scene_t *sc, const double H_true[9],
                     const double H_est[9])
{
    double cx[4], cy[4], He[9], sum = 0.0;
    if (corners_and_h(sc, H_true, H_est, cx, cy, He) != 0)
        return INFINITY;
    for (int k = 0; k < 4; k++) {
        double xt, yt, xe, ye;
        if (hb_apply_h(H_true, cx[k], cy[k], &xt, &yt) != 0 ||
            hb_apply_h(He, cx[k], cy[k], &xe, &ye) != 0)
            return INFINITY;
        sum += hypot(xe - xt, ye - yt);
    }
    return 0.25 * sum;
}

double hb_corner_err_tgt(const hb_scene_t *sc, const double H_true[9],
                         const double H_est[9])
{
    double cx[4], cy[4], He[9], sum = 0.0;
    if (corners_and_h(sc, H_true, H_est, cx, cy, He) != 0)
        return INFINITY;
    /* H_true^-1 as its adjugate (scale does not matter), signed so that
     * points in front of the current camera map back with w > 0. */
    const double *h = H_true;
    double A[9] = {h[4] * h[8] - h[5] * h[7], h[2] * h[7] - h[1] * h[8], h[1] * h[5] - h[2] * h[4],
                   h[5] * h[6] - h[3] * h[8], h[0] * h[8] - h[2] * h[6], h[2] * h[3] - h[0] * h[5],
                   h[3] * h[7] - h[4] * h[6], h[1] * h[6] - h[0] * h[7], h[0] * h[4] - h[1] * h[3]};
    const double det = h[0] * A[0] + h[1] * A[3] + h[2] * A[6];
    if (!(fabs(det) > 0.0))
        return INFINITY;
    for (int i = 0; i < 9; i++)
        A[i] /= det;
    for (int k = 0; k < 4; k++) {
        double xe, ye, xb, yb;
        if (hb_apply_h(He, cx[k], cy[k], &xe, &ye) != 0 ||
            hb_apply_h(A, xe, ye, &xb, &yb) != 0)
            return INFINITY;
        sum += hypot(xb - cx[k], yb - cy[k]);
    }
    return 0.25 * sum;
}

/* The x-range of the horizontal line y of the target image whose points
 * map under H in front of the current camera and within lim of its centre:
 * five half-lines a x + b >= 0 (w > 0, and lim w -+ x' >= 0, lim w -+ y' >= 0
 * with x' and y' the numerators), cut down to [*lo, *hi].  An empty range
 * leaves *lo > *hi. */
static void seen_on_line(const double H[9], double y, double lim, double *lo,
                         double *hi)
{
    const double w0 = H[7] * y + H[8];
    const double x0 = H[1] * y + H[2], y0 = H[4] * y + H[5];
    const double a[5] = {H[6], lim * H[6] - H[0], lim * H[6] + H[0],
                         lim * H[6] - H[3], lim * H[6] + H[3]};
    const double b[5] = {w0 - 1e-9, lim * w0 - x0, lim * w0 + x0,
                         lim * w0 - y0, lim * w0 + y0};
    for (int k = 0; k < 5; k++) {
        if (a[k] > 0.0)
            *lo = fmax(*lo, -b[k] / a[k]);
        else if (a[k] < 0.0)
            *hi = fmin(*hi, -b[k] / a[k]);
        else if (b[k] < 0.0)
            *hi = -INFINITY;
    }
}

int hb_view_region(const hb_scene_t *sc, const double H_true[9], double r[4])
{
    const double hw = 0.5 * sc->width_px, hh = 0.5 * sc->height_px;
    /* The seen set is convex (an intersection of half-planes), so a
     * rectangle lies in it when its top and bottom edges do. */
    double best_area = 0.0;
    for (int t = 16; t >= 1; t--) {
        const double yh = hh * (double)t / 16.0;
        double lo = -hw, hi = hw;
        seen_on_line(H_true, -yh, HB_VIEW_PX, &lo, &hi);
        seen_on_line(H_true, yh, HB_VIEW_PX, &lo, &hi);
        const double area = (hi - lo) * 2.0 * yh;
        if (hi - lo >= 1.0 && area > best_area) {
            best_area = area;
            r[0] = lo;
            r[1] = hi;
            r[2] = -yh;
            r[3] = yh;
        }
        if (t == 16 && lo == -hw && hi == hw)
            break; /* the whole image */
    }
    return best_area > 0.0 ? 0 : -1;
}

double hb_inliers_over(const hb_record_t *rec, double px)
{
    uint32_t over = 0, in = 0;
    for (uint32_t i = 0; i < rec->n; i++) {
        if (!rec->inlier[i])
            continue;
        in++;
        double x, y;
        if (hb_apply_h(rec->H, rec->pts[i][0], rec->pts[i][1], &x, &y) != 0 ||
            hypot(x - rec->pts[i][2], y - rec->pts[i][3]) > px)
            over++;
    }
    return in ? (double)over / (double)in : 0.0;
}

double hb_inliers_over_sampson(const hb_record_t *rec, double sigma, double chi2)
{
    if (!(sigma > 0.0))
        return 0.0;
    const double *h = rec->H;
    uint32_t over = 0, in = 0;
    for (uint32_t i = 0; i < rec->n; i++) {
        if (!rec->inlier[i])
            continue;
        in++;
        const double x = rec->pts[i][0], y = rec->pts[i][1];
        const double w = h[6] * x + h[7] * y + h[8];
        double fx, fy;
        if (hb_apply_h(h, x, y, &fx, &fy) != 0) {
            over++;
            continue;
        }
        /* A = d(fx, fy) / d(x, y); C = I + A A^T (symmetric 2x2). */
        const double a = (h[0] - fx * h[6]) / w, b = (h[1] - fx * h[7]) / w;
        const double c = (h[3] - fy * h[6]) / w, d = (h[4] - fy * h[7]) / w;
        const double c11 = 1.0 + a * a + b * b, c12 = a * c + b * d, c22 = 1.0 + c * c + d * d;
        const double ex = rec->pts[i][2] - fx, ey = rec->pts[i][3] - fy;
        const double det = c11 * c22 - c12 * c12;
        const double q = (c22 * ex * ex - 2.0 * c12 * ex * ey + c11 * ey * ey) / det;
        if (q > chi2 * sigma * sigma)
            over++;
    }
    return in ? (double)over / (double)in : 0.0;
}

/* a wrapped into (-pi, pi]. */
static double wrap_pi(double a)
{
    while (a > 0.5 * HB_TWO_PI)
        a -= HB_TWO_PI;
    while (a <= -0.5 * HB_TWO_PI)
        a += HB_TWO_PI;
    return a;
}

void hb_homing_pose(double x0_m, double z0_m, double phi0_rad, double s,
                    double *x_m, double *z_m, double *phi_rad)
{
    /* Facing the target: the heading (-sin phi, cos phi) points along
     * (0, 0) - (x0, z0), so sin phi = x0 / L and cos phi = -z0 / L.  Backing
     * onto it: that heading turned by pi.  The line's heading is the one
     * nearer phi0. */
    double phi_line = atan2(x0_m, -z0_m);
    if (fabs(wrap_pi(phi_line - phi0_rad)) > 0.25 * HB_TWO_PI)
        phi_line = wrap_pi(phi_line + 0.5 * HB_TWO_PI);
    if (s < 0.0)
        s = 0.0;
    if (s > 1.0)
        s = 1.0;
    if (s <= 0.2) {
        double a = s / 0.2;
        *x_m = x0_m;
        *z_m = z0_m;
        *phi_rad = wrap_pi(phi0_rad + a * wrap_pi(phi_line - phi0_rad));
    } else if (s <= 0.8) {
        double a = (s - 0.2) / 0.6;
        *x_m = (1.0 - a) * x0_m;
        *z_m = (1.0 - a) * z0_m;
        *phi_rad = phi_line;
    } else {
        double a = (s - 0.8) / 0.2;
        *x_m = 0.0;
        *z_m = 0.0;
        *phi_rad = (1.0 - a) * phi_line;
    }
}

/* ---- pose families ----------------------------------------------------- */

static const double fig5_starts[HB_FIG5_STARTS][3] = {
    {-3.0, -10.0, -30.0}, {0.0, -8.0, -40.0}, {6.0, -6.0, 0.0},
    {-6.0, 4.0, 20.0},    {6.0, 8.0, 10.0},   {5.0, 2.0, -50.0}};

const char *hb_family_name(uint32_t family)
{
    static const char *const names[HB_FAMILIES] = {"homing", "fig5", "grazing"};
    return family < HB_FAMILIES ? names[family] : NULL;
}

int hb_fig5_start(uint32_t i, double *x_m, double *z_m, double *phi_rad)
{
    if (i >= HB_FIG5_STARTS)
        return -1;
    *x_m = fig5_starts[i][0];
    *z_m = fig5_starts[i][1];
    *phi_rad = fig5_starts[i][2] * HB_TWO_PI / 360.0;
    return 0;
}

uint32_t hb_family_poses(uint32_t family, uint32_t poses)
{
    return family == HB_FAMILY_HOMING ? poses : HB_FIG5_STARTS * poses;
}

/* Bearing (radians, from +z towards +x) of the goal image's centre point
 * seen from (x, 0, z): the plane point (0, 0, -d / n_z) on the goal
 * camera's axis.  NAN when that axis does not meet the plane ahead. */
static double centre_bearing(const hb_scene_t *sc, double x_m, double z_m)
{
    if (!(sc->normal[2] < -1e-9))
        return NAN;
    const double t = -sc->d_m / sc->normal[2];
    return atan2(-x_m, t - z_m);
}

double hb_off_axis(const hb_scene_t *sc, double x_m, double z_m, double phi_rad)
{
    /* The optical axis (-sin phi, 0, cos phi) has bearing -phi. */
    return wrap_pi(centre_bearing(sc, x_m, z_m) + phi_rad);
}

int hb_family_pose(const hb_scene_t *sc, uint32_t family, uint32_t k,
                   uint32_t poses, double *x_m, double *z_m, double *phi_rad,
                   uint32_t *pose_id)
{
    if (poses == 0 || poses >= HB_POSE_STRIDE || k >= hb_family_poses(family, poses))
        return -1;
    double x0 = 0.0, z0 = 0.0, phi0 = 0.0;
    const uint32_t start = family == HB_FAMILY_HOMING ? 0u : k / poses, j = k % poses;
    if (hb_fig5_start(start, &x0, &z0, &phi0) != 0)
        return -1;
    const double s = poses > 1 ? (double)j / (double)(poses - 1) : 0.5;
    switch (family) {
    case HB_FAMILY_HOMING:
        hb_homing_pose(x0, z0, phi0, s, x_m, z_m, phi_rad);
        *pose_id = k;
        return 0;
    case HB_FAMILY_FIG5:
        hb_homing_pose(x0, z0, phi0, s, x_m, z_m, phi_rad);
        *pose_id = start * HB_POSE_STRIDE + j;
        return 0;
    case HB_FAMILY_GRAZING: {
        const double b = centre_bearing(sc, x0, z0);
        if (!isfinite(b))
            return -1;
        const double deg = HB_GRAZING_MIN_DEG + s * (HB_GRAZING_MAX_DEG - HB_GRAZING_MIN_DEG);
        const double off = (j % 2 == 0 ? 1.0 : -1.0) * deg * HB_TWO_PI / 360.0;
        *x_m = x0;
        *z_m = z0;
        *phi_rad = wrap_pi(off - b);
        *pose_id = start * HB_POSE_STRIDE + j;
        return 0;
    }
    default:
        return -1;
    }
}

int hb_record_alloc(hb_record_t *rec, uint32_t n)
{
    rec->pts = NULL;
    rec->inlier = NULL;
    if (n == 0 || n > HB_MAX_N)
        return -1;
    rec->pts = (double (*)[4])calloc(n, sizeof *rec->pts);
    rec->inlier = (uint8_t *)calloc(n, 1);
    if (!rec->pts || !rec->inlier) {
        free(rec->pts);
        free(rec->inlier);
        rec->pts = NULL;
        rec->inlier = NULL;
        return -1;
    }
    rec->n = n;
    return 0;
}

int hb_generate(const hb_scene_t *sc, uint32_t n, double mismatch,
                double sigma_px, double x_m, double z_m, double phi_rad,
                uint64_t seed, hb_record_t *rec)
{
    if (n == 0 || n > HB_MAX_N || !(mismatch >= 0.0 && mismatch <= 1.0) ||
        !(sigma_px >= 0.0) || !rec || !rec->pts || !rec->inlier)
        return -1;
    hb_rng_t rng;
    hb_rng_seed(&rng, seed);
    const double hw = 0.5 * sc->width_px, hh = 0.5 * sc->height_px;
    const double c = cos(phi_rad), s = sin(phi_rad);
    const double *nv = sc->normal;
    double H[9], reg[4];
    hb_true_h(sc, x_m, z_m, phi_rad, H);
    if (hb_view_region(sc, H, reg) != 0)
        return -1;

    for (uint32_t i = 0; i < n; i++) {
        /* A plane point seen at a uniform pixel of the seen rectangle of
         * the target image: back-project the ray and intersect n^T X = -d,
         * then project it into the current camera P2 = K [R | -R c].  Redraw
         * the rare point that falls behind either camera or beyond
         * HB_VIEW_PX (bounded: 64 tries). */
        int ok = 0;
        for (int tries = 0; tries < 64 && !ok; tries++) {
            double u = hb_rng_uniform(&rng, reg[0], reg[1]);
            double v = hb_rng_uniform(&rng, reg[2], reg[3]);
            double r[3] = {u / sc->alpha_x, v / sc->alpha_y, 1.0};
            double nr = nv[0] * r[0] + nv[1] * r[1] + nv[2] * r[2];
            if (!(nr < -1e-9))
                continue;
            double lam = -sc->d_m / nr;
            double X[3] = {lam * r[0] - x_m, lam * r[1], lam * r[2] - z_m};
            double Xc[3] = {c * X[0] + s * X[2], X[1], -s * X[0] + c * X[2]};
            if (!(Xc[2] > 1e-6))
                continue;
            const double xc = sc->alpha_x * Xc[0] / Xc[2], yc = sc->alpha_y * Xc[1] / Xc[2];
            if (!(fabs(xc) <= HB_VIEW_PX && fabs(yc) <= HB_VIEW_PX))
                continue;
            rec->pts[i][0] = u;
            rec->pts[i][1] = v;
            rec->pts[i][2] = xc;
            rec->pts[i][3] = yc;
            ok = 1;
        }
        if (!ok)
            return -1;
        rec->inlier[i] = 1;
    }

    /* Mismatches: a random subset (partial Fisher-Yates) of exactly
     * round(mismatch * n) matches gets a uniform current point. */
    uint32_t k = (uint32_t)lround(mismatch * (double)n);
    uint32_t *perm = (uint32_t *)malloc((size_t)n * sizeof *perm);
    if (!perm)
        return -1;
    for (uint32_t i = 0; i < n; i++)
        perm[i] = i;
    for (uint32_t i = 0; i < k; i++) {
        uint32_t j = i + (uint32_t)(hb_rng_next(&rng) % (uint64_t)(n - i));
        uint32_t t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
        rec->inlier[perm[i]] = 0;
        rec->pts[perm[i]][2] = hb_rng_uniform(&rng, -hw, hw);
        rec->pts[perm[i]][3] = hb_rng_uniform(&rng, -hh, hh);
    }
    free(perm);

    /* Noise on both images, drawn after the geometry so that sigma = 0 and
     * sigma = 1 share the same points for the same seed. */
    if (sigma_px > 0.0)
        for (uint32_t i = 0; i < n; i++)
            for (int j = 0; j < 4; j++)
                rec->pts[i][j] += sigma_px * hb_rng_normal(&rng);

    rec->n = n;
    rec->n_inliers = n - k;
    rec->seed = seed;
    rec->mismatch = mismatch;
    rec->sigma_px = sigma_px;
    rec->x_m = x_m;
    rec->z_m = z_m;
    rec->phi_rad = phi_rad;
    memcpy(rec->H, H, sizeof rec->H);
    return 0;
}

void hb_set_free(hb_set_t *set)
{
    if (!set)
        return;
    for (uint32_t i = 0; set->rec && i < set->count; i++) {
        free(set->rec[i].pts);
        free(set->rec[i].inlier);
    }
    free(set->rec);
    set->rec = NULL;
    set->count = 0;
}

/* ---- file format ------------------------------------------------------- */

static void seterr(char *err, size_t len, const char *fmt, ...)
{
    if (!err || len == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
}

/* Little-endian encoders: byte by byte, so the file is the same whatever the
 * host's byte order. */
static int put_u32(FILE *f, uint32_t v)
{
    unsigned char b[4];
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    return fwrite(b, 1, 4, f) == 4 ? 0 : -1;
}

static int put_u64(FILE *f, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    return fwrite(b, 1, 8, f) == 8 ? 0 : -1;
}

static int put_f64(FILE *f, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    return put_u64(f, v);
}

static uint32_t get_u32(const unsigned char *p)
{
    uint32_t v = 0;
    for (int i = 3; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

static uint64_t get_u64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

static double get_f64(const unsigned char *p)
{
    uint64_t v = get_u64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

static uint64_t rec_bytes(uint32_t n)
{
    uint64_t body = HB_REC_FIXED_BYTES + 32ull * n + n;
    return (body + 7u) & ~(uint64_t)7u;
}

int hb_write(const char *path, const hb_set_t *set, char *err, size_t err_len)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        seterr(err, err_len, "cannot open %s for writing", path);
        return -1;
    }
    int bad = fwrite("HOMBENCH", 1, 8, f) != 8;
    bad |= put_u32(f, 1u) | put_u32(f, set->count);
    const hb_scene_t *sc = &set->scene;
    const double hdr[8] = {sc->alpha_x, sc->alpha_y, sc->width_px, sc->height_px,
                           sc->normal[0], sc->normal[1], sc->normal[2], sc->d_m};
    for (int i = 0; i < 8; i++)
        bad |= put_f64(f, hdr[i]);
    for (uint32_t r = 0; r < set->count && !bad; r++) {
        const hb_record_t *rc = &set->rec[r];
        bad |= put_u32(f, rc->case_id) | put_u32(f, rc->instance) |
               put_u32(f, rc->pose) | put_u32(f, rc->n) |
               put_u32(f, rc->n_inliers) | put_u32(f, 0u);
        bad |= put_u64(f, rc->seed);
        const double fx[5] = {rc->mismatch, rc->sigma_px, rc->x_m, rc->z_m,
                              rc->phi_rad};
        for (int i = 0; i < 5; i++)
            bad |= put_f64(f, fx[i]);
        for (int i = 0; i < 9; i++)
            bad |= put_f64(f, rc->H[i]);
        for (uint32_t i = 0; i < rc->n; i++)
            for (int j = 0; j < 4; j++)
                bad |= put_f64(f, rc->pts[i][j]);
        if (rc->n && fwrite(rc->inlier, 1, rc->n, f) != rc->n)
            bad = 1;
        uint64_t pad = rec_bytes(rc->n) - (HB_REC_FIXED_BYTES + 33ull * rc->n);
        static const unsigned char zeros[8] = {0};
        if (pad && fwrite(zeros, 1, (size_t)pad, f) != pad)
            bad = 1;
    }
    if (fclose(f) != 0)
        bad = 1;
    if (bad) {
        seterr(err, err_len, "write error on %s", path);
        return -1;
    }
    return 0;
}

int hb_read(const char *path, hb_set_t *set, char *err, size_t err_len)
{
    memset(set, 0, sizeof *set);
    FILE *f = fopen(path, "rb");
    if (!f) {
        seterr(err, err_len, "cannot open %s", path);
        return -1;
    }
    unsigned char *buf = NULL;
    long size = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        size = ftell(f);
    if (size < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        seterr(err, err_len, "%s: cannot determine the file size", path);
        return -1;
    }
    if ((unsigned long)size < HB_HEADER_BYTES) {
        fclose(f);
        seterr(err, err_len, "%s: %ld bytes, shorter than the 80-byte header", path, size);
        return -1;
    }
    buf = (unsigned char *)malloc((size_t)size);
    if (!buf || fread(buf, 1, (size_t)size, f) != (size_t)size) {
        free(buf);
        fclose(f);
        seterr(err, err_len, "%s: cannot read %ld bytes", path, size);
        return -1;
    }
    fclose(f);

    const uint64_t len = (uint64_t)size;
    int rc = -1;
    if (memcmp(buf, "HOMBENCH", 8) != 0) {
        seterr(err, err_len, "%s: not a HOMBENCH file (bad magic)", path);
        goto done;
    }
    uint32_t version = get_u32(buf + 8), count = get_u32(buf + 12);
    if (version != 1) {
        seterr(err, err_len, "%s: HOMBENCH version %u, only 1 is supported", path, version);
        goto done;
    }
    if (count == 0 || count > HB_MAX_RECORDS) {
        seterr(err, err_len, "%s: record count %u out of range 1..%u", path, count, HB_MAX_RECORDS);
        goto done;
    }
    double hdr[8];
    for (int i = 0; i < 8; i++) {
        hdr[i] = get_f64(buf + 16 + 8 * i);
        if (!isfinite(hdr[i])) {
            seterr(err, err_len, "%s: non-finite value in the header", path);
            goto done;
        }
    }
    if (!(hdr[0] > 0 && hdr[1] > 0 && hdr[2] > 0 && hdr[3] > 0 && hdr[7] > 0)) {
        seterr(err, err_len, "%s: header needs positive focal lengths, image size and d", path);
        goto done;
    }
    set->scene = (hb_scene_t){hdr[0], hdr[1], hdr[2], hdr[3], {hdr[4], hdr[5], hdr[6]}, hdr[7]};
    set->rec = (hb_record_t *)calloc(count, sizeof *set->rec);
    if (!set->rec) {
        seterr(err, err_len, "%s: out of memory for %u records", path, count);
        goto done;
    }

    uint64_t off = HB_HEADER_BYTES;
    for (uint32_t r = 0; r < count; r++) {
        if (len - off < HB_REC_FIXED_BYTES) {
            seterr(err, err_len, "%s: record %u truncated (file ends at byte %llu)", path, r,
                   (unsigned long long)len);
            goto done;
        }
        const unsigned char *p = buf + off;
        hb_record_t *rec = &set->rec[r];
        uint32_t n = get_u32(p + 12), nin = get_u32(p + 16), zero = get_u32(p + 20);
        if (n == 0 || n > HB_MAX_N || nin > n || zero != 0) {
            seterr(err, err_len, "%s: record %u has N=%u, inliers=%u, reserved=%u (need 1<=N<=%u, inliers<=N, reserved 0)",
                   path, r, n, nin, zero, HB_MAX_N);
            goto done;
        }
        if (len - off < rec_bytes(n)) {
            seterr(err, err_len, "%s: record %u (N=%u) runs past the end of the file", path, r, n);
            goto done;
        }
        if (hb_record_alloc(rec, n) != 0) {
            seterr(err, err_len, "%s: out of memory for record %u", path, r);
            goto done;
        }
        set->count = r + 1; /* so that hb_set_free releases what is allocated */
        rec->case_id = get_u32(p);
        rec->instance = get_u32(p + 4);
        rec->pose = get_u32(p + 8);
        rec->n_inliers = nin;
        rec->seed = get_u64(p + 24);
        double fx[14];
        for (int i = 0; i < 14; i++)
            fx[i] = get_f64(p + 32 + 8 * i);
        rec->mismatch = fx[0];
        rec->sigma_px = fx[1];
        rec->x_m = fx[2];
        rec->z_m = fx[3];
        rec->phi_rad = fx[4];
        memcpy(rec->H, fx + 5, sizeof rec->H);
        int finite = 1;
        for (int i = 0; i < 14; i++)
            finite &= isfinite(fx[i]) != 0;
        const unsigned char *q = p + HB_REC_FIXED_BYTES;
        for (uint32_t i = 0; i < n; i++)
            for (int j = 0; j < 4; j++) {
                rec->pts[i][j] = get_f64(q + 32u * i + 8u * (unsigned)j);
                finite &= isfinite(rec->pts[i][j]) != 0;
            }
        if (!finite) {
            seterr(err, err_len, "%s: record %u holds a non-finite value", path, r);
            goto done;
        }
        if (!(fabs(rec->H[4]) > 0.0)) {
            seterr(err, err_len, "%s: record %u: true H has h22 = 0", path, r);
            goto done;
        }
        const unsigned char *fl = q + 32u * n;
        uint32_t count_in = 0;
        for (uint32_t i = 0; i < n; i++) {
            if (fl[i] > 1) {
                seterr(err, err_len, "%s: record %u: inlier flag %u is not 0 or 1", path, r, fl[i]);
                goto done;
            }
            rec->inlier[i] = fl[i];
            count_in += fl[i];
        }
        if (count_in != nin) {
            seterr(err, err_len, "%s: record %u: %u inlier flags set but header says %u", path, r,
                   count_in, nin);
            goto done;
        }
        for (uint64_t b = HB_REC_FIXED_BYTES + 33ull * n; b < rec_bytes(n); b++)
            if (p[b] != 0) {
                seterr(err, err_len, "%s: record %u: non-zero padding", path, r);
                goto done;
            }
        off += rec_bytes(n);
    }
    if (off != len) {
        seterr(err, err_len, "%s: %llu trailing bytes after record %u", path,
               (unsigned long long)(len - off), count - 1);
        goto done;
    }
    rc = 0;
done:
    free(buf);
    if (rc != 0)
        hb_set_free(set);
    return rc;
}
