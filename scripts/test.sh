#!/usr/bin/env bash
# Builds dyncull with warnings as errors and runs the whole ctest suite.
#   scripts/test.sh            Release (-O2, g++) build in build/test
#   scripts/test.sh --asan     AddressSanitizer + UndefinedBehaviorSanitizer build (clang++) in build/asan
# DYNCULL_DATA_DIR (default: ../shared/data beside the checkout, when it exists) enables real-data tests.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
mode=${1:-release}
jobs=${DYNCULL_JOBS:-$(nproc)}
ctest_args=()

if [[ -z "${DYNCULL_DATA_DIR:-}" && -d "$root/../shared/data" ]]; then
  export DYNCULL_DATA_DIR=$(cd "$root/../shared/data" && pwd)
fi
echo "test.sh: DYNCULL_DATA_DIR=${DYNCULL_DATA_DIR:-<unset: real-data tests will skip>}"

build="$root/build/test"
[[ "$mode" == --asan ]] && build="$root/build/asan"
# Ninja when it is installed (scripts/install-deps.sh installs it) and the build tree is new (a tree keeps
# the generator it was made with): one build graph for all targets, less work per step than make's.
generator=()
if [[ ! -f "$build/CMakeCache.txt" ]] && command -v ninja >/dev/null; then generator=(-G Ninja); fi

case "$mode" in
  release|"")
    # -O2 for the libraries and the apps (no fast-math); -O1 for the test executables, which then compile
    # in half the time and test the code the libraries hold at -O2, and for the benchmarks, which are only
    # built here (the published timings come from scripts/benchmarks.sh's -O3 build).
    cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
      -DDYNCULL_TEST_OPTIONS=-O1 -DDYNCULL_WERROR=ON -DDYNCULL_DATA_DIR="${DYNCULL_DATA_DIR:-}" >/dev/null
    ;;
  --asan)
    # Benchmarks and examples are not rebuilt under the sanitizers: the tests exercise the same headers. Nor
    # is the header-only side of the precompiled cull_frame's comparison (the same code as the library's).
    # The fuzz targets are (DYNCULL_FUZZ_TREE=build/asan scripts/fuzz.sh runs them): they share the compiled
    # libraries with the tests, which then carry libFuzzer's coverage instrumentation too.
    # clang++ builds this run (g++ builds the Release run), so the whole suite compiles warning-free
    # under both; it also compiles the tests ~1.7x faster than g++ here. -g1 (line tables) is enough
    # for symbolised sanitizer reports and costs a third less than -g. -O1 only where cases run long: clang
    # compiles a test file about twice as fast at -O0, and most cases run in seconds even so. The sim and
    # apps tests, the separate executables (the allocation test: 6 s at -O1, 135 s at -O0) and, of the
    # culling and geometry tests, the files named below (the kd-tree's oracle: 11 s and 130 s) stay at -O1.
    optimised_test_files=(culling/pipeline_test.cpp culling/pipeline_inputs_test.cpp culling/moving_consistency_test.cpp
                          culling/multiview_check_test.cpp culling/depth_mask_test.cpp geometry/kdtree_test.cpp)
    cxx=$(command -v clang++ || command -v g++)
    fuzzers=OFF  # libFuzzer needs clang++
    [[ "$(basename "$cxx")" == clang++* ]] && fuzzers=ON
    # One ctest case per test executable, two for a module's (tests/CMakeLists.txt says why). Left to the
    # Release run: the checks that only build (LABELS build_check, the header and mixing-rule checks) and
    # the cases that repeat over many frames code that shorter cases run: the simulator's statistics
    # (against the real YOLO streams, of its detector, of people's coverage, of its motion truth and its
    # recorded trajectory; the SimScene and SceneFamilies cases render every family and motion),
    # dynamic_vo's two accuracy bounds over 45 frames (its shorter cases run the same strategies) and its
    # truth-repaired copies of the recommended preset, the OpenCV culler against the hand-fed pipeline over
    # 90 frames and the compiled culler's three forms against its core over 30 frames twice (the
    # CullerContract cases and the culler fuzz target run every form), and the double-precision golden
    # sequences (the float case runs the same presets and frames; clang's labels are not compared there).
    # Under the sanitizers each of these takes 25 s to 4 min.
    cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug -DDYNCULL_WERROR=ON -DCMAKE_CXX_COMPILER="$cxx" \
      -DDYNCULL_BUILD_BENCHMARKS=OFF -DDYNCULL_BUILD_FUZZERS=$fuzzers -DDYNCULL_BUILD_EXAMPLES=OFF -DDYNCULL_BUILD_APPS=OFF -DDYNCULL_INSTALL=OFF -DDYNCULL_CHECK_HEADERS=OFF -DDYNCULL_CHECK_MIXING=OFF \
      -DDYNCULL_COMPARE_FORMS=OFF \
      -DDYNCULL_TEST_PER_EXECUTABLE=ON -DDYNCULL_UNOPTIMISED_TEST_MODULES="core;eval;ceres;opencv;host;culling;geometry" \
      -DDYNCULL_OPTIMISED_TEST_FILES="$(IFS=';'; echo "${optimised_test_files[*]}")" \
      -DCMAKE_CXX_FLAGS_DEBUG="" \
      -DCMAKE_CXX_FLAGS="-O1 -g1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" \
      -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
      -DDYNCULL_DATA_DIR="${DYNCULL_DATA_DIR:-}" >/dev/null
    export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    left_out=(SimDetectorCalibration.CalibratedModelMatchesTheRealYoloStreams
              SimScene.NoisyDetectionsStayCloseMissAndAddFalsePositives SimScene.PeopleCoverageLikeTumWalking
              SimScene.MovingTruthMatchesWorldMotion SimScene.MotionTruthIsTheSurfaceDisplacementPerFrame
              SimTrajectory.RecordedMotionFollowsTheRealTumGroundTruth
              DynamicVo.RecommendedPresetBeatsNoCullingOnShortXyz DynamicVo.CullerStrategyBeatsNoCullingOnShortXyz
              DynamicVo.TruthRepairedStrategiesUndoOneKindOfError
              OpenCvCuller.LabelsLikeTheHandFedPipelineOnTheWalkingScene
              CompiledCuller.GivesTheCoresLabelsOnTheWalkingSceneForEveryKeypointTypeWithoutExtraAllocations
              PipelineGolden.DoubleLabelsAndReasonsOfEveryPresetMatchTheRecordedOnes)
    export GTEST_FILTER="-$(IFS=:; echo "${left_out[*]}")"
    ctest_args=(-LE build_check)
    ;;
  *) echo "usage: $0 [--asan]" >&2; exit 2 ;;
esac
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs" ${ctest_args[@]+"${ctest_args[@]}"}
