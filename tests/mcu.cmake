# The controller on the emulated Cortex-M4F in the closed loop (label mcu):
# the serial codec's unit test, the closed loop through QEMU against the
# in-process run, the link faults, and the application image check.  The
# images come from the cross build of tests/target.cmake (fixture
# spvs_cross).  Tests that need QEMU or the cross compiler exit 77, which
# ctest reports as skipped with the reason, where either is missing.
if(NOT TARGET spvs_serial)
  return()
endif()
spvs_add_test(NAME test_serial SOURCES test_serial.c LIBS spvs_serial
              LABELS "mcu;unit" TIMEOUT 60)
# The codec's integer conversions (the fixed-point build's, for an MCU
# without FPU) against the float arithmetic, bit for bit, in every build:
# the codec's source compiled into the test with SPVS_SERIAL_INT_CONV=1.
spvs_add_test(NAME test_serial_bits
              SOURCES test_serial_bits.c ${PROJECT_SOURCE_DIR}/serial/spvs_serial.c
              LABELS "mcu;unit" TIMEOUT 120)
target_compile_definitions(test_serial_bits PRIVATE SPVS_SERIAL_INT_CONV=1)
target_include_directories(test_serial_bits PRIVATE ${PROJECT_SOURCE_DIR}/serial)

if(NOT TARGET spvs-serial-agent OR NOT TARGET spvs-sim OR SPVS_DOUBLE OR SPVS_SANITIZE)
  return()
endif()
# The application of the build's core: the Cortex-M4F's float one, or in
# the fixed-point build the Cortex-M3's fixed-point one (tests/target.cmake).
set(spvs_mcu_image ${CMAKE_BINARY_DIR}/cortex-m4f/target/spvs_app.elf)
set(spvs_mcu_image_fixed ${CMAKE_BINARY_DIR}/cortex-m3-fixed/target/spvs_app.elf)
if(SPVS_FIXED)
  set(spvs_mcu_image ${spvs_mcu_image_fixed})
endif()
find_program(SPVS_ARM_GCC_MCU arm-none-eabi-gcc)
find_program(SPVS_QEMU_ARM_MCU qemu-system-arm)
set(spvs_mcu_fixture "")
set(spvs_mcu_fixture_fixed "")
if(SPVS_ARM_GCC_MCU AND SPVS_QEMU_ARM_MCU)
  set(spvs_mcu_fixture spvs_cross)
  set(spvs_mcu_fixture_fixed spvs_cross_m3_fixed)
  if(SPVS_FIXED)
    set(spvs_mcu_fixture spvs_cross_m3_fixed)
  endif()
endif()

function(spvs_mcu_test name)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "${spvs_variant};mcu;process" TIMEOUT 900
                       SKIP_RETURN_CODE 77 FIXTURES_REQUIRED "${spvs_mcu_fixture}")
endfunction()

# Bit for bit: each method, with noise and mismatches.
set(spvs_mcu_cases
  "1\;-2,-8,-20\;3"
  "2\;2,-9,25\;4"
  "3\;0.8,-6,-20\;5")
foreach(c IN LISTS spvs_mcu_cases)
  list(GET c 0 method)
  list(GET c 1 pose)
  list(GET c 2 seed)
  spvs_mcu_test(mcu_closed_loop_m${method} ${CMAKE_CURRENT_SOURCE_DIR}/mcu/closed_loop.sh
                $<TARGET_FILE:spvs-sim> ${spvs_mcu_image} --method ${method} --pose ${pose}
                --noise 0.5 --outliers 0.1 --seed ${seed} --dt 0.2)
endforeach()

# The fixed-point core on the emulated Cortex-M3 (no FPU) in the closed
# loop over the serial link: bit for bit the host's fixed-point core
# (--ref fixed), each method.  (In the fixed-point build the runs above are
# these already.)
if(NOT SPVS_FIXED)
  foreach(c IN LISTS spvs_mcu_cases)
    list(GET c 0 method)
    list(GET c 1 pose)
    list(GET c 2 seed)
    add_test(NAME mcu_closed_loop_fixed_m${method}
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mcu/closed_loop.sh --ref fixed
                     $<TARGET_FILE:spvs-sim> ${spvs_mcu_image_fixed} --method ${method}
                     --pose ${pose} --noise 0.5 --outliers 0.1 --seed ${seed} --dt 0.2)
    set_tests_properties(mcu_closed_loop_fixed_m${method} PROPERTIES
                         LABELS "fixed;mcu;process" TIMEOUT 900 SKIP_RETURN_CODE 77
                         FIXTURES_REQUIRED "${spvs_mcu_fixture_fixed}")
  endforeach()
endif()

# Link faults (tests/mcu/faults.py says what each one asserts).
foreach(fault flip drop truncate garbage count range agent_restart mcu_reset)
  spvs_mcu_test(mcu_fault_${fault} /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/mcu/faults.py
                ${fault} $<TARGET_FILE:spvs-sim> $<TARGET_FILE:spvs-serial-agent> ${spvs_mcu_image})
endforeach()

# The application image links no heap, no stdio, no double helper
# (target/check_image.cmake, which the cross build also runs after linking);
# the fixed-point build's no floating-point helper at all (its serial codec
# converts through the floats' bits).
if(SPVS_FIXED)
  set(spvs_mcu_check_mode no-float)
else()
  set(spvs_mcu_check_mode "")
endif()
spvs_mcu_test(mcu_image_check ${CMAKE_CURRENT_SOURCE_DIR}/mcu/image_check.sh ${spvs_mcu_image}
              ${PROJECT_SOURCE_DIR}/target/check_image.cmake ${spvs_mcu_check_mode})
if(NOT SPVS_FIXED)
  add_test(NAME mcu_image_check_fixed
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mcu/image_check.sh ${spvs_mcu_image_fixed}
                   ${PROJECT_SOURCE_DIR}/target/check_image.cmake no-float)
  set_tests_properties(mcu_image_check_fixed PROPERTIES
                       LABELS "fixed;mcu" TIMEOUT 120 SKIP_RETURN_CODE 77
                       FIXTURES_REQUIRED "${spvs_mcu_fixture_fixed}")
endif()

# The agent's command line, its pty path, and spvs-sim stopping QEMU and
# the agent however the run ends.
add_test(NAME mcu_agent_cli COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/mcu/agent_cli.sh
         $<TARGET_FILE:spvs-serial-agent>)
set_tests_properties(mcu_agent_cli PROPERTIES LABELS "${spvs_variant};mcu" TIMEOUT 60)
spvs_mcu_test(mcu_agent_pty ${CMAKE_CURRENT_SOURCE_DIR}/mcu/agent_pty.sh
              $<TARGET_FILE:spvs-sim> $<TARGET_FILE:spvs-serial-agent> ${spvs_mcu_image})
spvs_mcu_test(mcu_sim_stop ${CMAKE_CURRENT_SOURCE_DIR}/mcu/sim_stop.sh
              $<TARGET_FILE:spvs-sim> ${spvs_mcu_image})
