# What a new user meets first: the demo's figures (tools/plot) with nothing
# cut at their edges.
if(TARGET spvs-sim)
  add_test(NAME plot_layout
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/first_run/plot_layout.sh $<TARGET_FILE:spvs-sim>
                   ${CMAKE_CURRENT_SOURCE_DIR}/../tools/plot)
  if(SPVS_DOUBLE)
    set(first_run_variant double)
  else()
    set(first_run_variant float)
  endif()
  if(SPVS_FIXED)
    set(first_run_variant fixed)
  endif()
  set_tests_properties(plot_layout PROPERTIES LABELS "${first_run_variant};tools" TIMEOUT 120)
endif()
