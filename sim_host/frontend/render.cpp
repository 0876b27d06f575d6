/* render.cpp - the textured scene and its ray caster (frontend_internal.hpp).
 *
 * Each surface is a plane patch, so the texel seen through image pixel
 * q = (u, v, 1) is a projective function of q: with the ray direction
 * dir = M q (M = R^T K^-1, unit depth in the camera), the hit depth is
 * t = N.(O - c) / N.dir and the texel s = ((c - O).U + t U.dir) / |U|^2.
 * Three dot products and one division per pixel and surface; a depth
 * buffer keeps the nearest hit, so nearer surfaces occlude farther ones. */
#include "frontend_internal.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace simfe {

namespace {

constexpr int kW = 640;
constexpr int kH = 480;
constexpr int kPlaneTex = 2048;      /* texels per side                   */
/* One texel is 12 cm: the plane is 246 m across, so that it fills the
 * view from every Figure 5 pose, and at its usual 50..100 m a pixel of the
 * 400 px camera covers 12..25 cm, one or two texels. */
constexpr double kPlaneTexel = 0.12; /* metres                            */
constexpr int kObjTex = 128;         /* texels per side                   */
/* Object widths: 2.5..5 m at 12..35 m are 30..170 px wide in the 400 px
 * camera, big enough for a handful of features each; their parallax
 * against the plane is what Methods II and III read the signs from. */
constexpr double kObjMinW = 2.5;     /* metres                            */
constexpr double kObjMaxW = 5.0;
constexpr int kAtlasPad = 4;         /* texels between atlas tiles        */
constexpr int kMaxObjectTries = 200; /* placement draws per object        */

double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void scale3(double a[3], double k)
{
    a[0] *= k;
    a[1] *= k;
    a[2] *= k;
}

/* M = R(phi)^T K^-1 for raw pixel coordinates (u, v): the world direction
 * of the ray through pixel (u, v), scaled to unit depth in the camera.
 * The true principal point is at (320 + x0, 240) in raw pixels. */
void ray_matrix(const sim_camera_t &cam, const sim_pose_t &pose, double M[9])
{
    double R[9];
    sim_rot(pose.phi_rad, R);
    const double cx = cam.width_px / 2.0 + cam.x0_px;
    const double cy = cam.height_px / 2.0;
    const double Ki[9] = { 1.0 / cam.alpha_x_px, 0.0, -cx / cam.alpha_x_px,
                           0.0, 1.0 / cam.alpha_y_px, -cy / cam.alpha_y_px,
                           0.0, 0.0, 1.0 };
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            /* (R^T)_{ik} = R_{ki} */
            M[3 * i + j] = R[0 * 3 + i] * Ki[0 * 3 + j] +
                           R[1 * 3 + i] * Ki[1 * 3 + j] +
                           R[2 * 3 + i] * Ki[2 * 3 + j];
        }
    }
}

/* Per-surface coefficients of the projective maps q -> depth, s, t. */
struct Coeffs {
    double B[3];   /* N.dir = B.q                                       */
    double num;    /* N.(O - c)                                         */
    double Au[3];  /* U.dir = Au.q                                      */
    double Av[3];
    double cu;     /* (c - O).U                                         */
    double cv;
    double inv_u2; /* 1 / |U|^2                                         */
    double inv_v2;
};

Coeffs coeffs(const Surface &s, const double M[9], const double c[3])
{
    Coeffs k;
    double N[3];
    cross3(s.U, s.V, N);
    for (int j = 0; j < 3; ++j) {
        k.B[j] = N[0] * M[j] + N[1] * M[3 + j] + N[2] * M[6 + j];
        k.Au[j] = s.U[0] * M[j] + s.U[1] * M[3 + j] + s.U[2] * M[6 + j];
        k.Av[j] = s.V[0] * M[j] + s.V[1] * M[3 + j] + s.V[2] * M[6 + j];
    }
    double oc[3] = { s.O[0] - c[0], s.O[1] - c[1], s.O[2] - c[2] };
    k.num = dot3(N, oc);
    k.cu = -dot3(oc, s.U);
    k.cv = -dot3(oc, s.V);
    k.inv_u2 = 1.0 / dot3(s.U, s.U);
    k.inv_v2 = 1.0 / dot3(s.V, s.V);
    return k;
}

/* An object quad at a random target pixel (margin 40 px) and depth in
 * [zmin_m, zmax_m]: fronto-parallel, kept only when all four corners are
 * nearer than the plane, so that it stands between camera and plane.
 * False when kMaxObjectTries tries place none. */
bool random_object(cv::RNG &rng, const sim_camera_t &cam, const sim_plane_t &pl, double zmin_m,
                   double zmax_m, Surface &o)
{
    const double *n = pl.n;
    for (int tries = 0; tries < kMaxObjectTries; ++tries) {
        double x = rng.uniform(-280.0, 280.0);
        double y = rng.uniform(-200.0, 200.0);
        double Z = rng.uniform(zmin_m, zmax_m);
        double w = rng.uniform(kObjMinW, kObjMaxW);
        double X = (x - cam.x0_px) * Z / cam.alpha_x_px;
        double Yc = y * Z / cam.alpha_y_px;
        double texel = w / kObjTex;
        o.U[0] = texel; o.U[1] = 0.0; o.U[2] = 0.0;
        o.V[0] = 0.0; o.V[1] = texel; o.V[2] = 0.0;
        o.O[0] = X - w / 2; o.O[1] = Yc - w / 2; o.O[2] = Z;
        bool ok = true;
        for (int cy = 0; cy < 2 && ok; ++cy) {
            for (int cx = 0; cx < 2 && ok; ++cx) {
                double P[3] = { o.O[0] + cx * w, o.O[1] + cy * w, Z };
                ok = dot3(n, P) > -pl.d_m;
            }
        }
        if (ok) {
            o.tex_w = o.tex_h = kObjTex;
            o.on_plane = false;
            return true;
        }
    }
    return false;
}

} // namespace

std::string Scene::build(const sim_camera_t &camera, const sim_plane_t &pl,
                         uint64_t seed, int n_objects, double zmin_m,
                         double zmax_m, const std::string &texture)
{
    cam = camera;
    surf.clear();
    const double *n = pl.n;

    /* The plane's texture is centred where the target camera's optical axis
     * meets the plane, which is what the target image mostly shows. */
    if (!(n[2] < -1e-3)) {
        return "the plane is not in front of the target camera (n_z >= 0)";
    }
    double P0[3] = { 0.0, 0.0, pl.d_m / -n[2] };
    /* In-plane axes: e1 horizontal (Y x n), e2 = n x e1 down the slope. */
    const double Y[3] = { 0.0, 1.0, 0.0 };
    double e1[3], e2[3];
    cross3(Y, n, e1);
    double l1 = std::sqrt(dot3(e1, e1));
    if (l1 < 1e-6) {
        return "the plane is horizontal: no view of it";
    }
    scale3(e1, 1.0 / l1);
    cross3(n, e1, e2);
    scale3(e2, 1.0 / std::sqrt(dot3(e2, e2)));

    Surface plane;
    for (int i = 0; i < 3; ++i) {
        plane.U[i] = e1[i] * kPlaneTexel;
        plane.V[i] = e2[i] * kPlaneTexel;
        plane.O[i] = P0[i] - 0.5 * kPlaneTex * (plane.U[i] + plane.V[i]);
    }
    plane.tex_w = plane.tex_h = kPlaneTex;
    plane.atlas_x = plane.atlas_y = 0;
    plane.on_plane = true;
    surf.push_back(plane);

    /* Objects between the camera and the plane (random_object). */
    cv::RNG rng(seed * 0x2545f4914f6cdd1dULL + 0x51ed27ULL);
    const int tile = kObjTex + kAtlasPad;
    /* Object tiles per atlas row: as many as fit in the plane's width. */
    const int per_row = kPlaneTex / tile;
    for (int k = 0; k < n_objects; ++k) {
        Surface o;
        if (!random_object(rng, cam, pl, zmin_m, zmax_m, o)) {
            continue;
        }
        /* Tiles by placed object, so that the rows below count them. */
        const int slot = (int)surf.size() - 1;
        o.atlas_x = (slot % per_row) * tile;
        o.atlas_y = kPlaneTex + kAtlasPad + (slot / per_row) * tile;
        surf.push_back(o);
    }

    /* One atlas: the plane on top, the objects in rows beneath it. */
    int rows = kPlaneTex + kAtlasPad +
               ((int)surf.size() > 1 ? tile * (((int)surf.size() - 2) / per_row + 1)
                                     : 0);
    atlas = cv::Mat(rows, kPlaneTex, CV_8U, cv::Scalar(128));
    cv::Mat plane_tex;
    if (texture.empty()) {
        plane_tex = make_plane_texture(seed, kPlaneTex, kPlaneTex);
    } else {
        std::string why = load_plane_texture(texture, kPlaneTex, kPlaneTex,
                                             plane_tex);
        if (!why.empty()) {
            return why;
        }
    }
    plane_tex.copyTo(atlas(cv::Rect(0, 0, kPlaneTex, kPlaneTex)));
    for (size_t i = 1; i < surf.size(); ++i) {
        make_object_texture(seed * 131 + i, kObjTex)
            .copyTo(atlas(cv::Rect(surf[i].atlas_x, surf[i].atlas_y, kObjTex,
                                   kObjTex)));
    }
    return "";
}

int Scene::cast(const sim_pose_t &pose, double x_px, double y_px,
                double X[3]) const
{
    double M[9];
    ray_matrix(cam, pose, M);
    const double c[3] = { pose.x_m, 0.0, pose.z_m };
    const double q[3] = { x_px + cam.width_px / 2.0, y_px + cam.height_px / 2.0,
                          1.0 };
    int best = -1;
    double best_t = INFINITY;
    for (size_t i = 0; i < surf.size(); ++i) {
        Coeffs k = coeffs(surf[i], M, c);
        double den = dot3(k.B, q);
        if (std::fabs(den) < 1e-12) {
            continue;
        }
        double t = k.num / den;
        if (!(t > SIM_MIN_DEPTH_M) || t >= best_t) {
            continue;
        }
        double s = (k.cu + t * dot3(k.Au, q)) * k.inv_u2;
        double r = (k.cv + t * dot3(k.Av, q)) * k.inv_v2;
        if (s < 0.0 || r < 0.0 || s > surf[i].tex_w - 1 ||
            r > surf[i].tex_h - 1) {
            continue;
        }
        best = (int)i;
        best_t = t;
    }
    if (best >= 0) {
        double dir[3];
        for (int i = 0; i < 3; ++i) {
            dir[i] = dot3(&M[3 * i], q);
        }
        for (int i = 0; i < 3; ++i) {
            X[i] = c[i] + best_t * dir[i];
        }
    }
    return best;
}

void Scene::render(const sim_pose_t &pose, cv::Mat &img, cv::Mat &mapx,
                   cv::Mat &mapy, cv::Mat &depth) const
{
    mapx.create(kH, kW, CV_32F);
    mapy.create(kH, kW, CV_32F);
    depth.create(kH, kW, CV_32F);
    /* Pixels that no surface covers sample far outside the atlas and get
     * the border grey: a featureless sky. */
    mapx.setTo(cv::Scalar(-100.0f));
    mapy.setTo(cv::Scalar(-100.0f));
    depth.setTo(cv::Scalar(INFINITY));

    double M[9];
    ray_matrix(cam, pose, M);
    const double c[3] = { pose.x_m, 0.0, pose.z_m };

    for (const Surface &s : surf) {
        Coeffs k = coeffs(s, M, c);
        /* Objects: only the bounding box of their projected corners, when
         * all four are in front of the camera; the plane: every pixel. */
        int u0 = 0, u1 = kW - 1, v0 = 0, v1 = kH - 1;
        if (!s.on_plane) {
            double R[9];
            sim_rot(pose.phi_rad, R);
            double umin = INFINITY, umax = -INFINITY;
            double vmin = INFINITY, vmax = -INFINITY;
            bool front = true;
            for (int cy = 0; cy < 2 && front; ++cy) {
                for (int cx = 0; cx < 2 && front; ++cx) {
                    double P[3];
                    for (int i = 0; i < 3; ++i) {
                        P[i] = s.O[i] + cx * s.tex_w * s.U[i] +
                               cy * s.tex_h * s.V[i] - c[i];
                    }
                    double Xc = dot3(&R[0], P), Yc = dot3(&R[3], P);
                    double Zc = dot3(&R[6], P);
                    if (Zc <= SIM_MIN_DEPTH_M) {
                        front = false;
                        break;
                    }
                    double u = cam.alpha_x_px * Xc / Zc + cam.x0_px + kW / 2.0;
                    double v = cam.alpha_y_px * Yc / Zc + kH / 2.0;
                    umin = std::min(umin, u); umax = std::max(umax, u);
                    vmin = std::min(vmin, v); vmax = std::max(vmax, v);
                }
            }
            if (front) {
                if (umax < 0 || vmax < 0 || umin > kW - 1 || vmin > kH - 1) {
                    continue;
                }
                u0 = std::max(0, (int)std::floor(umin));
                u1 = std::min(kW - 1, (int)std::ceil(umax));
                v0 = std::max(0, (int)std::floor(vmin));
                v1 = std::min(kH - 1, (int)std::ceil(vmax));
            }
        }
        const double smax = s.tex_w - 1.0, rmax = s.tex_h - 1.0;
        for (int v = v0; v <= v1; ++v) {
            float *px = mapx.ptr<float>(v);
            float *py = mapy.ptr<float>(v);
            float *pd = depth.ptr<float>(v);
            /* Each coefficient is affine in u along a row. */
            double den = k.B[0] * u0 + k.B[1] * v + k.B[2];
            double au = k.Au[0] * u0 + k.Au[1] * v + k.Au[2];
            double av = k.Av[0] * u0 + k.Av[1] * v + k.Av[2];
            for (int u = u0; u <= u1;
                 ++u, den += k.B[0], au += k.Au[0], av += k.Av[0]) {
                if (std::fabs(den) < 1e-12) {
                    continue;
                }
                double t = k.num / den;
                if (!(t > SIM_MIN_DEPTH_M) || t >= pd[u]) {
                    continue;
                }
                double ts = (k.cu + t * au) * k.inv_u2;
                double tr = (k.cv + t * av) * k.inv_v2;
                if (ts < 0.0 || tr < 0.0 || ts > smax || tr > rmax) {
                    continue;
                }
                pd[u] = (float)t;
                px[u] = (float)(ts + s.atlas_x);
                py[u] = (float)(tr + s.atlas_y);
            }
        }
    }
    cv::remap(atlas, img, mapx, mapy, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(128));
}

} // namespace simfe
