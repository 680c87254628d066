#!/usr/bin/env bash
# Sanitizer builds, each run through its tests; any sanitizer report fails the run.
#
#   address  libranger_can, its tool, its unit tests and the system suites in tests/ with
#            AddressSanitizer + UndefinedBehaviorSanitizer (build/asan); every CTest case that
#            needs no kernel CAN support (label != vcan) but the lock-step suites (see below).
#   thread   ThreadSanitizer (build/tsan) on the suites that start threads: the tool and the
#            test executables labelled `threads` (CTest label; target ranger_threaded_tests), and
#            only their cases. The plain build's thread guard (libranger_can/test/thread_guard/)
#            fails a suite that starts a thread without the label, so a new threaded suite is
#            chosen by labelling it. The other suites run on the test's one thread: TSan has
#            nothing to watch in them.
#   ros      the ROS packages up to ranger_base (libranger_can, ranger_msgs, ranger_base) with
#            ASan + UBSan in a colcon workspace of their own (build/asan-ws, build/asan-install),
#            then ranger_base's gtests and rostests (the node itself runs instrumented).
#   ros_thread  the same with ThreadSanitizer (build/tsan-ws, build/tsan-install): the node's
#            threads (roscpp's spinners, the XML-RPC thread, the driver's) around our code, which
#            is instrumented; roscpp and Boost are not (see scripts/tsan_roscpp.supp).
#
# Usage: scripts/test_sanitizers.sh [address|thread|ros|ros_thread]...  (default: all four)
# Environment: RANGER_JOBS (default 2), CXX (default: the system compiler), RANGER_RESULTS
#   (directory for the JUnit reports asan.xml, tsan.xml, asan-ros/, tsan-ros/; default
#   build/test-results).
#   RANGER_SANITIZE_VCAN=1 also runs the `vcan` suites of the ASan build, natively or in the qemu
#   VM (scripts/run_vcan_tests.sh; it adds several minutes).
#
# A report fails the run twice over: the process halts at the first report (halt_on_error,
# -fno-sanitize-recover=all), and every instrumented process also writes its reports to
# <build dir>/sanitizer-reports/, so that a report raised in a child process (the CLI run by the
# CLI tests, the node run by rostest) fails the run even when whatever started it ignored its exit
# status. No suppressions are used, but in ros_thread for roscpp's own internals
# (scripts/tsan_roscpp.supp: roscpp comes uninstrumented, so TSan misses its atomics).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
kinds=("$@")
[ ${#kinds[@]} -gt 0 ] || kinds=(address thread ros ros_thread)
jobs=${RANGER_JOBS:-2}
results=${RANGER_RESULTS:-$root/build/test-results}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
mkdir -p build "$results" && touch build/COLCON_IGNORE

# Asserts stay on (no NDEBUG); stack traces are exact. ASan+UBSan builds at -O0: GCC compiles
# UBSan's checks at -O1 about four times slower (test_codec.cpp: 66 s against 16 s), while the tests
# run only about twice as long; ThreadSanitizer builds at -O1, where it compiles quickly and its
# runs stay bearable, with line tables only (-g1: reports keep file and line; 12 s against 17 s).
asan_common_flags="-O0 -g -fno-omit-frame-pointer"
tsan_common_flags="-O1 -g1 -fno-omit-frame-pointer"
asan_flags="-fsanitize=address,undefined -fno-sanitize-recover=all"
tsan_flags="-fsanitize=thread"

# Points every sanitizer at a report directory (emptied first).
set_sanitizer_env() {  # report_dir
  rm -rf "$1" && mkdir -p "$1"
  export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:log_path=$1/asan"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$1/ubsan"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:log_path=$1/tsan"
}
# Prints the reports in a directory; fails when there is any.
check_reports() {  # name report_dir
  shopt -s nullglob
  local files=("$2"/*)
  shopt -u nullglob
  [ ${#files[@]} -eq 0 ] && return 0
  echo "== $1: ${#files[@]} SANITIZER REPORT(S):"
  local f
  for f in "${files[@]}"; do
    echo "---- $f"
    head -n 60 "$f"
  done
  return 1
}

# libranger_can + tests/ with one sanitizer, via plain CMake from the repository root.
# SELECT: "all" (every target; every CTest case but the vcan ones) or "threads" (the tool and the
# suites labelled `threads`, ranger_threaded_tests; only their cases).
run_cmake_build() {  # name dir RANGER_SANITIZE common_flags flags SELECT [ctest -E regex]
  local name=$1 dir=$2 sanitize=$3 common_flags=$4 flags=$5 select=$6 exclude=${7:-}
  local start=$SECONDS rc=0 targets=() labels=(-LE vcan)
  if [ "$select" = threads ]; then
    targets=(--target ranger_can_tool ranger_threaded_tests)
    labels=(-L threads -LE vcan)
  fi
  echo "== $name: configure + build ($dir)"
  # RANGER_SANITIZE instruments libranger_can's directory; the system suites in tests/ are a
  # sibling directory, so the same flags also go in CMAKE_CXX_FLAGS to instrument them too.
  if ! cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug \
    -DRANGER_SANITIZE="$sanitize" -DRANGER_BUILD_BENCHMARKS=OFF -DRANGER_BUILD_TESTS=ON \
    -DCMAKE_CXX_FLAGS="$common_flags $flags" \
    -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" >/dev/null ||
    ! cmake --build "$dir" -j "$jobs" "${targets[@]}"; then
    echo "== $name: BUILD FAILED"
    return 1
  fi
  echo "== $name: built in $((SECONDS - start)) s"

  start=$SECONDS
  (
    set_sanitizer_env "$root/$dir/sanitizer-reports"
    echo "== $name: ctest (${labels[*]})"
    rc=0
    local skip=()
    [ -n "$exclude" ] && skip=(-E "$exclude")
    ctest --test-dir "$dir" "${labels[@]}" "${skip[@]}" --output-on-failure -j "$jobs" \
      --timeout 600 --no-tests=error --output-junit "$results/$name.xml" || rc=1
    if [ "${RANGER_SANITIZE_VCAN:-0}" = 1 ] && [ "$sanitize" = address ]; then
      echo "== $name: vcan suites"
      scripts/run_vcan_tests.sh "$dir" --junit "$results/$name-vcan.xml" || rc=1
    fi
    exit $rc
  ) || rc=1
  echo "== $name: tests ran in $((SECONDS - start)) s"
  check_reports "$name" "$root/$dir/sanitizer-reports" || rc=1
  return $rc
}

# ranger_base (and what it needs) with one sanitizer in a colcon workspace of its own, then its
# tests: the gtests and every rostest but the nodelet's (the node itself runs instrumented).
run_ros_build() {  # name workspace common_flags flags ctest_exclude_regex
  local name=$1 ws=build/$2 install=build/${2%-ws}-install common_flags=$3 flags=$4 exclude=$5
  local reports=$root/build/$2/sanitizer-reports start=$SECONDS rc=0
  echo "== $name: colcon build up to ranger_base ($ws)"
  (
    # ROS's Python tools need the system interpreter (python3 on PATH may be a pyenv).
    export PATH=/usr/bin:$PATH
    if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
    # Without make's load limit (colcon's default -l<cores>): beside the foreground's stages it
    # would build one file at a time.
    MAKEFLAGS=-j$jobs colcon --log-base "build/log-${2%-ws}" build --base-paths . \
      --packages-up-to ranger_base --build-base "$ws" --install-base "$install" \
      --event-handlers console_cohesion- summary+ --parallel-workers 1 \
      --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Debug \
      "-DCMAKE_CXX_FLAGS=$common_flags $flags" \
      "-DCMAKE_EXE_LINKER_FLAGS=$flags" "-DCMAKE_SHARED_LINKER_FLAGS=$flags" \
      -DCATKIN_ENABLE_TESTING=ON
  ) || { echo "== $name: BUILD FAILED"; return 1; }
  echo "== $name: built in $((SECONDS - start)) s"

  start=$SECONDS
  (
    export PATH=/usr/bin:$PATH
    if [ -f /opt/ros/noetic/setup.bash ]; then set +u; source /opt/ros/noetic/setup.bash; set -u; fi
    set +u; source "$install/setup.bash"; set -u
    export ROS_HOME=$root/$ws/ros_home ROS_HOSTNAME=localhost
    export ROS_MASTER_URI=http://localhost:11311
    set_sanitizer_env "$reports"
    # roscpp's own internals only (the file says which and why); what roscpp and rosconsole
    # (uninstrumented) do through the intercepted functions (memcpy, delete) is theirs, not ours
    # (ignore_noninstrumented_modules: TSan's setting for libraries built without it).
    [ "$name" != tsan-ros ] || export TSAN_OPTIONS="$TSAN_OPTIONS:ignore_noninstrumented_modules=1:suppressions=$root/scripts/tsan_roscpp.supp"
    # A sanitizer's runtime makes every exit slower (TSan: the node's exit took 314-365 ms under
    # load against the 0.3 s bound; ASan, whose leak check runs at exit: 268 ms in a fresh run):
    # node_shutdown's bound is the plain build's to hold (the ros stage, 64-116 ms there); here
    # the shutdown paths are run for their races, leaks and memory errors.
    case $name in
      tsan-ros) export RANGER_EXIT_BOUND_SCALE=4 ;;
      asan-ros) export RANGER_EXIT_BOUND_SCALE=2 ;;
    esac
    # Every rostest but the nodelet's: that one loads the plugin into the system's nodelet
    # manager, which is not instrumented (the sanitizer's runtime must come first in a process),
    # and uses ranger_bringup's launch file, which this workspace does not build. The nodelet and
    # the node are one class, which the other rostests run instrumented.
    colcon --log-base "build/log-${2%-ws}" test --base-paths . --packages-select ranger_base \
      --build-base "$ws" --install-base "$install" --event-handlers console_cohesion- \
      --executor sequential --return-code-on-test-failure --ctest-args -E "$exclude"
    test_rc=$?
    colcon test-result --test-result-base "$ws" --verbose
    rm -rf "${results:?}/$name" && mkdir -p "$results/$name"
    find "$ws" -path '*test_results*' -name '*.xml' -exec cp {} "$results/$name/" \;
    exit $test_rc
  ) || rc=1
  echo "== $name: tests ran in $((SECONDS - start)) s"
  check_reports "$name" "$reports" || rc=1
  return $rc
}

failed=()
for kind in "${kinds[@]}"; do
  case $kind in
    # The lock-step suites (LockStep/...: the chassis and the driver stepped in turn under a
    # ManualClock on the test's one thread, for minutes of simulated driving) are left to the plain
    # build (the unit stage): they start no thread, so ThreadSanitizer has nothing to watch in
    # them, and they drive the code that every other suite runs under ASan, for longer; in either
    # build they take half of the run time.
    address)
      name=asan
      run=(run_cmake_build asan build/asan address "$asan_common_flags" "$asan_flags" all '^LockStep/')
      ;;
    thread)
      name=tsan
      run=(run_cmake_build tsan build/tsan thread "$tsan_common_flags" "$tsan_flags" threads)
      ;;
    ros)
      name=asan-ros
      run=(run_ros_build asan-ros asan-ws "$asan_common_flags" "$asan_flags" node_nodelet)
      ;;
    ros_thread)
      name=tsan-ros
      # The suites that drive the node's threads: node_sim (every topic, service and the
      # virtual chassis's thread), remote, faults, shutdown (signals, rosnode kill), namespaces,
      # commissioning, bad parameters, answers, cmd_vel_stamped, and the gtests. Left to the
      # plain and ASan builds: the chassis variants' suites (fault bits, identification,
      # implausible feedback, MINI, vendor, adversarial), which run the same threads on other
      # frames, and the rate tests (hz), which measure rates, not threads.
      run=(run_ros_build tsan-ros tsan-ws "$tsan_common_flags" "$tsan_flags"
        'node_nodelet|node_sim_(fault_bits|identify|implausible|mini_v|unidentified|vendor|adversarial|hz)')
      ;;
    *)
      echo "test_sanitizers.sh: unknown build '$kind' (expected address, thread, ros or ros_thread)" >&2
      exit 2
      ;;
  esac
  if "${run[@]}"; then
    echo "== $name: ok, no sanitizer reports"
  else
    echo "== $name: FAILED"
    failed+=("$name")
  fi
done

if [ ${#failed[@]} -gt 0 ]; then
  echo "test_sanitizers.sh: failed: ${failed[*]}"
  exit 1
fi
echo "test_sanitizers.sh: all clean (${kinds[*]})"
