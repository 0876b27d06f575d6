# Cortex-M3 (ARMv7-M) without an FPU, soft-float ABI: every float operation
# is a call to a libgcc helper (__aeabi_fadd, __aeabi_fmul, __aeabi_fdiv,
# __aeabi_fcmp*, __aeabi_f2iz, ...), and newlib comes from its
# thumb/v7-m/nofp multilib.  The float core built here is the soft-float
# baseline of issue 23; the fixed-point core is the build meant for it.
set(SPVS_CPU_FLAGS "-mcpu=cortex-m3 -mthumb -mfloat-abi=soft")
# QEMU's mps2-an385 (AN385 FPGA image, Cortex-M3): the AN386's memory map,
# UART0, timers and SysTick clock, without the FPU.
set(SPVS_QEMU_MACHINE mps2-an385)
set(SPVS_CPU_NAME "Cortex-M3")
