# LCM side: the node's message handling (in-process, memq://), the same checks
# against a separate spvs-node process, and the closed loop over LCM compared
# with the in-process loop.  The process tests run inside a loopback-only
# network namespace (tests/lcm/netns.sh).
if(TARGET spvs_node_lib)
  spvs_add_test(NAME test_node_msgs SOURCES test_node_msgs.c
                LIBS spvs_node_lib LABELS "lcm;unit" TIMEOUT 60)

  if(SPVS_DOUBLE)
    # Matches travel as float32, so a double build's two runs differ by the
    # rounding of the inputs, which the loop can amplify a little.
    set(lcm_tol_m 1e-3)
    set(lcm_tol_deg 1e-2)
  else()
    # float build: the wire carries exactly what the core computes with, so
    # only the JSON printing can differ.
    set(lcm_tol_m 1e-9)
    set(lcm_tol_deg 1e-7)
  endif()

  add_test(NAME lcm_node_robust
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/node_robust.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:test_node_msgs>)
  set_tests_properties(lcm_node_robust PROPERTIES
                       LABELS "${spvs_variant};lcm;process" TIMEOUT 90)

  if(TARGET spvs-sim)
    foreach(method 1 2 3)
      add_test(NAME lcm_closed_loop_m${method}
               COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/closed_loop.sh
                       $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                       ${lcm_tol_m} ${lcm_tol_deg} --method ${method} --seed 0)
      set_tests_properties(lcm_closed_loop_m${method} PROPERTIES
                           LABELS "${spvs_variant};lcm;process;scenario" TIMEOUT 240)
    endforeach()
    add_test(NAME lcm_sim_timeout
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/sim_timeout.sh $<TARGET_FILE:spvs-sim>)
    set_tests_properties(lcm_sim_timeout PROPERTIES
                         LABELS "${spvs_variant};lcm;process" TIMEOUT 60)
    add_test(NAME plot_figures
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/plot.sh $<TARGET_FILE:spvs-sim>
                     ${CMAKE_CURRENT_SOURCE_DIR}/../tools/plot)
    set_tests_properties(plot_figures PROPERTIES
                         LABELS "${spvs_variant};tools" TIMEOUT 120)
    # A noisy run with mismatches: RANSAC draws must match too.
    add_test(NAME lcm_closed_loop_noise
             COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/closed_loop.sh
                     $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                     ${lcm_tol_m} ${lcm_tol_deg} --method 3 --seed 7
                     --noise 0.5 --outliers 0.1)
    set_tests_properties(lcm_closed_loop_noise PROPERTIES
                         LABELS "${spvs_variant};lcm;process;scenario" TIMEOUT 240)
  endif()
endif()

# The README's and docs/LCM.md's sample report held to a default run of the
# demo's loop (tests/lcm/readme_report.sh): simulated time, frames, metres
# driven and the LCM log's events per channel.
if(TARGET spvs-node AND TARGET spvs-sim AND NOT SPVS_FIXED AND NOT SPVS_DOUBLE)
  add_test(NAME lcm_readme_report
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/lcm/readme_report.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                   ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/docs/LCM.md
                   ${CMAKE_CURRENT_BINARY_DIR}/lcm_readme_report)
  set_tests_properties(lcm_readme_report PROPERTIES
                       LABELS "${spvs_variant};lcm;process;docs" TIMEOUT 180)
endif()
