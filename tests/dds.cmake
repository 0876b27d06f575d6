# ROS 2 on DDS (docs/ROS2.md): spvs_msgs' IDL held equal to its .msg files,
# spvs-node --dds against spvs-sim --transport dds compared with the
# in-process run, faults, domains, the same /cmd_vel heard by Fast DDS, and
# the rosbag2 of a run read by rosbags.  Every DDS process runs in a
# loopback-only network namespace (tests/dds/netns.sh), each test on a
# ROS_DOMAIN_ID of its own.
add_test(NAME spvs_msgs_idl_matches_msg
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/spvs_msgs/msg2idl.py --check
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/msg/Matches.msg
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/msg/Matches.idl
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/msg/State.msg
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/msg/State.idl
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/external/geometry_msgs/msg/Vector3.msg
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/external/geometry_msgs/msg/Vector3.idl
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/external/geometry_msgs/msg/Twist.msg
                 ${PROJECT_SOURCE_DIR}/spvs_msgs/external/geometry_msgs/msg/Twist.idl)
set_tests_properties(spvs_msgs_idl_matches_msg PROPERTIES LABELS "${spvs_variant};dds" TIMEOUT 30)

if(NOT TARGET spvs_dds_link OR NOT TARGET spvs-node)
  # No Cyclone DDS in this build: in CI that is a failure, elsewhere a skip.
  add_test(NAME dds_available
           COMMAND sh -c "echo 'Cyclone DDS not found: run scripts/install_deps.sh (cyclonedds-dev)'; [ \"$CI\" = true ] && exit 1; exit 77")
  set_tests_properties(dds_available PROPERTIES LABELS "${spvs_variant};dds"
                       SKIP_RETURN_CODE 77)
  return()
endif()
if(SPVS_DOUBLE)
  # Matches travel as float32: a double core's runs are compared by the LCM
  # tests' tolerances there; the DDS tests run in the float and fixed builds.
  return()
endif()

add_executable(dds_probe dds/dds_probe.c)
target_link_libraries(dds_probe PRIVATE spvs_ros_dds)

# Closed loops, one domain id each (41..43).
foreach(method 1 2 3)
  math(EXPR domain "40 + ${method}")
  add_test(NAME dds_closed_loop_m${method}
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dds/closed_loop.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim> ${domain}
                   --method ${method} --seed 0)
  set_tests_properties(dds_closed_loop_m${method} PROPERTIES
                       LABELS "${spvs_variant};dds;process;scenario" TIMEOUT 180)
endforeach()

# Malformed frames, the node killed mid-run, and a node on another domain.
add_test(NAME dds_faults
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dds/faults.sh
                 $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                 $<TARGET_FILE:dds_probe> 44)
set_tests_properties(dds_faults PROPERTIES LABELS "${spvs_variant};dds;process" TIMEOUT 180)

# An independent DDS implementation hears /cmd_vel: Fast DDS (Debian's
# libfastrtps-dev), its Twist made by fastddsgen from the same IDL.
find_package(fastrtps CONFIG QUIET)
find_package(fastcdr CONFIG QUIET)
find_program(FASTDDSGEN fastddsgen)
if(fastrtps_FOUND AND fastcdr_FOUND AND FASTDDSGEN)
  enable_language(CXX)
  set(fdg_out ${CMAKE_CURRENT_BINARY_DIR}/fastddsgen)
  set(fdg_idl ${PROJECT_SOURCE_DIR}/spvs_msgs/external/geometry_msgs/msg)
  set(fdg_src ${fdg_out}/Twist.cxx ${fdg_out}/TwistPubSubTypes.cxx
              ${fdg_out}/Vector3.cxx ${fdg_out}/Vector3PubSubTypes.cxx)
  add_custom_command(
    OUTPUT ${fdg_src}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${fdg_out}
    COMMAND ${FASTDDSGEN} -replace -d ${fdg_out}
            -I ${PROJECT_SOURCE_DIR}/spvs_msgs/external
            ${fdg_idl}/Vector3.idl ${fdg_idl}/Twist.idl
    DEPENDS ${fdg_idl}/Vector3.idl ${fdg_idl}/Twist.idl
    COMMENT "fastddsgen: geometry_msgs Twist for Fast DDS")
  add_executable(fastdds_cmd_vel dds/fastdds_cmd_vel.cpp ${fdg_src})
  target_include_directories(fastdds_cmd_vel PRIVATE ${fdg_out})
  target_link_libraries(fastdds_cmd_vel PRIVATE fastrtps fastcdr)
  set_target_properties(fastdds_cmd_vel PROPERTIES CXX_STANDARD 14)
  set(fastdds_sub $<TARGET_FILE:fastdds_cmd_vel>)
else()
  set(fastdds_sub "")
endif()
add_test(NAME dds_fastdds_hears_cmd_vel
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dds/fastdds.sh
                 $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim> 45 "${fastdds_sub}")
set_tests_properties(dds_fastdds_hears_cmd_vel PROPERTIES
                     LABELS "${spvs_variant};dds;process" TIMEOUT 180
                     SKIP_RETURN_CODE 77)

# rosbag2: spvs-sim --rosbag read by mcap-ros2-support and rosbags from the
# project's venv (scripts/setup_venv.sh, tools/rosbag/requirements.txt).
add_test(NAME dds_venv COMMAND ${PROJECT_SOURCE_DIR}/scripts/setup_venv.sh)
set_tests_properties(dds_venv PROPERTIES FIXTURES_SETUP dds_venv
                     LABELS "${spvs_variant};dds" TIMEOUT 600)
add_test(NAME dds_rosbag_readers
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dds/rosbag.sh
                 $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim> 46
                 ${PROJECT_SOURCE_DIR}/.venv/bin/python)
set_tests_properties(dds_rosbag_readers PROPERTIES FIXTURES_REQUIRED dds_venv
                     LABELS "${spvs_variant};dds;process" TIMEOUT 180
                     SKIP_RETURN_CODE 77)
# (lcm_types/ is added after tests/: its Python types, target
# spvs_lcm_python, are built with ALL.)
if(EXISTS ${PROJECT_SOURCE_DIR}/lcm_types/CMakeLists.txt)
  add_test(NAME rosbag_from_lcm_log
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dds/lcm_rosbag.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-sim>
                   ${PROJECT_BINARY_DIR}/lcm_types/python
                   ${PROJECT_SOURCE_DIR}/.venv/bin/python)
  set_tests_properties(rosbag_from_lcm_log PROPERTIES FIXTURES_REQUIRED dds_venv
                       LABELS "${spvs_variant};lcm;process" TIMEOUT 180
                       SKIP_RETURN_CODE 77)
endif()

# /cmd_vel on Zenoh with rmw_zenoh's key, liveliness tokens and attachment
# (spvs-zenoh-bridge --ros2-cmd-vel), decoded by rosbags' ROS 2 types.
if(TARGET spvs_zenoh_link)
  add_test(NAME zenoh_ros2_cmd_vel
           COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/zenoh/netns.sh ${PROJECT_SOURCE_DIR} 200
                   ${PROJECT_SOURCE_DIR}/.venv/bin/python
                   ${CMAKE_CURRENT_SOURCE_DIR}/dds/check_zenoh_ros2.py
                   ${CMAKE_BINARY_DIR} ${PROJECT_SOURCE_DIR} 47)
  set_tests_properties(zenoh_ros2_cmd_vel PROPERTIES FIXTURES_REQUIRED dds_venv
                       LABELS "${spvs_variant};zenoh;dds" TIMEOUT 200)
endif()

# Bad settings: one line on stderr, exit status 2.
add_test(NAME sim_cli_bad_rosbag_exists
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_sim_cli.py usage --
                 $<TARGET_FILE:spvs-sim> --rosbag ${CMAKE_CURRENT_SOURCE_DIR})
add_test(NAME dds_node_bad_domain
         COMMAND sh -c "out=$(ROS_DOMAIN_ID=233 \"$0\" --dds 2>&1 >/dev/null); rc=$?; echo \"$out\"; [ $rc -eq 2 ] && [ $(printf '%s\\n' \"$out\" | wc -l) -eq 1 ] && echo \"$out\" | grep -q '^spvs-node: ROS_DOMAIN_ID'"
                 $<TARGET_FILE:spvs-node>)
set_tests_properties(sim_cli_bad_rosbag_exists dds_node_bad_domain PROPERTIES
                     LABELS "${spvs_variant};dds;cli" TIMEOUT 30)
# CYCLONEDDS_URI is read: an interface that does not exist stops the node
# with exit status 1 and its reason.
add_test(NAME dds_node_reads_cyclonedds_uri
         COMMAND sh -c "out=$(CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"nosuchif0\"/></Interfaces></General></Domain></CycloneDDS>' ROS_DOMAIN_ID=49 timeout 20 \"$0\" --dds 2>&1 >/dev/null); rc=$?; echo \"$out\"; [ $rc -eq 1 ] && echo \"$out\" | grep -q 'nosuchif0' && echo \"$out\" | grep -q '^spvs-node: error: cannot join DDS domain 49'"
                 $<TARGET_FILE:spvs-node>)
set_tests_properties(dds_node_reads_cyclonedds_uri PROPERTIES
                     LABELS "${spvs_variant};dds;cli" TIMEOUT 30)
