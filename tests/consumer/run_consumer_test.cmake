# Run by ctest: install the build tree into a scratch prefix and build + run the consumer.
file(REMOVE_RECURSE "${SCRATCH_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${DYNCULL_BINARY_DIR}" --prefix "${SCRATCH_DIR}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed (${rc})")
endif()
# Every public header is installed, beside the generated version header.
file(GLOB_RECURSE source_headers RELATIVE "${DYNCULL_SOURCE_DIR}/include" "${DYNCULL_SOURCE_DIR}/include/dyncull/*.hpp")
file(GLOB_RECURSE installed_headers RELATIVE "${SCRATCH_DIR}/prefix/include" "${SCRATCH_DIR}/prefix/include/dyncull/*.hpp")
list(APPEND source_headers dyncull/version.hpp)
list(SORT source_headers)
list(SORT installed_headers)
if(NOT source_headers STREQUAL installed_headers)
  set(missing ${source_headers})
  list(REMOVE_ITEM missing ${installed_headers})
  set(extra ${installed_headers})
  list(REMOVE_ITEM extra ${source_headers})
  message(FATAL_ERROR "the install's headers differ from include/: missing '${missing}', extra '${extra}'")
endif()

execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${SCRATCH_DIR}/build"
                        -DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer against the installed package failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer failed (${rc})")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build/consumer" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer ran but returned ${rc}")
endif()

# The exported targets name no absolute path: every path is relative to the install prefix.
file(GLOB target_files "${SCRATCH_DIR}/prefix/lib*/cmake/dyncull/*Targets*.cmake")
foreach(f IN LISTS target_files)
  file(STRINGS "${f}" lines REGEX "INTERFACE_(INCLUDE_DIRECTORIES|LINK_LIBRARIES|COMPILE_OPTIONS)")
  foreach(line IN LISTS lines)
    string(REPLACE "\${_IMPORT_PREFIX}" "<prefix>" stripped "${line}")
    if(stripped MATCHES "\"/|;/")
      message(FATAL_ERROR "${f} exports an absolute path: ${line}")
    endif()
  endforeach()
endforeach()

# The core without Ceres: a host whose machine lacks Ceres's development files still configures.
execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${SCRATCH_DIR}/build_no_ceres"
                        -DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                        -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer with Ceres hidden failed (${rc})")
endif()

# The compiled culler alone, with Eigen and Ceres hidden: OpenCV core and calib3d are all it needs.
file(GLOB culler_targets "${SCRATCH_DIR}/prefix/lib*/cmake/dyncull/dyncull-cullerTargets.cmake")
if(EXPECT_CULLER AND NOT culler_targets)
  message(FATAL_ERROR "the build has dyncull::culler but the install has no culler component")
endif()
if(EXPECT_CULLER)
  execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}/culler" -B "${SCRATCH_DIR}/build_culler"
                          -DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                          -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON
                          -DHOST_SOURCE=${CONSUMER_SOURCE_DIR}/../opencv/compiled_culler_host.cpp
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring a culler-only consumer with Eigen and Ceres hidden failed (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build_culler" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building the culler-only consumer failed (${rc})")
  endif()
  execute_process(COMMAND "${SCRATCH_DIR}/build_culler/culler_consumer" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the culler-only consumer ran but returned ${rc}")
  endif()
endif()

# The host harness alone (as the ORB-SLAM2 patch asks for it), with Eigen and Ceres hidden.
if(EXPECT_CULLER)
  execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}/host" -B "${SCRATCH_DIR}/build_host"
                          -DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                          -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON
                          -DHOST_SOURCE=${CONSUMER_SOURCE_DIR}/../host/orb_slam_host.cpp
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring a host-harness consumer with Eigen and Ceres hidden failed (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build_host" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building the host-harness consumer failed (${rc})")
  endif()
  execute_process(COMMAND "${SCRATCH_DIR}/build_host/host_consumer" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the host-harness consumer ran but returned ${rc}")
  endif()
endif()

# The same consumer with dyncull vendored through add_subdirectory (no install step).
execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${SCRATCH_DIR}/build_subdir"
                        -DCONSUMER_USE_SUBDIRECTORY=ON -DDYNCULL_SOURCE_DIR=${DYNCULL_SOURCE_DIR}
                        -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer with add_subdirectory(dyncull) failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build_subdir" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer with add_subdirectory(dyncull) failed (${rc})")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build_subdir/consumer" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the add_subdirectory consumer ran but returned ${rc}")
endif()

# examples/ on its own against the install, as a user copies it: it configures with find_package(dyncull)
# alone, and the README's front end and the monocular one build and run. The header-only example links
# dyncull::dyncull alone, as the consumer above does; it builds and runs in dyncull's own tree (ctest
# examples.header_only_*), and building it here again would take two minutes of one core.
if(EXPECT_CULLER)
  execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}/../../examples" -B "${SCRATCH_DIR}/build_examples"
                          -DCMAKE_PREFIX_PATH=${SCRATCH_DIR}/prefix -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                          -DCMAKE_BUILD_TYPE=Release
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring examples/ against the installed package failed (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build_examples" --target front_end monocular
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building examples/ against the installed package failed (${rc})")
  endif()
  foreach(example front_end monocular)
    execute_process(COMMAND "${SCRATCH_DIR}/build_examples/${example}" RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "examples/${example}, built against the install, returned ${rc}")
    endif()
  endforeach()
endif()
