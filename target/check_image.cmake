# Fails when a linked image (or an archive such as libspvs_core.a) defines or
# references the heap, stdio, or a floating-point helper it must not use.
#
# Default (the float build): no double-precision helper.  The core must not
# compute in double; the FPv4-SP FPU has no double instructions, so every
# double operation is a call to an __aeabi_d* routine, and a float -> double
# conversion is __aeabi_f2d.
#
# FORBID_FLOAT=ON (the fixed-point build): no floating-point helper at all,
# single or double: the run-time ABI's __aeabi_f* and __aeabi_d*
# (arithmetic, comparisons, conversions to integers), the int -> float
# conversions __aeabi_[u]i2f / __aeabi_[u]l2f (and their double forms), the
# flag-setting comparisons __aeabi_cf* / __aeabi_cd*, and libgcc's generic
# names of the same routines (__addsf3, __mulsf3, __floatsisf, __ltsf2,
# __extendsfdf2, ...), which an image links beside or instead of the ABI
# names.
#
# Usage: cmake -DNM=<arm-none-eabi-nm> -DIMAGE=<image.elf> [-DFORBID_FLOAT=ON]
#              -P check_image.cmake
if(NOT NM OR NOT IMAGE)
  message(FATAL_ERROR "usage: cmake -DNM=<nm> -DIMAGE=<image.elf> [-DFORBID_FLOAT=ON] -P check_image.cmake")
endif()
if(NOT EXISTS "${IMAGE}")
  message(FATAL_ERROR "check_image: no such file ${IMAGE}")
endif()
execute_process(COMMAND ${NM} ${IMAGE} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${IMAGE}")
endif()
set(heap_stdio malloc calloc realloc free _malloc_r _free_r _realloc_r _calloc_r
    _sbrk sbrk _sbrk_r printf fprintf sprintf snprintf vfprintf _vfprintf_r _printf_r puts
    fputs putchar fputc fwrite fflush fopen stdout stderr _write
    iprintf fiprintf siprintf sniprintf _vfiprintf_r _svfprintf_r _svfiprintf_r
    scanf sscanf _vfscanf_r getchar fgets _read)
set(double_helpers "^__aeabi_(d|f2d)")
# Every soft-float routine of libgcc for SFmode (sf) and DFmode (df), by
# its ABI name or its generic name.
set(float_helpers
    "^__aeabi_([fd]|c[fd]|u?i2[fd]$|u?l2[fd]$)"
    "^__(add|sub|mul|div|neg)[sd]f3$"
    "^__(eq|ne|lt|le|gt|ge|cmp|unord)[sd]f2$"
    "^__fix(uns)?[sd]f[sdt]i$"
    "^__float(un)?[sdt]i[sd]f$"
    "^__(extendsfdf2|truncdfsf2)$")
if(FORBID_FLOAT)
  set(forbidden_patterns ${float_helpers})
  set(what "heap, stdio and floating-point helpers")
else()
  set(forbidden_patterns ${double_helpers})
  set(what "heap, stdio and double-precision helpers")
endif()
set(found "")
string(REPLACE "\n" ";" lines "${syms}")
foreach(line IN LISTS lines)
  # Symbol lines only ("ADDR T name", "         U name"); an archive's
  # "member.o:" headers and blank lines are skipped.
  if(NOT line MATCHES "^[0-9a-fA-F]* *[A-Za-z] +[^ ]+$")
    continue()
  endif()
  string(REGEX REPLACE "^[0-9a-fA-F]* *[A-Za-z] +" "" sym "${line}")
  list(FIND heap_stdio "${sym}" at)
  set(bad OFF)
  if(NOT at EQUAL -1)
    set(bad ON)
  endif()
  foreach(pattern IN LISTS forbidden_patterns)
    if(sym MATCHES "${pattern}")
      set(bad ON)
    endif()
  endforeach()
  if(bad)
    list(APPEND found ${sym})
  endif()
endforeach()
if(found)
  list(REMOVE_DUPLICATES found)
  list(SORT found)
  message(FATAL_ERROR "${IMAGE} contains forbidden symbols (${what}): ${found}")
endif()
