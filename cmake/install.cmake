# Install rules, the CMake package and the pkg-config file of spvs
# (included once, at the end of the top-level CMakeLists.txt, when every
# target exists).  Layout under the GNU install dirs (docs/INSTALL.md):
#
#   include/spvs/*.h                 the installed API: spvs.h, status.h,
#                                    abi.h (with the version), spvs_config.h
#   lib/libspvs_core.a               the core
#   lib/cmake/spvs/                  spvsConfig.cmake (spvs::core),
#                                    spvsConfigVersion.cmake, spvsTargets*.cmake
#   lib/pkgconfig/spvs.pc
#   bin/                             spvs-sim, spvs-node, spvs-zenoh-bridge,
#                                    spvs-lcm-spy (host builds)
#   share/spvs/cmake/                the arm-none-eabi toolchain file, cpu/
#   share/spvs/lcm_types/            the .lcm message types
#   share/spvs/python/spvs/          their Python modules (lcm-gen -p)
#   share/spvs/java/spvs_lcm_types.jar  their Java classes, for lcm-spy
#   share/spvs/sim_host/zenoh/       the Zenoh bridge's Python program
#   share/doc/spvs/                  README.md and docs/
#
# Components: core (headers, library, package, pkg-config, toolchain
# files), runtime (programs), lcm (message types), doc.
#   cmake --install BUILD --prefix PREFIX [--component core]
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The top-level project installs by default; a project that pulls spvs in
# with add_subdirectory or FetchContent decides for itself.
if(CMAKE_SOURCE_DIR STREQUAL PROJECT_SOURCE_DIR)
  set(spvs_install_default ON)
else()
  set(spvs_install_default OFF)
endif()
option(SPVS_INSTALL "Generate the install rules of spvs" ${spvs_install_default})

# Where the Zenoh bridge's Python files are in the source tree.  Installed
# under share/spvs/ at the same relative path, so that the bridge finds
# share/spvs/lcm_types/ as it finds lcm_types/ in a checkout.
set(SPVS_ZENOH_BRIDGE_DIR ${PROJECT_SOURCE_DIR}/sim_host/zenoh)

# spvs_core's include directories as the build tree and an installed tree
# each see them: the folders firmware/CMakeLists.txt gives (absolute source
# paths, which cannot go into an installed package) for the build tree only;
# include/ once installed.
get_target_property(spvs_core_inc spvs_core INTERFACE_INCLUDE_DIRECTORIES)
set(spvs_core_iface "")
foreach(dir IN LISTS spvs_core_inc)
  if(dir MATCHES "^\\$<")
    list(APPEND spvs_core_iface "${dir}")
  else()
    list(APPEND spvs_core_iface "$<BUILD_INTERFACE:${dir}>")
  endif()
endforeach()
set_property(TARGET spvs_core PROPERTY INTERFACE_INCLUDE_DIRECTORIES
  ${spvs_core_iface}
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
set_target_properties(spvs_core PROPERTIES EXPORT_NAME core)
# The core calls sqrtf and logf.  The cross build links libm in the image
# (target/), not through the core; an installed core carries it for every
# consumer.
if(CMAKE_CROSSCOMPILING)
  set_property(TARGET spvs_core APPEND PROPERTY INTERFACE_LINK_LIBRARIES $<INSTALL_INTERFACE:m>)
endif()

if(NOT SPVS_INSTALL)
  return()
endif()

if(SPVS_DOUBLE)
  set(SPVS_DOUBLE_BOOL ON)
  set(SPVS_USE_DOUBLE_VALUE 1)
  set(SPVS_SCALAR_NAME double)
else()
  set(SPVS_DOUBLE_BOOL OFF)
  set(SPVS_USE_DOUBLE_VALUE 0)
  set(SPVS_SCALAR_NAME float32)
endif()
if(SPVS_FIXED)
  set(SPVS_FIXED_BOOL ON)
  # The interface's scalar stays spvs_real; the core computes in Q formats.
  set(SPVS_SCALAR_NAME "fixed-point (${SPVS_SCALAR_NAME} interface)")
  set(SPVS_PC_FIXED " -DSPVS_USE_FIXED=1")
else()
  set(SPVS_FIXED_BOOL OFF)
  set(SPVS_PC_FIXED " -DSPVS_USE_FIXED=0")
endif()
set(SPVS_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/spvs)
set(SPVS_INSTALL_TOOLCHAINDIR ${CMAKE_INSTALL_DATADIR}/spvs/cmake)
set(SPVS_INSTALL_SHAREDIR ${CMAKE_INSTALL_DATADIR}/spvs)

# ---- core: headers, library, CMake package, pkg-config -------------------
install(DIRECTORY ${PROJECT_SOURCE_DIR}/firmware/include/spvs
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT core FILES_MATCHING PATTERN "*.h")
install(TARGETS spvs_core EXPORT spvsTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT core)
install(EXPORT spvsTargets NAMESPACE spvs:: FILE spvsTargets.cmake
        DESTINATION ${SPVS_INSTALL_CMAKEDIR} COMPONENT core)

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/spvsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/generated/spvsConfig.cmake
  INSTALL_DESTINATION ${SPVS_INSTALL_CMAKEDIR}
  PATH_VARS SPVS_INSTALL_TOOLCHAINDIR)
# Before 1.0.0 a minor release may change the API, so 0.1 accepts 0.1.x only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/generated/spvsConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/generated/spvsConfig.cmake
              ${PROJECT_BINARY_DIR}/generated/spvsConfigVersion.cmake
        DESTINATION ${SPVS_INSTALL_CMAKEDIR} COMPONENT core)

# spvs.pc finds its prefix from its own place (${pcfiledir}), so an
# installed tree can be moved or installed with --prefix.
set(spvs_pcdir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${spvs_pcdir}")
  set(SPVS_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH spvs_pc_up /r/${spvs_pcdir} /r)
  string(REGEX REPLACE "/$" "" spvs_pc_up "${spvs_pc_up}")
  set(SPVS_PC_PREFIX "\${pcfiledir}/${spvs_pc_up}")
endif()
foreach(kind LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${kind}}")
    set(SPVS_PC_${kind} "${CMAKE_INSTALL_${kind}}")
  else()
    set(SPVS_PC_${kind} "\${prefix}/${CMAKE_INSTALL_${kind}}")
  endif()
endforeach()
set(SPVS_PC_LIBM " -lm")
configure_file(${CMAKE_CURRENT_LIST_DIR}/spvs.pc.in ${PROJECT_BINARY_DIR}/generated/spvs.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/generated/spvs.pc DESTINATION ${spvs_pcdir} COMPONENT core)

# The cross build's toolchain file and CPU flags, for consumers that build
# for the Cortex-M4F (docs/INSTALL.md).
install(FILES ${PROJECT_SOURCE_DIR}/cmake/toolchain-arm-none-eabi.cmake
        DESTINATION ${SPVS_INSTALL_TOOLCHAINDIR} COMPONENT core)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/cmake/cpu
        DESTINATION ${SPVS_INSTALL_TOOLCHAINDIR} COMPONENT core)

# ---- message types ----------------------------------------------------------
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lcm_types/ DESTINATION ${SPVS_INSTALL_SHAREDIR}/lcm_types
        COMPONENT lcm FILES_MATCHING PATTERN "*.lcm")
if(TARGET spvs_lcm_python)
  install(DIRECTORY ${PROJECT_BINARY_DIR}/lcm_types/python/spvs
          DESTINATION ${SPVS_INSTALL_SHAREDIR}/python COMPONENT lcm
          FILES_MATCHING PATTERN "*.py")
endif()
if(TARGET spvs_lcm_jar)
  get_target_property(spvs_jar_file spvs_lcm_jar SPVS_JAR_FILE)
  install(FILES ${spvs_jar_file} DESTINATION ${SPVS_INSTALL_SHAREDIR}/java COMPONENT lcm)
endif()

# ---- programs -------------------------------------------------------------
foreach(prog spvs-sim spvs-node)
  if(TARGET ${prog})
    install(TARGETS ${prog} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  endif()
endforeach()

if(SPVS_HOST AND EXISTS ${SPVS_ZENOH_BRIDGE_DIR}/bridge.py)
  file(RELATIVE_PATH spvs_bridge_rel ${PROJECT_SOURCE_DIR} ${SPVS_ZENOH_BRIDGE_DIR})
  set(spvs_bridge_dest ${SPVS_INSTALL_SHAREDIR}/${spvs_bridge_rel})
  install(DIRECTORY ${SPVS_ZENOH_BRIDGE_DIR}/ DESTINATION ${spvs_bridge_dest}
          COMPONENT runtime FILES_MATCHING PATTERN "*.py" PATTERN "requirements.txt"
          PATTERN "__pycache__" EXCLUDE)
  file(RELATIVE_PATH SPVS_BRIDGE_REL /r/${CMAKE_INSTALL_BINDIR} /r/${spvs_bridge_dest})
  configure_file(${CMAKE_CURRENT_LIST_DIR}/spvs-zenoh-bridge.in
                 ${PROJECT_BINARY_DIR}/generated/spvs-zenoh-bridge @ONLY)
  install(PROGRAMS ${PROJECT_BINARY_DIR}/generated/spvs-zenoh-bridge
          DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()

if(SPVS_HOST AND EXISTS ${PROJECT_SOURCE_DIR}/tools/lcm_spy/spvs-lcm-spy)
  install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/lcm_spy/spvs-lcm-spy
          DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()

# ---- documents --------------------------------------------------------------
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT doc)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT doc)
