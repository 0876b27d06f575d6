# spvs-camera (sim_host/camera) on real photographs and a real camera
# sequence, and the closed loop through images with a photograph on the
# plane (docs/CAMERA.md).  The data come from Debian's opencv-doc and
# visp-images-data (scripts/install_deps.sh); a test whose data are missing
# fails under CI=true and is skipped (77) otherwise.
if(TARGET spvs-camera AND TARGET spvs-sim)
  set(camera_check /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_camera.py)
  set(camera_opencv_data /usr/share/doc/opencv-doc/examples/data)
  set(camera_mire2 /usr/share/visp-images-data/ViSP-images/mire-2)
  set(camera_work ${CMAKE_CURRENT_BINARY_DIR}/camera)

  # The closed loop with graf1.png on the plane: Methods I, II, III from two
  # Figure 5 starts (docs/RESULTS.md).  From the first start Method I's
  # frames (every second one) are also replayed through spvs-camera and
  # checked against the renderer's truth and the simulator's own estimate.
  set(camera_loop_cases
    "truth_m1_a|1|-3,-10,-30|--truth-every|2"
    "loop_m2_a|2|-3,-10,-30"
    "loop_m3_a|3|-3,-10,-30"
    "loop_m1_b|1|0,-8,-40"
    "loop_m2_b|2|0,-8,-40"
    "loop_m3_b|3|0,-8,-40")
  if(SPVS_IMAGE_LOOP_TESTS OR NOT DEFINED SPVS_IMAGE_LOOP_TESTS)
    set(camera_loop_disabled FALSE)
  else()
    set(camera_loop_disabled TRUE)
  endif()
  foreach(case IN LISTS camera_loop_cases)
    string(REPLACE "|" ";" case_args "${case}")
    list(POP_FRONT case_args case_name method pose)
    add_test(NAME camera_${case_name}
             COMMAND ${camera_check} loop $<TARGET_FILE:spvs-sim>
                     $<TARGET_FILE:spvs-camera> ${camera_opencv_data}/graf1.png
                     ${method} ${pose} ${camera_work}/${case_name} ${case_args})
    set_tests_properties(camera_${case_name} PROPERTIES
                         LABELS "${spvs_variant};images;camera"
                         TIMEOUT 600 SKIP_RETURN_CODE 77
                         DISABLED ${camera_loop_disabled}
                         ENVIRONMENT "OPENCV_FOR_THREADS_NUM=1")
  endforeach()

  # ViSP's mire-2 (a real camera before a planar target): frames 1..120 of
  # 501 in the test, the whole sequence for the figures in docs/CAMERA.md.
  add_test(NAME camera_mire2
           COMMAND ${camera_check} mire $<TARGET_FILE:spvs-camera>
                   ${camera_mire2} ${camera_work}/mire2 1 120)
  # graf1 / graf3 with Oxford's H1to3p.
  add_test(NAME camera_graf
           COMMAND ${camera_check} graf $<TARGET_FILE:spvs-camera>
                   ${camera_opencv_data} ${camera_work}/graf)
  # Bad frames, refused options, teach's check.
  add_test(NAME camera_bad_input
           COMMAND ${camera_check} bad $<TARGET_FILE:spvs-camera>
                   ${camera_mire2} ${camera_work}/bad)
  # --calib: the undistortion of an OpenCV calibration file.
  add_test(NAME camera_calib
           COMMAND ${camera_check} calib $<TARGET_FILE:spvs-camera>
                   ${camera_opencv_data} ${camera_work}/calib)
  set_tests_properties(camera_mire2 camera_graf camera_bad_input camera_calib PROPERTIES
                       LABELS "${spvs_variant};camera" TIMEOUT 300
                       SKIP_RETURN_CODE 77
                       ENVIRONMENT "OPENCV_FOR_THREADS_NUM=1")
endif()

# The matches over LCM to spvs-node: the node's commands equal the
# in-process controller's, frame by frame.
if(TARGET spvs-camera AND TARGET spvs-node)
  add_test(NAME camera_lcm
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/camera_lcm.sh
                   $<TARGET_FILE:spvs-node> $<TARGET_FILE:spvs-camera>
                   /usr/share/visp-images-data/ViSP-images/mire-2)
  set_tests_properties(camera_lcm PROPERTIES
                       LABELS "${spvs_variant};camera;lcm;process"
                       TIMEOUT 240 SKIP_RETURN_CODE 77)
endif()

# The matches over Zenoh (spvs-zenoh-bridge to spvs-node), in the Zenoh
# tests' namespace and venv (tests/zenoh.cmake's fixture).
if(TARGET spvs-camera AND TARGET spvs-node AND TARGET spvs_zenoh_link)
  add_test(NAME camera_zenoh
           COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/zenoh/netns.sh ${PROJECT_SOURCE_DIR} 180
                   ${CMAKE_CURRENT_SOURCE_DIR}/camera_zenoh.sh ${PROJECT_SOURCE_DIR}
                   ${CMAKE_BINARY_DIR} /usr/share/visp-images-data/ViSP-images/mire-2)
  set_tests_properties(camera_zenoh PROPERTIES
                       LABELS "${spvs_variant};camera;zenoh;process"
                       TIMEOUT 240 SKIP_RETURN_CODE 77
                       FIXTURES_REQUIRED zenoh_venv)
endif()

# The matches over DDS with ROS 2's names to spvs-node --dds: the same
# commands as the in-process controller's (ROS_DOMAIN_ID 48, loopback only).
if(TARGET spvs-camera AND TARGET spvs-node AND TARGET spvs_dds_link)
  add_test(NAME camera_dds
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/camera_dds.sh ${CMAKE_BINARY_DIR}
                   /usr/share/visp-images-data/ViSP-images/mire-2 48)
  set_tests_properties(camera_dds PROPERTIES
                       LABELS "${spvs_variant};camera;dds;process"
                       TIMEOUT 240 SKIP_RETURN_CODE 77)
endif()

# A video file as the source: mire-2 frames 1-30 written to an MJPEG AVI by
# OpenCV's own writer (tests/camera_make_video.cpp).
if(TARGET spvs-camera)
  find_package(OpenCV QUIET COMPONENTS core imgcodecs videoio)
  if(OpenCV_FOUND)
    add_executable(camera_make_video camera_make_video.cpp)
    target_include_directories(camera_make_video SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
    target_link_libraries(camera_make_video PRIVATE ${OpenCV_LIBS})
    add_test(NAME camera_video
             COMMAND ${camera_check} video $<TARGET_FILE:spvs-camera>
                     $<TARGET_FILE:camera_make_video> ${camera_mire2}
                     ${camera_work}/video)
    set_tests_properties(camera_video PROPERTIES
                         LABELS "${spvs_variant};camera" TIMEOUT 120
                         SKIP_RETURN_CODE 77
                         ENVIRONMENT "OPENCV_FOR_THREADS_NUM=1")
  endif()
endif()
