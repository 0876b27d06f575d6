/* common.c - status names and the match list's checks (spvs/common.h). */
#include "spvs/common.h"

const char *spvs_status_str(int status)
{
    switch (status) {
    case SPVS_OK: return "ok";
    case SPVS_E_ARG: return "bad_argument";
    case SPVS_E_TOO_FEW: return "too_few_matches";
    case SPVS_E_NONFINITE: return "non_finite_input";
    case SPVS_E_RANGE: return "out_of_range_input";
    case SPVS_E_CAPACITY: return "over_capacity";
    case SPVS_E_DEGENERATE: return "degenerate";
    case SPVS_E_NO_CONSENSUS: return "no_consensus";
    case SPVS_E_STALE: return "stale_frame";
    case SPVS_E_NO_PARALLAX: return "no_parallax";
    case SPVS_E_PLANE_NZ: return "plane_normal_nz_zero";
    case SPVS_E_PLANE_NY: return "plane_normal_ny_zero";
    case SPVS_E_STEP_TIMEOUT: return "step_timeout";
    case SPVS_E_CONFIG: return "bad_config";
    case SPVS_E_NOT_AT_TARGET: return "not_at_target";
    default: return "unknown_status";
    }
}

int spvs_match_list_check(const spvs_match_t *m, uint16_t n)
{
    if (n > SPVS_MAX_MATCHES) {
        return SPVS_E_CAPACITY;
    }
    if (m == 0 && n > 0) {
        return SPVS_E_ARG;
    }
    if (n < 3u) {
        return SPVS_E_TOO_FEW;
    }
    return SPVS_OK;
}
