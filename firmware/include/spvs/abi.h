/*
 * abi.h - the version of spvs, and the core's configuration in a link-time
 * name, so that code built with one configuration never runs against a
 * library built with another.
 *
 * The version (semantic versioning: MAJOR changes break the API, MINOR adds
 * to it, PATCH fixes; before 1.0.0 a MINOR change may also break it) is
 * written here once: the top-level CMakeLists.txt reads it for project(),
 * the CMake package and spvs.pc.
 *
 * spvs_t (spvs.h) is a plain struct the caller allocates, so its layout is
 * fixed by the settings the caller's compiler sees, while the library's code
 * was fixed by the settings the library's compiler saw.  If they differ (a
 * float consumer against a double library, another SPVS_MAX_MATCHES), the
 * library would read and write past the caller's instance.  To make that a
 * link error instead, spvs_init is a macro for a name that spells out every
 * setting that changes the layout of spvs_t:
 *
 *   spvs_init__<float|double|fixed_float|fixed_double>_matches<SPVS_MAX_MATCHES>
 *       _features<SPVS_MAX_FEATURES>_offplane<SPVS_MAX_OFFPLANE>
 *       _lo<SPVS_LO_POINTS>_median<SPVS_EPIPOLE_MEDIAN>
 *
 * e.g. spvs_init__float_matches256_features512_offplane64_lo96_median5.
 * (The point layout is not part of it: spvs_t is the same size in both.)
 * The library defines the name of its own configuration (spvs.c includes this
 * header through spvs.h); a consumer compiled otherwise references another
 * name and the link fails with "undefined reference to spvs_init__double_..."
 * which says the configuration it was compiled for.  `nm -g libspvs_core.a |
 * grep spvs_init__` shows the library's.  Source code keeps calling
 * spvs_init(); nothing else is renamed.
 *
 * The settings must be plain decimal numbers (-DSPVS_MAX_MATCHES=128, not
 * (128)): they are pasted into the name.  Settings that change only the
 * library's behaviour, not the layout (SPVS_RANSAC_MAX_ITERS, SPVS_ACCEL,
 * ...), are not part of it.  A new setting that sizes a member of spvs_t, or
 * of a struct it holds, belongs in SPVS_ABI_INIT below.
 */
#ifndef SPVS_ABI_H
#define SPVS_ABI_H

#include "spvs/spvs_config.h"

#define SPVS_VERSION_MAJOR 0
#define SPVS_VERSION_MINOR 1
#define SPVS_VERSION_PATCH 0
#define SPVS_VERSION_STR_(x) #x
#define SPVS_VERSION_STR(x) SPVS_VERSION_STR_(x)
/* "MAJOR.MINOR.PATCH" */
#define SPVS_VERSION_STRING                                                           \
    SPVS_VERSION_STR(SPVS_VERSION_MAJOR) "." SPVS_VERSION_STR(SPVS_VERSION_MINOR) "." \
    SPVS_VERSION_STR(SPVS_VERSION_PATCH)
/* MAJOR * 10000 + MINOR * 100 + PATCH, for #if comparisons. */
#define SPVS_VERSION_NUMBER                                                    \
    (SPVS_VERSION_MAJOR * 10000 + SPVS_VERSION_MINOR * 100 + SPVS_VERSION_PATCH)

#if SPVS_USE_FIXED && SPVS_USE_DOUBLE
#define SPVS_ABI_SCALAR fixed_double
#elif SPVS_USE_FIXED
#define SPVS_ABI_SCALAR fixed_float
#elif SPVS_USE_DOUBLE
#define SPVS_ABI_SCALAR double
#else
#define SPVS_ABI_SCALAR float
#endif

/* Two levels, so that the settings are expanded before they are pasted. */
#define SPVS_ABI_NAME_(sc, m, f, o, lo, med)                                       \
    spvs_init__##sc##_matches##m##_features##f##_offplane##o##_lo##lo##_median##med
#define SPVS_ABI_NAME(sc, m, f, o, lo, med) SPVS_ABI_NAME_(sc, m, f, o, lo, med)

/* The link name of spvs_init() for the configuration in force. */
#define SPVS_ABI_INIT                                                                \
    SPVS_ABI_NAME(SPVS_ABI_SCALAR, SPVS_MAX_MATCHES, SPVS_MAX_FEATURES, SPVS_MAX_OFFPLANE, \
                  SPVS_LO_POINTS, SPVS_EPIPOLE_MEDIAN)

#define spvs_init SPVS_ABI_INIT

#endif /* SPVS_ABI_H */
