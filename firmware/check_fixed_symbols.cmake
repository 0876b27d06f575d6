# Fails when the fixed-point kernels' library references a floating-point
# helper (__aeabi_f*, __aeabi_d*, the libgcc soft-float names), a libm
# function, the heap or stdio.
# Usage: cmake -DNM=<nm> -DLIB=<libspvs_fixed.a or .o> -P check_fixed_symbols.cmake
# (or included with NM and OBJ set)
if(NOT LIB AND OBJ)
  set(LIB ${OBJ})
endif()
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE undef RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(found "")
string(REPLACE "\n" ";" lines "${undef}")
foreach(line IN LISTS lines)
  string(STRIP "${line}" line)
  string(REGEX REPLACE "^U +" "" sym "${line}")
  string(REGEX REPLACE "@.*$" "" sym "${sym}")
  if(sym MATCHES "^__aeabi_[fd]" OR sym MATCHES "^__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord|fix|fixuns|float|floatun|extend|trunc)[sdt]f"
     OR sym MATCHES "^(sqrt|sqrtf|fabs|fabsf|log|logf|exp|expf|sin|sinf|cos|cosf|atan2|atan2f|floor|floorf|ldexp|ldexpf|frexp|frexpf)$"
     OR sym MATCHES "^(malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|puts|fputs|putchar|fwrite|stdout|stderr|_malloc_r|_free_r)$")
    list(APPEND found ${sym})
  endif()
endforeach()
if(found)
  message(FATAL_ERROR "${LIB} references forbidden symbols: ${found}")
endif()
