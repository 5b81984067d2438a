# Run by ctest: the walk-through of docs/design.md, "Adding a stage", done on a copy of include/ for a stage
# of each kind (box classification, depth, evidence). Each is one header (into culling/stages/), one test
# and one bench (beside the other stages'), one line (the stage in stages/list.hpp, with its #include);
# then the tests and the benches are built header-only and run. Fails when any step no longer suffices.
set(tree "${SCRATCH_DIR}/tree")
file(REMOVE_RECURSE "${SCRATCH_DIR}")
file(COPY "${DYNCULL_SOURCE_DIR}/include" DESTINATION "${tree}")

# For a stage of each kind, one header, one test and one bench (beside the other stages'), and one line:
# the stage in the list, after the stage its kind runs after (its #include beside the others).
set(list_file "${tree}/include/dyncull/culling/stages/list.hpp")
file(READ "${list_file}" list_text)
function(add_stage header stage after)
  file(COPY "${WALKTHROUGH_DIR}/${header}.hpp" DESTINATION "${tree}/include/dyncull/culling/stages")
  file(COPY "${WALKTHROUGH_DIR}/${header}_test.cpp" DESTINATION "${tree}/tests/culling/stages")
  file(COPY "${WALKTHROUGH_DIR}/${header}_bench.cpp" DESTINATION "${tree}/bench/culling/stages")
  set(entry "    ${after}<T>,\n")
  string(FIND "${list_text}" "${entry}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "stages/list.hpp no longer lists '${after}<T>,' on a line: update the walk-through in docs/design.md")
  endif()
  string(REPLACE "${entry}" "${entry}    ${stage}<T>,\n" text "${list_text}")
  set(include_line "#include \"dyncull/culling/stages/multiview.hpp\"\n")
  string(REPLACE "${include_line}" "${include_line}#include \"dyncull/culling/stages/${header}.hpp\"\n" text "${text}")
  set(list_text "${text}" PARENT_SCOPE)
endfunction()
add_stage(box_margin BoxMarginStage DepthMaskStage)           # a box classification stage
add_stage(depth_range DepthRangeStage BoxMarginStage)         # a depth stage
add_stage(large_displacement LargeDisplacementStage MultiViewStage)  # an evidence stage
file(WRITE "${list_file}" "${list_text}")

file(COPY "${WALKTHROUGH_DIR}/CMakeLists.txt" DESTINATION "${tree}")
execute_process(COMMAND ${CMAKE_COMMAND} -S "${tree}" -B "${SCRATCH_DIR}/build" -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                        -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the walk-through failed (${rc})")
endif()
# --parallel 2: the tests and the benches (one translation unit each) compile side by side.
execute_process(COMMAND ${CMAKE_COMMAND} --build "${SCRATCH_DIR}/build" --parallel 2 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the new stages' tests and benches failed (${rc})")
endif()
# The three stages' tests are one executable: a failure is named by its gtest name (the stage's suite).
execute_process(COMMAND "${SCRATCH_DIR}/build/stages_test" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
message("${out}")
if(NOT rc EQUAL 0)
  string(REGEX MATCHALL "\\[  FAILED  \\] [^\n]* \\([0-9]+ ms\\)" failed "${out}")
  list(TRANSFORM failed REPLACE "^\\[  FAILED  \\] (.*) \\([0-9]+ ms\\)$" "  \\1")
  list(JOIN failed "\n" failed)
  if(failed STREQUAL "")
    set(failed "  none reported: stages_test stopped before its summary (its output is above)")
  endif()
  message(FATAL_ERROR "the new stages' tests (stages_test) failed (${rc}):\n${failed}")
endif()
execute_process(COMMAND "${SCRATCH_DIR}/build/stages_bench" --benchmark_min_time=0.01 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the new stages' benches (stages_bench) failed (${rc}) after the benches listed above")
endif()
message(STATUS "adding a stage of each kind: one header, one test, one bench and one line suffice")
