# Sourced (bash): the compiler flags the scripts build with, in one place.
# RelWithDebInfo is -O2 with line tables only (-g1): backtraces, sanitizers and perf keep file and
# line, and a build takes about a third less time than with full debug information (-g: every type
# and variable; test_codec.cpp compiles in 15 s against 22 s). RANGER_RELWITHDEBINFO_FLAGS
# replaces them. Used by scripts/build.sh, scripts/fuzz.sh and scripts/test_ros2.sh.
# shellcheck disable=SC2034  # read by the scripts that source this file
ranger_relwithdebinfo_flags=${RANGER_RELWITHDEBINFO_FLAGS:--O2 -g1 -DNDEBUG}
