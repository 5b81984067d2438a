# Run by ctest: install the build tree into a scratch prefix and build + run the consumer.
file(REMOVE_RECURSE "${SCRATCH_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${DYNCULL_BINARY_DIR}" --prefix "${SCRATCH_DIR}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed (${rc})")
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
