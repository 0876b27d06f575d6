#!/usr/bin/python3
"""Generate tests/golden/golden_vectors.h: ground-truth planar-motion
homographies and epipoles for the core's host test and the Cortex-M4F image.

Geometry (DESIGN.md section 1, paper eqs. (2), (3)):
  target camera P1 = K[I|0], current camera P2 = K[R | -R c],
  R = R(phi) of eq. (3), c = (x, 0, z) in metres,
  plane n^T X = -d (d > 0, n points from the plane towards the target camera),
  H_cur_tgt = K R (I + c n^T / d) K^-1, normalised so h22 = 1,
  K = diag(800, 800, 1) on pixels centred on the principal point.
  Epipole (image of the target camera centre in the current image):
  e = K (-R c); e_x = alpha * e_cam[0] / e_cam[2] with e_cam = -R c.

Every case is drawn from one fixed seed, so the header is reproducible:
  tools/gen_golden.py > tests/golden/golden_vectors.h      (or -o FILE)
The literals are written with 17 significant digits; the element type is the
macro SPVS_GOLDEN_T (double unless the includer defines it), so a float build
converts them at compile time and never runs a double operation.
"""

import argparse
import sys

import numpy as np

ALPHA = 800.0          # focal length, pixels (6 mm / 7.5 um)
W, HGT = 640, 480      # image size, pixels; centred coordinates +-320, +-240
SEED = 20070601        # fixed: the vectors are committed
N_H_CASES = 24         # homography cases
N_E_CASES = 16         # epipole cases
N_NOISY = 40           # noisy plane points per homography case
NOISE_PX = 0.5         # sigma of the pixel noise on both images
N_OFF = 12             # off-plane points per epipole case
K = np.diag([ALPHA, ALPHA, 1.0])
KI = np.linalg.inv(K)
CORNERS = np.array([[-320.0, -240.0], [320.0, -240.0],
                    [320.0, 240.0], [-320.0, 240.0]])


def rot(phi):
    """R(phi) of eq. (3): world (target camera) -> current camera."""
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def homography(x, z, phi, n, d):
    """Eq. (2), normalised so h22 = 1 (it is 1 already under planar motion)."""
    c = np.array([x, 0.0, z])
    H = K @ rot(phi) @ (np.eye(3) + np.outer(c, n) / d) @ KI
    return H / H[1, 1]


def project_cur(x, z, phi, X):
    """Current-image pixels (centred) and depth of world points X (m x 3)."""
    c = np.array([x, 0.0, z])
    Xc = (rot(phi) @ (X - c).T).T
    p = (K @ Xc.T).T
    return p[:, :2] / p[:, 2:3], Xc[:, 2]


def in_image(p, margin=0.0):
    return (np.abs(p[:, 0]) <= 320.0 - margin) & (np.abs(p[:, 1]) <= 240.0 - margin)


def transfer(H, p):
    q = (H @ np.column_stack([p, np.ones(len(p))]).T).T
    return q[:, :2] / q[:, 2:3]


def refit(H0, pts):
    """Least-squares planar H minimising the current-image transfer error
    (Gauss-Newton in double, to convergence): the reference optimum."""
    H = H0.copy()
    idx = [(0, 0), (0, 1), (0, 2), (2, 0), (2, 1), (2, 2)]
    for _ in range(50):
        J, r = [], []
        for xt, yt, xc, yc in pts:
            den = H[2, 0] * xt + H[2, 1] * yt + H[2, 2]
            u = (H[0, 0] * xt + H[0, 1] * yt + H[0, 2]) / den
            vv = yt / den
            r += [xc - u, yc - vv]
            ju = [xt / den, yt / den, 1.0 / den,
                  -u * xt / den, -u * yt / den, -u / den]
            jv = [0.0, 0.0, 0.0, -vv * xt / den, -vv * yt / den, -vv / den]
            J += [ju, jv]
        J, r = np.array(J), np.array(r)
        # Column scaling keeps the normal equations well conditioned in pixels.
        s = np.linalg.norm(J, axis=0)
        step = np.linalg.lstsq(J / s, r, rcond=None)[0] / s
        for k, (i, j) in enumerate(idx):
            H[i, j] += step[k]
        if np.max(np.abs(step / np.array([1, 1, 100, 1e-3, 1e-3, 1]))) < 1e-14:
            break
    return H


def corner_err(Ha, Hb):
    return float(np.mean(np.linalg.norm(transfer(Ha, CORNERS) - transfer(Hb, CORNERS), axis=1)))


def tri_area(p):
    a, b, c = p
    return 0.5 * abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def random_plane(rng):
    """Unit normal, mostly facing the target camera (n_z < 0); a few are
    side walls with n_z ~ 0."""
    if rng.random() < 0.85:
        n = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-0.7, 0.7), -1.0])
    else:
        n = np.array([rng.choice([-1.0, 1.0]), rng.uniform(-0.3, 0.3),
                      rng.uniform(-0.15, 0.05)])
    return n / np.linalg.norm(n), rng.uniform(10.0, 60.0)


def random_pose(rng):
    return (rng.uniform(-8.0, 8.0), rng.uniform(-12.0, 8.0),
            np.radians(rng.uniform(-60.0, 60.0)))


def plane_points(rng, pose, n, d, count):
    """Target pixels of plane points seen by both cameras (noise-free)."""
    x, z, phi = pose
    out = np.zeros((0, 4))
    for _ in range(40):
        pt = np.column_stack([rng.uniform(-320, 320, 400), rng.uniform(-240, 240, 400)])
        ray = (KI @ np.column_stack([pt, np.ones(len(pt))]).T).T
        nr = ray @ n
        ok = nr < -1e-6
        Zt = np.where(ok, -d / np.where(ok, nr, -1.0), 0.0)
        ok &= (Zt > 1.0) & (Zt < 200.0)
        X = ray * Zt[:, None]
        pc, zc = project_cur(x, z, phi, X)
        ok &= (zc > 1.0) & in_image(pc)
        out = np.vstack([out, np.column_stack([pt[ok], pc[ok]])])
        if len(out) >= count:
            return out[:count]
    return None


def make_h_case(rng):
    while True:
        pose = random_pose(rng)
        n, d = random_plane(rng)
        x, z, phi = pose
        # Both cameras on the side of the plane the normal points to.
        if n @ np.array([x, 0.0, z]) <= -0.9 * d:
            continue
        pts = plane_points(rng, pose, n, d, 200)
        if pts is None:
            continue
        H = homography(x, z, phi, n, d)
        # Exact triple: well spread in both images, and every point well off
        # the horizon row y = 0, where its y-equation (homography.h) is 0 = 0.
        exact = None
        for _ in range(200):
            tri = pts[rng.choice(len(pts), 3, replace=False)]
            if (tri_area(tri[:, :2]) > 20000.0 and tri_area(tri[:, 2:]) > 20000.0
                    and np.min(np.abs(tri[:, 1])) > 40.0):
                exact = tri
                break
        if exact is None:
            continue
        clean = pts[rng.choice(len(pts), N_NOISY, replace=False)]
        noisy = clean + rng.normal(0.0, NOISE_PX, clean.shape)
        # Start index triple for the refit, spread like a good RANSAC sample.
        start = None
        for _ in range(200):
            tri = rng.choice(N_NOISY, 3, replace=False)
            if tri_area(noisy[tri, :2]) > 20000.0 and np.min(np.abs(noisy[tri, 1])) > 40.0:
                start = tri
                break
        if start is None:
            continue
        Hfit = refit(H, noisy)
        Hfit /= Hfit[1, 1]
        err_fit = corner_err(Hfit, H)
        # The test's 0.5 px bound needs a margin over what the optimum reaches.
        if err_fit > 0.35:
            continue
        return dict(pose=pose, n=n, d=d, H=H, exact=exact, noisy=noisy,
                    start=start, Hfit=Hfit, err_fit=err_fit)


def make_e_case(rng):
    while True:
        pose = random_pose(rng)
        n, d = random_plane(rng)
        x, z, phi = pose
        c = np.array([x, 0.0, z])
        if n @ c <= -0.9 * d or np.hypot(x, z) < 2.0:
            continue
        e_cam = -rot(phi) @ c
        if abs(e_cam[2]) < 1e-3:
            continue
        e_x = ALPHA * e_cam[0] / e_cam[2]
        # Stay clear of the estimator's clamp (the epipole near infinity).
        if abs(e_x) > 4000.0:
            continue
        H = homography(x, z, phi, n, d)
        offp = []
        for _ in range(400):
            pt = np.array([rng.uniform(-320, 320), rng.uniform(-240, 240)])
            ray = KI @ np.array([pt[0], pt[1], 1.0])
            nr = ray @ n
            if nr >= -1e-6:
                continue
            z_plane = -d / nr
            # Between the target camera and the plane: gamma > 0 (epipole.h).
            lo, hi = 0.3 * z_plane, 0.85 * z_plane
            if hi < 3.0:
                continue
            Zt = rng.uniform(max(lo, 3.0), hi)
            X = ray * Zt
            pc, zc = project_cur(x, z, phi, X[None, :])
            if zc[0] < 1.0 or not in_image(pc)[0]:
                continue
            par = np.linalg.norm(pc[0] - transfer(H, pt[None, :])[0])
            if par < 3.0:
                continue
            offp.append([pt[0], pt[1], pc[0, 0], pc[0, 1]])
            if len(offp) == N_OFF:
                break
        if len(offp) < N_OFF:
            continue
        # Cross-check the closed form of the straight line of step 2:
        # with x = -z tan(phi_t), e_x = alpha tan(phi - phi_t).
        if abs(z) > 1e-6:
            phi_t = np.arctan(-x / z)
            assert abs(ALPHA * np.tan(phi - phi_t) - e_x) < 1e-6 * max(1.0, abs(e_x))
        return dict(pose=pose, n=n, d=d, H=H, e_cam=e_cam, e_x=e_x,
                    pts=np.array(offp))


def lit(v):
    s = "%.17g" % float(v)
    if "." not in s and "e" not in s and "inf" not in s and "nan" not in s:
        s += ".0"
    return s


def arr(vals, per_line=4, indent="        "):
    vals = [lit(v) for v in np.ravel(vals)]
    lines = [", ".join(vals[i:i + per_line]) for i in range(0, len(vals), per_line)]
    return (",\n" + indent).join(lines)


def emit(out, hcases, ecases):
    w = out.write
    w("""/*
 * golden_vectors.h - ground truth for the core: planar-motion homographies
 * (eq. 2 with R of eq. 3) and epipoles e = K(-R c).
 *
 * GENERATED by tools/gen_golden.py (seed %d); do not edit by hand, rerun it.
 * Pixels are centred on the principal point, alpha = %g px, 640x480.
 * Element type: SPVS_GOLDEN_T (double unless defined before inclusion), so a
 * float build converts every literal at compile time.
 */
#ifndef SPVS_GOLDEN_VECTORS_H
#define SPVS_GOLDEN_VECTORS_H

#include <stdint.h>

#ifndef SPVS_GOLDEN_T
#define SPVS_GOLDEN_T double
#endif

#define SPVS_GOLDEN_ALPHA_PX %s
#define SPVS_GOLDEN_NOISE_PX %s
#define SPVS_GOLDEN_N_H %d
#define SPVS_GOLDEN_N_NOISY %d
#define SPVS_GOLDEN_N_E %d
#define SPVS_GOLDEN_N_OFF %d

/* One homography case.  Points are {x_tgt, y_tgt, x_cur, y_cur}, pixels. */
typedef struct {
    SPVS_GOLDEN_T x_m, z_m, phi_rad;  /* current pose, target frame         */
    SPVS_GOLDEN_T n[3];               /* unit plane normal, n^T X = -d       */
    SPVS_GOLDEN_T d_m;                /* plane distance, m                   */
    SPVS_GOLDEN_T H[9];               /* true H_cur_tgt, pixels, h22 = 1     */
    SPVS_GOLDEN_T exact[3][4];        /* exact plane matches (minimal set)   */
    SPVS_GOLDEN_T noisy[%d][4];       /* plane matches, %g px noise both images */
    uint8_t start[3];                 /* noisy points whose solve3 starts the refit */
    SPVS_GOLDEN_T H_fit[9];           /* least-squares optimum on noisy, pixels */
    SPVS_GOLDEN_T fit_corner_err_px;  /* mean corner error of H_fit vs H     */
} spvs_golden_h_t;

/* One epipole case: off-plane points between the target camera and the plane
 * (gamma > 0), noise-free.  e_cam = -R c (metres, current camera frame);
 * e_x_px = alpha * e_cam[0] / e_cam[2]; dir_z of the estimate has the sign
 * of e_cam[2] (target in front of the current camera when positive). */
typedef struct {
    SPVS_GOLDEN_T x_m, z_m, phi_rad;
    SPVS_GOLDEN_T n[3];
    SPVS_GOLDEN_T d_m;
    SPVS_GOLDEN_T H[9];               /* true H_cur_tgt, pixels, h22 = 1     */
    SPVS_GOLDEN_T pts[%d][4];         /* off-plane matches, pixels           */
    SPVS_GOLDEN_T e_cam[3];
    SPVS_GOLDEN_T e_x_px;
} spvs_golden_e_t;

""" % (SEED, ALPHA, lit(ALPHA), lit(NOISE_PX), len(hcases), N_NOISY, len(ecases), N_OFF,
       N_NOISY, NOISE_PX, N_OFF))
    w("static const spvs_golden_h_t spvs_golden_h[SPVS_GOLDEN_N_H] = {\n")
    for k, c in enumerate(hcases):
        x, z, phi = c["pose"]
        w("    { /* case %d: x %.3f m, z %.3f m, phi %.2f deg, d %.2f m */\n"
          % (k, x, z, np.degrees(phi), c["d"]))
        w("        %s, %s, %s,\n" % (lit(x), lit(z), lit(phi)))
        w("        {%s},\n" % arr(c["n"], 3))
        w("        %s,\n" % lit(c["d"]))
        w("        {%s},\n" % arr(c["H"], 3, "         "))
        w("        {%s},\n" % ", ".join("{%s}" % arr(p, 4) for p in c["exact"]))
        w("        {\n")
        for p in c["noisy"]:
            w("            {%s},\n" % arr(p, 4))
        w("        },\n")
        w("        {%d, %d, %d},\n" % tuple(int(i) for i in c["start"]))
        w("        {%s},\n" % arr(c["Hfit"], 3, "         "))
        w("        %s\n" % lit(c["err_fit"]))
        w("    },\n")
    w("};\n\n")
    w("static const spvs_golden_e_t spvs_golden_e[SPVS_GOLDEN_N_E] = {\n")
    for k, c in enumerate(ecases):
        x, z, phi = c["pose"]
        w("    { /* case %d: x %.3f m, z %.3f m, phi %.2f deg, e_x %.2f px */\n"
          % (k, x, z, np.degrees(phi), c["e_x"]))
        w("        %s, %s, %s,\n" % (lit(x), lit(z), lit(phi)))
        w("        {%s},\n" % arr(c["n"], 3))
        w("        %s,\n" % lit(c["d"]))
        w("        {%s},\n" % arr(c["H"], 3, "         "))
        w("        {\n")
        for p in c["pts"]:
            w("            {%s},\n" % arr(p, 4))
        w("        },\n")
        w("        {%s},\n" % arr(c["e_cam"], 3))
        w("        %s\n" % lit(c["e_x"]))
        w("    },\n")
    w("};\n\n#endif /* SPVS_GOLDEN_VECTORS_H */\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", help="header to write (default: stdout)")
    args = ap.parse_args()
    rng = np.random.default_rng(SEED)
    hcases = [make_h_case(rng) for _ in range(N_H_CASES)]
    ecases = [make_e_case(rng) for _ in range(N_E_CASES)]
    # Both signs of e_z must be covered, or the dir_z check proves little.
    signs = {bool(c["e_cam"][2] > 0) for c in ecases}
    if len(signs) != 2:
        sys.exit("gen_golden: epipole cases cover one sign of e_z only; change SEED")
    if args.output:
        with open(args.output, "w") as f:
            emit(f, hcases, ecases)
    else:
        emit(sys.stdout, hcases, ecases)
    worst = max(c["err_fit"] for c in hcases)
    print("gen_golden: %d H cases (worst optimum corner error %.3f px), %d epipole cases"
          % (len(hcases), worst, len(ecases)), file=sys.stderr)


if __name__ == "__main__":
    main()
