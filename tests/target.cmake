# The core on a Cortex-M4F under QEMU (mps2-an386): a cross build of the
# core and the images of target/, then the golden vectors and the recorded
# replay on the emulated MCU.  Only in the float32 host build (the image
# replays what the host float32 core answered), and only when the cross
# compiler and QEMU are installed.
find_program(SPVS_ARM_GCC arm-none-eabi-gcc)
find_program(SPVS_QEMU_ARM qemu-system-arm)
if(SPVS_ARM_GCC AND SPVS_QEMU_ARM AND NOT SPVS_DOUBLE AND NOT SPVS_SANITIZE)
  set(spvs_cross_dir ${CMAKE_BINARY_DIR}/cortex-m4f)
  set(spvs_target_script ${CMAKE_CURRENT_SOURCE_DIR}/target/target_test.sh)
  if(TARGET spvs-sim)
    set(spvs_replay_sim $<TARGET_FILE:spvs-sim>)
  else()
    set(spvs_replay_sim "")
  endif()
  add_test(NAME target_build
           COMMAND ${spvs_target_script} build ${PROJECT_SOURCE_DIR} ${spvs_cross_dir}
                   ${spvs_replay_sim})
  add_test(NAME target_qemu COMMAND ${spvs_target_script} run ${spvs_cross_dir})
  add_test(NAME target_qemu_tamper COMMAND ${spvs_target_script} tamper ${spvs_cross_dir})
  set_tests_properties(target_build PROPERTIES LABELS "float;target" TIMEOUT 300
                       FIXTURES_SETUP spvs_cross)
  set_tests_properties(target_qemu target_qemu_tamper PROPERTIES LABELS "float;target"
                       TIMEOUT 150 FIXTURES_REQUIRED spvs_cross)
endif()
