# Toolchain file: GNU Arm Embedded (arm-none-eabi-gcc, Debian's
# gcc-arm-none-eabi with libnewlib-arm-none-eabi), bare metal.
#
#   cmake --preset cortex-m4f
#   cmake -S . -B build/cortex-m4f -G Ninja \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-arm-none-eabi.cmake \
#         -DSPVS_CPU=cortex-m4f -DSPVS_HOST=OFF
#
# SPVS_CPU names a flags file in cmake/cpu/: cortex-m4f (default; QEMU
# mps2-an386) or cortex-m3 (no FPU, soft-float; QEMU mps2-an385).  The file
# sets SPVS_CPU_FLAGS, SPVS_QEMU_MACHINE and SPVS_CPU_NAME.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

# There is no OS to link a test program against: let try_compile build a
# static library instead of an executable.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(SPVS_TOOLCHAIN_PREFIX arm-none-eabi- CACHE STRING "Prefix of the cross tools")
find_program(CMAKE_C_COMPILER ${SPVS_TOOLCHAIN_PREFIX}gcc REQUIRED)
find_program(CMAKE_ASM_COMPILER ${SPVS_TOOLCHAIN_PREFIX}gcc REQUIRED)
find_program(CMAKE_AR ${SPVS_TOOLCHAIN_PREFIX}ar REQUIRED)
find_program(CMAKE_RANLIB ${SPVS_TOOLCHAIN_PREFIX}ranlib REQUIRED)
find_program(CMAKE_NM ${SPVS_TOOLCHAIN_PREFIX}nm REQUIRED)
find_program(CMAKE_OBJCOPY ${SPVS_TOOLCHAIN_PREFIX}objcopy REQUIRED)
find_program(CMAKE_OBJDUMP ${SPVS_TOOLCHAIN_PREFIX}objdump REQUIRED)
find_program(CMAKE_SIZE ${SPVS_TOOLCHAIN_PREFIX}size)

# Per-CPU flags (-mcpu, -mfpu, float ABI) come from one file per core.
set(SPVS_CPU cortex-m4f CACHE STRING "CPU flags file in cmake/cpu/")
if(NOT EXISTS ${CMAKE_CURRENT_LIST_DIR}/cpu/${SPVS_CPU}.cmake)
  file(GLOB spvs_cpus RELATIVE ${CMAKE_CURRENT_LIST_DIR}/cpu ${CMAKE_CURRENT_LIST_DIR}/cpu/*.cmake)
  string(REPLACE ".cmake" "" spvs_cpus "${spvs_cpus}")
  message(FATAL_ERROR "SPVS_CPU=${SPVS_CPU}: no cmake/cpu/${SPVS_CPU}.cmake (known: ${spvs_cpus})")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/cpu/${SPVS_CPU}.cmake)

# Find headers and libraries in the cross sysroot only, programs on the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Each function and object in its own section, so the linker drops what the
# image does not use and the link map shows the core's size per function.
# SPVS_EXTRA_C_FLAGS adds flags without replacing these (setting
# CMAKE_C_FLAGS on the command line would drop the CPU flags), e.g.
# "-fstack-usage -fcallgraph-info=su" for tools/embedded_measure.sh.
set(SPVS_EXTRA_C_FLAGS "" CACHE STRING "Extra C flags for the cross build")
set(CMAKE_C_FLAGS_INIT "${SPVS_CPU_FLAGS} -ffunction-sections -fdata-sections ${SPVS_EXTRA_C_FLAGS}")
set(CMAKE_ASM_FLAGS_INIT "${SPVS_CPU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${SPVS_CPU_FLAGS} -Wl,--gc-sections")
