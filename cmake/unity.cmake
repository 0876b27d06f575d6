# Unity (ThrowTheSwitch), the framework of the core's unit tests on the host
# and on the Cortex-M images.  Never committed: scripts/install_deps.sh
# fetches it from Debian's source package of cJSON into .deps/unity/src/; a
# folder of one's own is given with -DSPVS_UNITY_DIR=... (or the
# environment's SPVS_UNITY_DIR), holding unity.c, unity.h and
# unity_internals.h, or a src/ folder with them.
#
# spvs_unity_library(NAME [DEFINES ...]): Unity built with
# UNITY_INCLUDE_CONFIG_H and tests/unit/unity_config.h; targets linking it
# get Unity's and tests/unit's headers and the same definitions.
if(NOT SPVS_UNITY_DIR AND DEFINED ENV{SPVS_UNITY_DIR})
  set(SPVS_UNITY_DIR $ENV{SPVS_UNITY_DIR})
endif()
set(SPVS_UNITY_DIR "${SPVS_UNITY_DIR}" CACHE PATH
    "Folder holding Unity's unity.c, unity.h, unity_internals.h (default: .deps/unity)")
set(spvs_unity_dir "")
foreach(dir ${SPVS_UNITY_DIR} ${SPVS_UNITY_DIR}/src ${PROJECT_SOURCE_DIR}/.deps/unity/src)
  if(EXISTS ${dir}/unity.c AND EXISTS ${dir}/unity.h AND EXISTS ${dir}/unity_internals.h)
    set(spvs_unity_dir ${dir})
    break()
  endif()
endforeach()
if(NOT spvs_unity_dir)
  message(FATAL_ERROR "Unity not found (unity.c, unity.h, unity_internals.h) in "
          "'${SPVS_UNITY_DIR}' or ${PROJECT_SOURCE_DIR}/.deps/unity/src: run "
          "scripts/install_deps.sh, which fetches it from Debian's source package "
          "of cJSON, or give its folder with -DSPVS_UNITY_DIR=DIR")
endif()
set(SPVS_UNITY_SOURCE_DIR ${spvs_unity_dir})
set(SPVS_UNIT_TESTS_DIR ${PROJECT_SOURCE_DIR}/tests/unit)

function(spvs_unity_library name)
  cmake_parse_arguments(U "" "" "DEFINES" ${ARGN})
  if(TARGET ${name})
    return()
  endif()
  add_library(${name} STATIC ${SPVS_UNITY_SOURCE_DIR}/unity.c)
  target_include_directories(${name} SYSTEM PUBLIC ${SPVS_UNITY_SOURCE_DIR})
  target_include_directories(${name} PUBLIC ${SPVS_UNIT_TESTS_DIR})
  target_compile_definitions(${name} PUBLIC UNITY_INCLUDE_CONFIG_H ${U_DEFINES})
  # cJSON's copy of unity_internals.h includes ../examples/unity_config.h
  # in place of honouring UNITY_INCLUDE_CONFIG_H, so the settings are also
  # read first into every source that sees Unity's headers.
  target_compile_options(${name} PUBLIC -include ${SPVS_UNIT_TESTS_DIR}/unity_config.h)
endfunction()
