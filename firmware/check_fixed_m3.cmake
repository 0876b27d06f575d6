# Compiles the Q-format kernels for a Cortex-M3 (no FPU) and fails if the
# object references a floating-point helper (check_fixed_symbols.cmake).
# Usage: cmake -DCC= -DNM= -DSRC= -DINC= -DOBJ= -DDOUBLE=0|1 -DCHECK= -P check_fixed_m3.cmake
execute_process(
  COMMAND ${CC} -std=c11 -mcpu=cortex-m3 -mthumb -mfloat-abi=soft -Os
          -Wall -Wextra -Werror -Wconversion -Wshadow -Wundef -Wdouble-promotion
          -Wvla -Wstrict-prototypes -Wmissing-prototypes -fno-common
          -I${INC} -DSPVS_USE_DOUBLE=${DOUBLE} -c ${SRC} -o ${OBJ}
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cortex-m3 compile failed: ${err}")
endif()
include(${CHECK})
