# Run by ctest: the walk-through of docs/design.md, "Adding a stage", done on a copy of include/. One
# header (large_displacement.hpp into culling/stages/), one test and one bench (beside the other stages'),
# one line (the stage in stages/list.hpp, with its #include); then the test and the bench are built
# header-only and run. Fails when any step no longer suffices.
set(tree "${SCRATCH_DIR}/tree")
file(REMOVE_RECURSE "${SCRATCH_DIR}")
file(COPY "${DYNCULL_SOURCE_DIR}/include" DESTINATION "${tree}")

# One header, one test, one bench.
file(COPY "${WALKTHROUGH_DIR}/large_displacement.hpp" DESTINATION "${tree}/include/dyncull/culling/stages")
file(COPY "${WALKTHROUGH_DIR}/large_displacement_test.cpp" DESTINATION "${tree}/tests/culling/stages")
file(COPY "${WALKTHROUGH_DIR}/large_displacement_bench.cpp" DESTINATION "${tree}/bench/culling/stages")

# One line: the stage in the list (its #include goes beside the others).
set(list_file "${tree}/include/dyncull/culling/stages/list.hpp")
file(READ "${list_file}" list_text)
set(entry "using EvidenceStages = StageList<MultiViewStage<T>>;")
string(FIND "${list_text}" "${entry}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "stages/list.hpp no longer holds '${entry}': update the walk-through in docs/design.md")
endif()
string(REPLACE "${entry}" "using EvidenceStages = StageList<MultiViewStage<T>, LargeDisplacementStage<T>>;"
       list_text "${list_text}")
set(include_line "#include \"dyncull/culling/stages/multiview.hpp\"\n")
string(REPLACE "${include_line}" "${include_line}#include \"dyncull/culling/stages/large_displacement.hpp\"\n"
       list_text "${list_text}")
file(WRITE "${list_file}" "${list_text}")

file(COPY "${WALKTHROUGH_DIR}/CMakeLists.txt" DESTINATION "${tree}")
execute_process(COMMAND ${CMAKE_COMMAND} -S "${tree}" -B "${SCRATCH_DIR}/build" -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                        -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the walk-through failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the new stage's test and bench failed (${rc})")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build/large_displacement_test" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the new stage's test failed (${rc})")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build/large_displacement_bench" --benchmark_min_time=0.01
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the new stage's bench failed (${rc})")
endif()
message(STATUS "adding a stage: one header, one test, one bench and one line suffice")
