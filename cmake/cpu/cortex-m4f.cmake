# Cortex-M4 with the single-precision FPU (FPv4-SP-D16), hard-float ABI:
# float arithmetic in hardware, double in software (so the float build of the
# core must contain no double operation).
set(SPVS_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
# The board the images of target/ run on under QEMU, and the CPU's name in
# their banners.
set(SPVS_QEMU_MACHINE mps2-an386)
set(SPVS_CPU_NAME "Cortex-M4F")
