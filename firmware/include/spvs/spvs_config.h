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
 *                       (the 4 scalars in columns with SPVS_SIMD_COLUMNS)
 *   SPVS_MAX_FEATURES x 1 byte (off-plane memory)
 *   SPVS_MAX_OFFPLANE x 3 scalars (+ 4 scalars and 2 index bytes with
 *                       SPVS_SIMD_COLUMNS)
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

/* Most Gauss-Newton steps spvs_h_refit takes (callers ask for fewer; it
 * stops earlier once a step gains under 1e-4 of the cost).  spvs_update
 * starts it from a linear fit on the same inliers and asks for one step
 * (FINAL_GN_STEPS in spvs.c). */
#ifndef SPVS_REFIT_MAX_ITERS
#define SPVS_REFIT_MAX_ITERS 5
#endif

/* Inlier re-selection rounds after RANSAC (linear fit -> re-score), ending
 * early once the inlier set stops changing. */
#ifndef SPVS_REFIT_ROUNDS
#define SPVS_REFIT_ROUNDS 4
#endif

/* Points that RANSAC's LO step fits on: the first of the spread order
 * (spvs.c, est_refine). */
#ifndef SPVS_LO_POINTS
#define SPVS_LO_POINTS 96
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

/* 1: keep the frame's points in columns instead of rows, count inliers in
 * blocks of 16 and run the sums of the linear fit and of the Gauss-Newton
 * refit a block at a time, loops a compiler runs on SIMD lanes (the
 * off-plane candidates are copied out as rows for the epipole:
 * SPVS_MAX_OFFPLANE x 4 more scalars in spvs_t).  0: rows, everything point
 * by point.  The result is the same bits either way; the
 * default is 1 where the compiler says the target has SSE2 or NEON, 0
 * elsewhere (Cortex-M4F).  Compile the core and the code that allocates
 * spvs_t with the same setting. */
#ifndef SPVS_SIMD_COLUMNS
#if defined(__SSE2__) || defined(__ARM_NEON)
#define SPVS_SIMD_COLUMNS 1
#else
#define SPVS_SIMD_COLUMNS 0
#endif
#endif

/* 1: ask the data cache for the frame's matches before they are read in the
 * spread order (a gather the hardware prefetcher cannot follow); measured on
 * the host benchmark, about 8 % less time per estimate when other code ran
 * in between (docs/BENCHMARKS.md).  Default: where SPVS_SIMD_COLUMNS is (a
 * target with a data cache), 0 elsewhere (the Cortex-M4F has none). */
#ifndef SPVS_PREFETCH
#define SPVS_PREFETCH SPVS_SIMD_COLUMNS
#endif

/* ---- range checks ------------------------------------------------------ */
#if (SPVS_SIMD_COLUMNS != 0) && (SPVS_SIMD_COLUMNS != 1)
#error "SPVS_SIMD_COLUMNS must be 0 or 1"
#endif
#if (SPVS_PREFETCH != 0) && (SPVS_PREFETCH != 1)
#error "SPVS_PREFETCH must be 0 or 1"
#endif
#if (SPVS_USE_DOUBLE != 0) && (SPVS_USE_DOUBLE != 1)
#error "SPVS_USE_DOUBLE must be 0 or 1"
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
#if (SPVS_REFIT_MAX_ITERS < 0) || (SPVS_REFIT_MAX_ITERS > 20)
#error "SPVS_REFIT_MAX_ITERS must be in 0..20"
#endif
#if (SPVS_REFIT_ROUNDS < 1) || (SPVS_REFIT_ROUNDS > 8)
#error "SPVS_REFIT_ROUNDS must be in 1..8"
#endif
#if (SPVS_LO_POINTS < 8) || (SPVS_LO_POINTS > 4096)
#error "SPVS_LO_POINTS must be in 8..4096"
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
#ifndef SPVS_CTL_ARRIVAL_MAX_FRAMES
#define SPVS_CTL_ARRIVAL_MAX_FRAMES 1000
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
#if (SPVS_CTL_ARRIVAL_MAX_FRAMES < 1) || (SPVS_CTL_ARRIVAL_MAX_FRAMES > 65535)
#error "SPVS_CTL_ARRIVAL_MAX_FRAMES must be in 1..65535"
#endif

#endif /* SPVS_CONFIG_H */
