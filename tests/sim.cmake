# Simulator tests: the sim library (unit), closed loops through the
# in-process link (closedloop) and the spvs-sim command line (cli).
spvs_add_test(NAME test_sim SOURCES test_sim.c LIBS spvs_sim LABELS unit)
spvs_add_test(NAME test_closed_loop SOURCES test_closed_loop.c LIBS spvs_sim
              LABELS closedloop TIMEOUT 120)
