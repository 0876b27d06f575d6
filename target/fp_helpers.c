/*
 * fp_helpers.c - the wrappers of fp_helpers.h: one per soft-float helper
 * of libgcc (run-time ABI names) and per libm function the float core
 * calls.  Each wrapper passes its arguments to __real_<name> (ld --wrap)
 * and, while counting is on and no timed call encloses it, counts and times
 * the call.  Under the soft-float ABI float arguments and results travel in
 * core registers, as the helpers expect, so plain C prototypes fit them.
 *
 * The list must name every float helper the core references; the
 * comparison helpers with flag results (__aeabi_cfcmple, ...) are only
 * called from inside libgcc's own __aeabi_fcmp* and need no wrapper.
 */
#include "fp_helpers.h"

#include "board.h"

enum {
    H_FADD,
    H_FSUB,
    H_FRSUB,
    H_FMUL,
    H_FDIV,
    H_FCMPEQ,
    H_FCMPLT,
    H_FCMPLE,
    H_FCMPGE,
    H_FCMPGT,
    H_FCMPUN,
    H_F2IZ,
    H_F2UIZ,
    H_I2F,
    H_UI2F,
    H_SQRTF,
    H_LOGF,
    H_COUNT
};

static fp_helper_stat_t stats[H_COUNT] = {
    [H_FADD] = {"__aeabi_fadd", 0u, 0u},     [H_FSUB] = {"__aeabi_fsub", 0u, 0u},
    [H_FRSUB] = {"__aeabi_frsub", 0u, 0u},   [H_FMUL] = {"__aeabi_fmul", 0u, 0u},
    [H_FDIV] = {"__aeabi_fdiv", 0u, 0u},     [H_FCMPEQ] = {"__aeabi_fcmpeq", 0u, 0u},
    [H_FCMPLT] = {"__aeabi_fcmplt", 0u, 0u}, [H_FCMPLE] = {"__aeabi_fcmple", 0u, 0u},
    [H_FCMPGE] = {"__aeabi_fcmpge", 0u, 0u}, [H_FCMPGT] = {"__aeabi_fcmpgt", 0u, 0u},
    [H_FCMPUN] = {"__aeabi_fcmpun", 0u, 0u}, [H_F2IZ] = {"__aeabi_f2iz", 0u, 0u},
    [H_F2UIZ] = {"__aeabi_f2uiz", 0u, 0u},   [H_I2F] = {"__aeabi_i2f", 0u, 0u},
    [H_UI2F] = {"__aeabi_ui2f", 0u, 0u},     [H_SQRTF] = {"sqrtf", 0u, 0u},
    [H_LOGF] = {"logf", 0u, 0u},
};

static uint32_t counting;
static uint32_t depth;
/* Ticks a timed call costs when the routine is a single return
 * instruction: the two counter reads, the argument moves and the call. */
static uint64_t call_ticks;
/* The call being calibrated lands in `probe`, not in stats[]. */
static fp_helper_stat_t probe;

static void account(fp_helper_stat_t *h, uint64_t t0, uint64_t t1)
{
    uint64_t dt = t1 - t0;
    h->calls++;
    h->ticks += dt > call_ticks ? dt - call_ticks : 0u;
}

/* A timed call of `real` made by `wrapper`, accounted in `stat`. */
#define FP_TIMED(stat, ret, wrapper, real, params, args)                                           \
    ret wrapper params                                                                             \
    {                                                                                              \
        if (counting == 0u || depth != 0u) {                                                       \
            return real args;                                                                      \
        }                                                                                          \
        ++depth;                                                                                   \
        uint64_t t0 = board_ticks();                                                               \
        ret r = real args;                                                                         \
        uint64_t t1 = board_ticks();                                                               \
        --depth;                                                                                   \
        account(stat, t0, t1);                                                                     \
        return r;                                                                                  \
    }

/* One wrapper: the real routine's prototype, the wrapper's prototype (for
 * -Wmissing-prototypes), and the wrapper. */
#define FP_WRAP(which, ret, name, params, args)                                                    \
    ret __real_##name params;                                                                      \
    ret __wrap_##name params;                                                                      \
    FP_TIMED(&stats[which], ret, __wrap_##name, __real_##name, params, args)

/* The calibration's routine: one return instruction, kept out of line and
 * opaque to the optimiser, called through the same timed path. */
__attribute__((noipa)) static float one_instruction(float a, float b)
{
    (void)b;
    return a;
}
__attribute__((noipa)) static float timed_one_instruction(float a, float b);
FP_TIMED(&probe, float, timed_one_instruction, one_instruction, (float a, float b), (a, b))

FP_WRAP(H_FADD, float, __aeabi_fadd, (float a, float b), (a, b))
FP_WRAP(H_FSUB, float, __aeabi_fsub, (float a, float b), (a, b))
FP_WRAP(H_FRSUB, float, __aeabi_frsub, (float a, float b), (a, b))
FP_WRAP(H_FMUL, float, __aeabi_fmul, (float a, float b), (a, b))
FP_WRAP(H_FDIV, float, __aeabi_fdiv, (float a, float b), (a, b))
FP_WRAP(H_FCMPEQ, int, __aeabi_fcmpeq, (float a, float b), (a, b))
FP_WRAP(H_FCMPLT, int, __aeabi_fcmplt, (float a, float b), (a, b))
FP_WRAP(H_FCMPLE, int, __aeabi_fcmple, (float a, float b), (a, b))
FP_WRAP(H_FCMPGE, int, __aeabi_fcmpge, (float a, float b), (a, b))
FP_WRAP(H_FCMPGT, int, __aeabi_fcmpgt, (float a, float b), (a, b))
FP_WRAP(H_FCMPUN, int, __aeabi_fcmpun, (float a, float b), (a, b))
FP_WRAP(H_F2IZ, int, __aeabi_f2iz, (float a), (a))
FP_WRAP(H_F2UIZ, unsigned, __aeabi_f2uiz, (float a), (a))
FP_WRAP(H_I2F, float, __aeabi_i2f, (int a), (a))
FP_WRAP(H_UI2F, float, __aeabi_ui2f, (unsigned a), (a))
FP_WRAP(H_SQRTF, float, sqrtf, (float a), (a))
FP_WRAP(H_LOGF, float, logf, (float a), (a))

void fp_helpers_start(void)
{
    for (uint32_t i = 0; i < H_COUNT; ++i) {
        stats[i].calls = 0u;
        stats[i].ticks = 0u;
    }
    /* The cost of a timed call itself, as the wrappers see it: the
     * smallest of a few timed calls of a one-instruction routine. */
    uint64_t least = UINT64_MAX;
    depth = 0u;
    counting = 1u;
    call_ticks = 0u;
    for (int i = 0; i < 4; ++i) {
        probe.ticks = 0u;
        (void)timed_one_instruction(1.0f, 2.0f);
        if (probe.ticks < least) {
            least = probe.ticks;
        }
    }
    call_ticks = least;
}

void fp_helpers_stop(void)
{
    counting = 0u;
}

uint32_t fp_helpers_count(void)
{
    return H_COUNT;
}

const fp_helper_stat_t *fp_helpers_stat(uint32_t i)
{
    return i < H_COUNT ? &stats[i] : 0;
}
