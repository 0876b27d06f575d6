# Compiles every Q-format source of firmware/src/fixed for a Cortex-M3 (no
# FPU) and fails if an object references a floating-point helper
# (check_symbols.cmake with NO_FLOAT).  With the fixed-point build's setting
# (SPVS_USE_FIXED=1: spvs.h's pipeline is the Q one, spvs_fixed.c is built).
# Usage: cmake -DCC= -DNM= -DSRCDIR= -DINC= -DOBJDIR= -DDOUBLE=0|1 -DCHECK= -P check_fixed_m3.cmake
file(GLOB srcs ${SRCDIR}/*.c)
if(NOT srcs)
  message(FATAL_ERROR "no sources in ${SRCDIR}")
endif()
file(MAKE_DIRECTORY ${OBJDIR})
foreach(src IN LISTS srcs)
  get_filename_component(name ${src} NAME_WE)
  set(OBJ ${OBJDIR}/${name}.o)
  execute_process(
    COMMAND ${CC} -std=c11 -mcpu=cortex-m3 -mthumb -mfloat-abi=soft -Os
            -Wall -Wextra -Werror -Wconversion -Wshadow -Wundef -Wdouble-promotion
            -Wvla -Wstrict-prototypes -Wmissing-prototypes -fno-common
            -I${INC} -I${SRCDIR} -I${SRCDIR}/.. -DSPVS_USE_DOUBLE=${DOUBLE} -DSPVS_USE_FIXED=1
            -c ${src} -o ${OBJ}
    RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cortex-m3 compile of ${name}.c failed: ${err}")
  endif()
  set(LIB "")
  set(NO_FLOAT ON)
  include(${CHECK})
endforeach()
