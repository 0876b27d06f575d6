# Fails when a library or object of the core references the heap or stdio,
# and, with NO_FLOAT set, a floating-point helper (__aeabi_f*, __aeabi_d*,
# the libgcc soft-float names) or a libm function: the fixed-point core.
# Usage: cmake -DNM=<nm> -DLIB=<libspvs_core.a> [-DNO_FLOAT=ON] -P check_symbols.cmake
# (or included with NM and OBJ set)
if(NOT LIB AND OBJ)
  set(LIB ${OBJ})
endif()
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE undef RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(heap_stdio malloc calloc realloc free aligned_alloc posix_memalign
    printf fprintf sprintf snprintf vprintf vfprintf vsnprintf puts fputs putchar
    fputc fwrite fread fopen fclose fflush stdout stderr stdin perror
    _malloc_r _free_r _realloc_r _calloc_r)
set(found "")
string(REPLACE "\n" ";" lines "${undef}")
foreach(line IN LISTS lines)
  string(STRIP "${line}" line)
  string(REGEX REPLACE "^U +" "" sym "${line}")
  string(REGEX REPLACE "@.*$" "" sym "${sym}")
  list(FIND heap_stdio "${sym}" at)
  if(NOT at EQUAL -1)
    list(APPEND found ${sym})
  elseif(NO_FLOAT AND (sym MATCHES "^__aeabi_[fd]"
         OR sym MATCHES "^__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord|fix|fixuns|float|floatun|extend|trunc)[sdt]f"
         OR sym MATCHES "^(sqrt|sqrtf|fabs|fabsf|log|logf|exp|expf|sin|sinf|cos|cosf|atan2|atan2f|floor|floorf|ldexp|ldexpf|frexp|frexpf)$"))
    list(APPEND found ${sym})
  endif()
endforeach()
if(found)
  message(FATAL_ERROR "${LIB} references forbidden symbols: ${found}")
endif()
