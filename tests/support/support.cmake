# The tests' own code that is no part of the core (tests/support/): the
# forward transfer error's Gauss-Newton refit (h_refit.c), the oracle of
# test_homography, test_golden and the Cortex-M images' golden run.
# Included by tests/unit.cmake (host) and target/ (cross builds).
if(NOT TARGET spvs_test_support)
  add_library(spvs_test_support STATIC ${CMAKE_CURRENT_LIST_DIR}/h_refit.c)
  target_include_directories(spvs_test_support PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
  target_link_libraries(spvs_test_support PUBLIC spvs::internal)
  target_compile_options(spvs_test_support PRIVATE -Wall -Wextra -Wshadow -Wdouble-promotion)
endif()
