# Fails when a linked image defines or references the heap, stdio, or any
# double-precision helper (the float build must not compute in double; the
# FPv4-SP FPU has no double instructions, so every double operation is a
# call to an __aeabi_d* routine, and a float -> double conversion is
# __aeabi_f2d).
# Usage: cmake -DNM=<arm-none-eabi-nm> -DIMAGE=<image.elf> -P check_image.cmake
execute_process(COMMAND ${NM} ${IMAGE} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${IMAGE}")
endif()
set(heap_stdio malloc calloc realloc free _malloc_r _free_r _realloc_r _calloc_r
    _sbrk sbrk _sbrk_r printf fprintf sprintf snprintf vfprintf _vfprintf_r _printf_r puts
    fputs putchar fputc fwrite fflush fopen stdout stderr _write
    iprintf fiprintf siprintf sniprintf _vfiprintf_r _svfprintf_r _svfiprintf_r
    scanf sscanf _vfscanf_r getchar fgets _read)
set(found "")
string(REPLACE "\n" ";" lines "${syms}")
foreach(line IN LISTS lines)
  string(REGEX REPLACE "^[0-9a-fA-F]* *[A-Za-z] +" "" sym "${line}")
  list(FIND heap_stdio "${sym}" at)
  if(NOT at EQUAL -1 OR sym MATCHES "^__aeabi_(d|f2d)")
    list(APPEND found ${sym})
  endif()
endforeach()
if(found)
  message(FATAL_ERROR "${IMAGE} contains forbidden symbols: ${found}")
endif()
