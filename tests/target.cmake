# The core on a Cortex-M4F under QEMU (mps2-an386), the same float core on
# a Cortex-M3 without FPU (mps2-an385, soft-float), and the fixed-point core
# on the Cortex-M3: per tree a cross build of the core and the images of
# target/ in its own folder, then the golden vectors and the recorded
# replay on the emulated MCU.  Only in a float32 host build (each image
# replays what the host's core of its build answered), and only when the
# cross compiler and QEMU are installed.
find_program(SPVS_ARM_GCC arm-none-eabi-gcc)
find_program(SPVS_QEMU_ARM qemu-system-arm)
if(SPVS_ARM_GCC AND SPVS_QEMU_ARM AND NOT SPVS_DOUBLE AND NOT SPVS_SANITIZE)
  set(spvs_cross_dir ${CMAKE_BINARY_DIR}/cortex-m4f)
  set(spvs_target_script ${CMAKE_CURRENT_SOURCE_DIR}/target/target_test.sh)
  # The images build the host's path (SPVS_ACCEL), so each replays and
  # matches the host core of this build bit for bit.
  if(SPVS_ACCEL)
    set(spvs_target_accel ON)
  else()
    set(spvs_target_accel OFF)
  endif()
  if(TARGET spvs-sim)
    set(spvs_replay_sim $<TARGET_FILE:spvs-sim>)
  else()
    set(spvs_replay_sim "")
  endif()
  # The fixed-point core on the Cortex-M3 (SPVS_FIXED=ON, mps2-an385): its
  # test image links no float helper, checks the golden vectors in
  # integers and replays the host's fixed-point run bit for bit; the tamper
  # twin must fail.  In every float32 host build and in the fixed-point one.
  set(spvs_cross_m3_fixed_dir ${CMAKE_BINARY_DIR}/cortex-m3-fixed)
  add_test(NAME target_m3_fixed_build
           COMMAND ${spvs_target_script} --cpu cortex-m3 --fixed --accel ${spvs_target_accel} build ${PROJECT_SOURCE_DIR}
                   ${spvs_cross_m3_fixed_dir} ${spvs_replay_sim})
  add_test(NAME target_m3_fixed_qemu COMMAND ${spvs_target_script} run ${spvs_cross_m3_fixed_dir})
  add_test(NAME target_m3_fixed_tamper
           COMMAND ${spvs_target_script} tamper ${spvs_cross_m3_fixed_dir})
  set_tests_properties(target_m3_fixed_build PROPERTIES LABELS "fixed;target" TIMEOUT 300
                       FIXTURES_SETUP spvs_cross_m3_fixed)
  set_tests_properties(target_m3_fixed_qemu target_m3_fixed_tamper PROPERTIES
                       LABELS "fixed;target" TIMEOUT 150 FIXTURES_REQUIRED spvs_cross_m3_fixed)
endif()
# The float core's images replay the host float32 core's run: not in the
# fixed-point build, whose spvs-sim runs the fixed-point core.
if(SPVS_ARM_GCC AND SPVS_QEMU_ARM AND NOT SPVS_DOUBLE AND NOT SPVS_SANITIZE AND NOT SPVS_FIXED)
  add_test(NAME target_build
           COMMAND ${spvs_target_script} --accel ${spvs_target_accel} build ${PROJECT_SOURCE_DIR} ${spvs_cross_dir}
                   ${spvs_replay_sim})
  add_test(NAME target_qemu COMMAND ${spvs_target_script} run ${spvs_cross_dir})
  add_test(NAME target_qemu_tamper COMMAND ${spvs_target_script} tamper ${spvs_cross_dir})
  set_tests_properties(target_build PROPERTIES LABELS "float;target" TIMEOUT 300
                       FIXTURES_SETUP spvs_cross)
  set_tests_properties(target_qemu target_qemu_tamper PROPERTIES LABELS "float;target"
                       TIMEOUT 150 FIXTURES_REQUIRED spvs_cross)

  # Cortex-M3, soft-float: the same three tests in <build>/cortex-m3, and
  # the proof that the image check's no-float mode (for the fixed-point
  # build) refuses an image that calls float helpers.
  set(spvs_cross_m3_dir ${CMAKE_BINARY_DIR}/cortex-m3)
  add_test(NAME target_m3_build
           COMMAND ${spvs_target_script} --cpu cortex-m3 --accel ${spvs_target_accel} build ${PROJECT_SOURCE_DIR}
                   ${spvs_cross_m3_dir} ${spvs_replay_sim})
  add_test(NAME target_m3_qemu COMMAND ${spvs_target_script} run ${spvs_cross_m3_dir})
  add_test(NAME target_m3_qemu_tamper COMMAND ${spvs_target_script} tamper ${spvs_cross_m3_dir})
  add_test(NAME target_m3_float_check
           COMMAND ${spvs_target_script} float-check ${spvs_cross_m3_dir}
                   ${PROJECT_SOURCE_DIR}/target/check_image.cmake)
  set_tests_properties(target_m3_build PROPERTIES LABELS "float;target" TIMEOUT 300
                       FIXTURES_SETUP spvs_cross_m3)
  set_tests_properties(target_m3_qemu target_m3_qemu_tamper target_m3_float_check
                       PROPERTIES LABELS "float;target" TIMEOUT 150
                       FIXTURES_REQUIRED spvs_cross_m3)
endif()
