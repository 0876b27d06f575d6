# What a new user meets first: the demo's figures (tools/plot) with nothing
# cut at their edges.
if(TARGET spvs-sim)
  add_test(NAME plot_layout
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/first_run/plot_layout.sh $<TARGET_FILE:spvs-sim>
                   ${CMAKE_CURRENT_SOURCE_DIR}/../tools/plot)
  set_tests_properties(plot_layout PROPERTIES LABELS "${spvs_variant};tools" TIMEOUT 120)
endif()
