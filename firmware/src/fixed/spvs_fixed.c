/*
 * spvs_fixed.c - the pipeline of spvs.h in the fixed-point build
 * (SPVS_FIXED=ON, SPVS_USE_FIXED=1): spvs_t holds the Q pipeline's state
 * (spvs_q.h; spvs/instance.h) and each call is its Q twin, so a program written against
 * spvs.h runs the fixed-point core with nothing else changed.  The
 * parameters' defaults are params.c's, shared with the float build.
 */
#include "spvs/instance.h"

#if !SPVS_USE_FIXED
#error "spvs_fixed.c belongs to the fixed-point build only (SPVS_FIXED=ON)"
#endif

int spvs_init(spvs_t *s, const spvs_params_t *p)
{
    return spvs_q_init(spvs_state(s), p);
}

void spvs_reset(spvs_t *s)
{
    spvs_q_reset(spvs_state(s));
}

int spvs_update(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                spvs_output_t *out)
{
    return spvs_q_update(spvs_state(s), m, n, t_s, out);
}

int spvs_update_with_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                       const spvs_real H_px[9], spvs_output_t *out)
{
    return spvs_q_update_with_h(spvs_state(s), m, n, t_s, H_px, out);
}

spvs_real spvs_inlier_px(const spvs_params_t *p)
{
    return spvs_q_inlier_px(p);
}

int spvs_estimate_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    return spvs_q_estimate_h(spvs_state(s), m, n, out);
}

spvs_step_t spvs_step(const spvs_t *s)
{
    return spvs_state_c(s)->ctl.step;
}
