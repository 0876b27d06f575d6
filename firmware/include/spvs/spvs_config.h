/*
 * spvs_config.h - every buffer size and loop bound of the core, fixed at
 * compile time.
 *
 * Each value has a default guarded by #ifndef, so a build may override it with
 * -D flags or with a user file named by SPVS_USER_CONFIG_FILE (included first).
 * Range checks at the bottom turn a bad choice into a compile error.
 *
 * Memory of one spvs_t instance (see spvs.h) grows with:
 *   SPVS_MAX_MATCHES  x (4 scalars + 4 index bytes + 2 flag bytes)
 *   SPVS_MAX_FEATURES x 1 byte (off-plane memory)
 *   SPVS_MAX_OFFPLANE x (7 scalars + 4 index bytes + 1 flag byte)
 *   SPVS_LO_POINTS    x 1 byte
 * whatever the point layout (points.h); SPVS_INSTANCE_BYTES at the bottom
 * is the sum.
 */
#ifndef SPVS_CONFIG_H
#define SPVS_CONFIG_H

#ifdef SPVS_USER_CONFIG_FILE
#include SPVS_USER_CONFIG_FILE
#endif

/* 1: the core computes in double; 0 (default): float32, as on the MCU. */
#ifndef SPVS_USE_DOUBLE
#define SPVS_USE_DOUBLE 0
#endif

/* 1: the pipeline (spvs.h) runs the fixed-point core of firmware/src/fixed
 * (CMake SPVS_FIXED=ON, docs/FIXED.md); the interface keeps spvs_real, read
 * and written through its bits with integer operations only. 0 (default):
 * the pipeline computes in spvs_real. */
#ifndef SPVS_USE_FIXED
#define SPVS_USE_FIXED 0
#endif

/* Largest number of matches one update accepts. */
#ifndef SPVS_MAX_MATCHES
#define SPVS_MAX_MATCHES 256
#endif

/* Target-image feature indices must be below this (off-plane memory size). */
#ifndef SPVS_MAX_FEATURES
#define SPVS_MAX_FEATURES 512
#endif

/* Most off-plane candidates the epipole estimator looks at in one frame.
 * Its consensus is O(SPVS_MAX_OFFPLANE^2). */
#ifndef SPVS_MAX_OFFPLANE
#define SPVS_MAX_OFFPLANE 64
#endif

/* Epipole consensus: hypotheses tried (spread evenly over the candidates,
 * the remembered off-plane features first); cost SPVS_EPIPOLE_MAX_HYP x
 * SPVS_MAX_OFFPLANE pair tests. */
#ifndef SPVS_EPIPOLE_MAX_HYP
#define SPVS_EPIPOLE_MAX_HYP 16
#endif

/* The controller sees the median of this many frames' epipoles (odd). */
#ifndef SPVS_EPIPOLE_MEDIAN
#define SPVS_EPIPOLE_MEDIAN 5
#endif

/* RANSAC hypotheses: min(adaptive count for the confidence, this cap). */
#ifndef SPVS_RANSAC_MAX_ITERS
#define SPVS_RANSAC_MAX_ITERS 200
#endif

/* Steps of the estimator's final refit (plane_h.c): each solves the
 * joint linear fit on the final inliers with Sampson weights taken at the
 * current H, and is kept only if it lowers their summed Sampson error
 * (docs/ESTIMATION.md). */
#ifndef SPVS_FINAL_STEPS
#define SPVS_FINAL_STEPS 1
#endif

/* The inlier test: a match is an inlier when its squared Sampson error is
 * at most SPVS_INLIER_CHI2_X100 / 100 noise_px^2 (spvs_params_t).  With
 * Gaussian noise of sigma noise_px in both images the squared Sampson error
 * over sigma^2 is chi-square with 2 degrees of freedom; 921 is its 0.99
 * quantile (9.21), so 1 % of true inliers fall outside. */
#ifndef SPVS_INLIER_CHI2_X100
#define SPVS_INLIER_CHI2_X100 921
#endif

/* Fewest plane inliers that make a consensus, and fewest plane candidates
 * a frame must have. */
#ifndef SPVS_MIN_INLIERS
#define SPVS_MIN_INLIERS 8
#endif

/* Inlier re-selection rounds after RANSAC (linear fit -> re-score), ending
 * early once the inlier set stops changing. */
#ifndef SPVS_REFIT_ROUNDS
#define SPVS_REFIT_ROUNDS 4
#endif

/* Points that RANSAC's LO step fits on: the first of the spread order
 * (plane_h.c, est_refine). */
#ifndef SPVS_LO_POINTS
#define SPVS_LO_POINTS 96
#endif

/* RANSAC polishes a new best model (LO step) only when at least
 * 1 / SPVS_LO_MIN_SHARE of the points are its inliers: below that it is
 * almost surely a contaminated sample's model, and polishing it is
 * wasted. */
#ifndef SPVS_LO_MIN_SHARE
#define SPVS_LO_MIN_SHARE 5
#endif

/* The inlier count (points.c) runs in blocks of SPVS_SCORE_BLOCK points (a
 * multiple of 4, the SIMD lanes) and after each block drops a model whose
 * count so far is more than SPVS_BAIL_SIGMAS binomial standard deviations
 * below what a model as good as the best so far would show. */
#ifndef SPVS_SCORE_BLOCK
#define SPVS_SCORE_BLOCK 16
#endif
#ifndef SPVS_BAIL_SIGMAS
#define SPVS_BAIL_SIGMAS 3
#endif

/* Off-plane memory (offplane.h): a target feature's score counts frames in
 * which it was seen off the plane; at SPVS_OFFPLANE_ON it is off the plane,
 * and it stays within SPVS_OFFPLANE_MIN..SPVS_OFFPLANE_MAX.  A plane inlier
 * lowers its score only while the scene's parallax exceeds
 * SPVS_PARALLAX_CLEAR times the off-plane threshold. */
#ifndef SPVS_OFFPLANE_ON
#define SPVS_OFFPLANE_ON 2
#endif
#ifndef SPVS_OFFPLANE_MAX
#define SPVS_OFFPLANE_MAX 3
#endif
#ifndef SPVS_OFFPLANE_MIN
#define SPVS_OFFPLANE_MIN (-3)
#endif
#ifndef SPVS_PARALLAX_CLEAR
#define SPVS_PARALLAX_CLEAR 2
#endif

/* Pixel coordinates are multiplied by 1/SPVS_COORD_SCALE inside the core so
 * that every intermediate stays in a bounded range (a power of two keeps the
 * scaling exact in binary floating and fixed point). */
#ifndef SPVS_COORD_SCALE
#define SPVS_COORD_SCALE 512
#endif

/* Largest |coordinate| in pixels (centred) accepted as input. */
#ifndef SPVS_MAX_COORD_PX
#define SPVS_MAX_COORD_PX 8192
#endif

/* 1: the accelerators are built (src/accel and src/fixed/accel: the
 * frame's points in columns on SIMD lanes where the target has SSE2 or
 * NEON, eight lanes on AVX2, the fixed-point core's integer filters); 0:
 * the reference path alone.  The build option SPVS_ACCEL sets it, and
 * firmware/CMakeLists.txt chooses the point layout's translation unit
 * (points.c, or accel/points_columns.c) from it and the target.  The
 * outputs are the same either way (docs/ESTIMATION.md). */
#ifndef SPVS_ACCEL
#define SPVS_ACCEL 1
#endif

/* 1: where the processor has AVX2 (asked at run time, once per call), the
 * columns' sums and inlier counts take eight points a step instead of four.
 * Each point gets the four-lane operations, and each step's two rows of
 * four go into the four lanes' sums one after the other, so the results are
 * the same bits as with four lanes (and as the rows').  Default: with the
 * accelerators, on x86-64 with GCC 12 or later or Clang, float32; 0
 * elsewhere. */
#ifndef SPVS_AVX2
#if SPVS_ACCEL && !SPVS_USE_DOUBLE && defined(__x86_64__) && \
    (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12))
#define SPVS_AVX2 1
#else
#define SPVS_AVX2 0
#endif
#endif

/* ---- range checks ------------------------------------------------------ */
#if (SPVS_ACCEL != 0) && (SPVS_ACCEL != 1)
#error "SPVS_ACCEL must be 0 or 1"
#endif
#if (SPVS_AVX2 != 0) && (SPVS_AVX2 != 1)
#error "SPVS_AVX2 must be 0 or 1"
#endif
#if SPVS_AVX2 && (!SPVS_ACCEL || SPVS_USE_DOUBLE || !defined(__x86_64__))
#error "SPVS_AVX2 needs SPVS_ACCEL, float32 and x86-64"
#endif
#if (SPVS_USE_DOUBLE != 0) && (SPVS_USE_DOUBLE != 1)
#error "SPVS_USE_DOUBLE must be 0 or 1"
#endif
#if (SPVS_USE_FIXED != 0) && (SPVS_USE_FIXED != 1)
#error "SPVS_USE_FIXED must be 0 or 1"
#endif
#if (SPVS_MAX_MATCHES < 8) || (SPVS_MAX_MATCHES > 4096)
#error "SPVS_MAX_MATCHES must be in 8..4096"
#endif
#if (SPVS_MAX_FEATURES < SPVS_MAX_MATCHES) || (SPVS_MAX_FEATURES > 65535)
#error "SPVS_MAX_FEATURES must be in SPVS_MAX_MATCHES..65535"
#endif
#if (SPVS_MAX_OFFPLANE < 4) || (SPVS_MAX_OFFPLANE > 128)
#error "SPVS_MAX_OFFPLANE must be in 4..128"
#endif
#if (SPVS_EPIPOLE_MAX_HYP < 1) || (SPVS_EPIPOLE_MAX_HYP > SPVS_MAX_OFFPLANE)
#error "SPVS_EPIPOLE_MAX_HYP must be in 1..SPVS_MAX_OFFPLANE"
#endif
#if (SPVS_EPIPOLE_MEDIAN < 1) || (SPVS_EPIPOLE_MEDIAN > 15) || ((SPVS_EPIPOLE_MEDIAN % 2) == 0)
#error "SPVS_EPIPOLE_MEDIAN must be odd, in 1..15"
#endif
#if (SPVS_RANSAC_MAX_ITERS < 1) || (SPVS_RANSAC_MAX_ITERS > 100000)
#error "SPVS_RANSAC_MAX_ITERS must be in 1..100000"
#endif
#if (SPVS_REFIT_ROUNDS < 1) || (SPVS_REFIT_ROUNDS > 8)
#error "SPVS_REFIT_ROUNDS must be in 1..8"
#endif
#if (SPVS_LO_POINTS < 8) || (SPVS_LO_POINTS > 4096)
#error "SPVS_LO_POINTS must be in 8..4096"
#endif
#if (SPVS_FINAL_STEPS < 1) || (SPVS_FINAL_STEPS > 20)
#error "SPVS_FINAL_STEPS must be in 1..20"
#endif
#if (SPVS_INLIER_CHI2_X100 < 100) || (SPVS_INLIER_CHI2_X100 > 10000)
#error "SPVS_INLIER_CHI2_X100 must be in 100..10000"
#endif
#if (SPVS_MIN_INLIERS < 4) || (SPVS_MIN_INLIERS > SPVS_MAX_MATCHES)
#error "SPVS_MIN_INLIERS must be in 4..SPVS_MAX_MATCHES"
#endif
#if (SPVS_LO_MIN_SHARE < 1) || (SPVS_LO_MIN_SHARE > 100)
#error "SPVS_LO_MIN_SHARE must be in 1..100"
#endif
#if (SPVS_SCORE_BLOCK < 4) || (SPVS_SCORE_BLOCK > 64) || ((SPVS_SCORE_BLOCK % 4) != 0)
#error "SPVS_SCORE_BLOCK must be a multiple of 4 in 4..64"
#endif
#if (SPVS_BAIL_SIGMAS < 1) || (SPVS_BAIL_SIGMAS > 10)
#error "SPVS_BAIL_SIGMAS must be in 1..10"
#endif
#if (SPVS_OFFPLANE_MIN > -1) || (SPVS_OFFPLANE_MIN < -100)
#error "SPVS_OFFPLANE_MIN must be in -100..-1"
#endif
#if (SPVS_OFFPLANE_ON < 1) || (SPVS_OFFPLANE_ON > SPVS_OFFPLANE_MAX) || (SPVS_OFFPLANE_MAX > 100)
#error "SPVS_OFFPLANE_ON must be in 1..SPVS_OFFPLANE_MAX, and SPVS_OFFPLANE_MAX at most 100"
#endif
#if (SPVS_PARALLAX_CLEAR < 1) || (SPVS_PARALLAX_CLEAR > 100)
#error "SPVS_PARALLAX_CLEAR must be in 1..100"
#endif
#if (SPVS_COORD_SCALE < 1) || (SPVS_COORD_SCALE > 65536)
#error "SPVS_COORD_SCALE must be in 1..65536"
#endif
#if (SPVS_MAX_COORD_PX < 64) || (SPVS_MAX_COORD_PX > 1000000)
#error "SPVS_MAX_COORD_PX must be in 64..1000000"
#endif

/* ---- controller (control.c) -------------------------------------------- */

/* Method III learns cos phi_t (eq. 8) as a running mean of h11 over the
 * first SPVS_CTL_PHIT_FRAMES frames facing the line, then as an exponential
 * mean of that length, so that it can follow odometry drift. */
#ifndef SPVS_CTL_PHIT_FRAMES
#define SPVS_CTL_PHIT_FRAMES 50
#endif

/* Step 2's least-squares line of the signal against the distance driven is
 * used only while the distances spread by more than this (standard
 * deviation, micrometres): a fit whose distances are all but equal fixes no
 * slope. */
#ifndef SPVS_CTL_FIT_MIN_SPREAD_UM
#define SPVS_CTL_FIT_MIN_SPREAD_UM 32
#endif

/* The arrival check after step 3 (control.h): how many times a failed check
 * may send the robot back to a step before the run ends with
 * SPVS_E_NOT_AT_TARGET, and the most frames one check may average. */
#ifndef SPVS_CTL_ARRIVAL_MAX_REENTRIES
#define SPVS_CTL_ARRIVAL_MAX_REENTRIES 3
#endif
/* Method I's step 1 escapes the false zero of eq. (19) while |e_x| is
 * over this many times lock_ex_px (control_steps.inc, far_from_line). */
#ifndef SPVS_CTL_FALSE_ZERO_LOCKS
#define SPVS_CTL_FALSE_ZERO_LOCKS 4
#endif
/* ... and the bound on the remembered off-plane points' mean parallax, in
 * hundredths of its median at the target, SPVS_CTL_NOISE_PARALLAX_X1000
 * (control_steps.inc, arrival_decide). */
#ifndef SPVS_CTL_ARRIVAL_PARALLAX_X100
#define SPVS_CTL_ARRIVAL_PARALLAX_X100 150
#endif
/* ... and how far it backs off, in decimetres, when the check finds it
 * beside the target (control_steps.inc, reenter). */
#ifndef SPVS_CTL_ARRIVAL_BACKOFF_DM
#define SPVS_CTL_ARRIVAL_BACKOFF_DM 50
#endif
/* ... and how far a step 2 after a re-entry may drive, in decimetres,
 * before it counts as going the wrong way (control_steps.inc,
 * control_update): about as long as the back-off, with its margin. */
#ifndef SPVS_CTL_REENTRY_MAX_DM
#define SPVS_CTL_REENTRY_MAX_DM (2 * SPVS_CTL_ARRIVAL_BACKOFF_DM)
#endif
/* The median parallax that image noise alone gives an off-plane point at
 * the target, in thousandths of arrival_sigma_px (noise in both images):
 * the unit of SPVS_CTL_ARRIVAL_PARALLAX_X100. */
#ifndef SPVS_CTL_NOISE_PARALLAX_X1000
#define SPVS_CTL_NOISE_PARALLAX_X1000 1665
#endif
/* The arrival check's residuals: six entries of H - I, the horizontal and
 * the radial parallax (spvs.h, arrival_k). */
#define SPVS_CTL_ARRIVAL_RESIDUALS 8
/* The least standard deviation of a residual, thousandths of a pixel: exact
 * frames (no spread) divide by it. */
#ifndef SPVS_CTL_ARRIVAL_SD_MIN_MPX
#define SPVS_CTL_ARRIVAL_SD_MIN_MPX 10
#endif
/* The horizontal parallax's dead zone, in tenths of arrival_resolution_px
 * (2 px by default, about 0.08 m sideways on the default scene): a camera
 * whose principal point is tens of pixels off ends that far beside the
 * target (docs/CONTROL.md). */
#ifndef SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10
#define SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10 40
#endif
/* The longest drive of a re-entered step 2 that measures its distance by
 * the first line's slope (control_steps.inc, step_translate_again),
 * decimetres. */
#ifndef SPVS_CTL_REENTRY_DRIVE_MAX_DM
#define SPVS_CTL_REENTRY_DRIVE_MAX_DM 10
#endif
/* The depth correction before the verdict (control_steps.inc): a depth
 * figure over this many tenths of a standard deviation. */
#ifndef SPVS_CTL_ARRIVAL_CORRECT_X10
#define SPVS_CTL_ARRIVAL_CORRECT_X10 10
#endif
#ifndef SPVS_CTL_ARRIVAL_MAX_FRAMES
#define SPVS_CTL_ARRIVAL_MAX_FRAMES 1000
#endif
/* The inlier count the arrival check's noise model takes at the least
 * (control.h's n_inliers: a frame with fewer counts as this many). */
#ifndef SPVS_CTL_ARRIVAL_MIN_INLIERS
#define SPVS_CTL_ARRIVAL_MIN_INLIERS 4
#endif

/* How many times the per-frame scatter of alpha_y h32 is that of h33 (both
 * from the same plane inliers spread over the image; docs/CONTROL.md):
 * Method II's re-entered step 2 reads the distance from the less noisy. */
#ifndef SPVS_CTL_H32_NOISE_RATIO
#define SPVS_CTL_H32_NOISE_RATIO 3
#endif

#if (SPVS_CTL_PHIT_FRAMES < 1) || (SPVS_CTL_PHIT_FRAMES > 100000)
#error "SPVS_CTL_PHIT_FRAMES must be in 1..100000"
#endif
#if (SPVS_CTL_FIT_MIN_SPREAD_UM < 1) || (SPVS_CTL_FIT_MIN_SPREAD_UM > 100000)
#error "SPVS_CTL_FIT_MIN_SPREAD_UM must be in 1..100000"
#endif
#if (SPVS_CTL_H32_NOISE_RATIO < 1) || (SPVS_CTL_H32_NOISE_RATIO > 100)
#error "SPVS_CTL_H32_NOISE_RATIO must be in 1..100"
#endif
#if (SPVS_CTL_ARRIVAL_MAX_REENTRIES < 0) || (SPVS_CTL_ARRIVAL_MAX_REENTRIES > 20)
#error "SPVS_CTL_ARRIVAL_MAX_REENTRIES must be in 0..20"
#endif
#if (SPVS_CTL_FALSE_ZERO_LOCKS < 1) || (SPVS_CTL_FALSE_ZERO_LOCKS > 8)
#error "SPVS_CTL_FALSE_ZERO_LOCKS must be in 1..8"
#endif
#if (SPVS_CTL_ARRIVAL_PARALLAX_X100 < 100) || (SPVS_CTL_ARRIVAL_PARALLAX_X100 > 1000)
#error "SPVS_CTL_ARRIVAL_PARALLAX_X100 must be in 100..1000"
#endif
#if (SPVS_CTL_ARRIVAL_BACKOFF_DM < 1) || (SPVS_CTL_ARRIVAL_BACKOFF_DM > 200)
#error "SPVS_CTL_ARRIVAL_BACKOFF_DM must be in 1..200"
#endif
#if (SPVS_CTL_REENTRY_MAX_DM < 1) || (SPVS_CTL_REENTRY_MAX_DM > 400)
#error "SPVS_CTL_REENTRY_MAX_DM must be in 1..400"
#endif
#if (SPVS_CTL_NOISE_PARALLAX_X1000 < 100) || (SPVS_CTL_NOISE_PARALLAX_X1000 > 10000)
#error "SPVS_CTL_NOISE_PARALLAX_X1000 must be in 100..10000"
#endif
#if (SPVS_CTL_ARRIVAL_MIN_INLIERS < 1) || (SPVS_CTL_ARRIVAL_MIN_INLIERS > 1000)
#error "SPVS_CTL_ARRIVAL_MIN_INLIERS must be in 1..1000"
#endif
#if (SPVS_CTL_ARRIVAL_MAX_FRAMES < 1) || (SPVS_CTL_ARRIVAL_MAX_FRAMES > 65535)
#error "SPVS_CTL_ARRIVAL_MAX_FRAMES must be in 1..65535"
#endif

/* Bytes of one spvs_t instance (spvs.h): the terms above with a scalar of
 * SPVS_SCALAR_BYTES (4 for float, 8 for double; the fixed-point state
 * holds int32 where the float core holds a scalar), two scalars per slot of
 * the epipole's median, and SPVS_INSTANCE_FIXED_BYTES for the parameters,
 * the controller's state and the rest, whose size no setting changes.  The
 * core checks at compile time that its state fits (firmware/src/spvs/
 * instance.h); a state grown past this figure is a compile error there, to
 * be answered here. */
#if SPVS_USE_FIXED || !SPVS_USE_DOUBLE
#define SPVS_SCALAR_BYTES 4
#else
#define SPVS_SCALAR_BYTES 8
#endif
#define SPVS_INSTANCE_FIXED_BYTES (200 * SPVS_SCALAR_BYTES + (SPVS_USE_FIXED ? 512 : 0))
#define SPVS_INSTANCE_BYTES                                                            \
    ((SPVS_MAX_MATCHES) * (4 * SPVS_SCALAR_BYTES + 6) + (SPVS_MAX_FEATURES) +           \
     (SPVS_MAX_OFFPLANE) * (7 * SPVS_SCALAR_BYTES + 5) + (SPVS_LO_POINTS) +             \
     (SPVS_EPIPOLE_MEDIAN) * 2 * SPVS_SCALAR_BYTES + SPVS_INSTANCE_FIXED_BYTES)

#endif /* SPVS_CONFIG_H */
