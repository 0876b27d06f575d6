# Fails when the core library references the heap or stdio.
# Usage: cmake -DNM=<nm> -DLIB=<libspvs_core.a> -P check_symbols.cmake
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE undef RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(forbidden malloc calloc realloc free aligned_alloc posix_memalign
    printf fprintf sprintf snprintf vprintf vfprintf vsnprintf puts fputs putchar
    fputc fwrite fread fopen fclose fflush stdout stderr stdin perror
    _malloc_r _free_r _realloc_r _calloc_r __aeabi_d2f_unused)
set(found "")
string(REPLACE "\n" ";" lines "${undef}")
foreach(line IN LISTS lines)
  string(STRIP "${line}" line)
  string(REGEX REPLACE "^U +" "" sym "${line}")
  string(REGEX REPLACE "@.*$" "" sym "${sym}")
  list(FIND forbidden "${sym}" at)
  if(NOT at EQUAL -1)
    list(APPEND found ${sym})
  endif()
endforeach()
if(found)
  message(FATAL_ERROR "spvs_core references forbidden symbols: ${found}")
endif()
