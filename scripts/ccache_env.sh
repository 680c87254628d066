# Sourced (bash): one compiler cache for every build of scripts/test.sh (issue 34), kept between
# runs. Every build of the run reaches it through CMake's CMAKE_<LANG>_COMPILER_LAUNCHER
# environment variables (CMake >= 3.17; the CMake 3.16 step passes it itself), so the build tools
# run as a user runs them and a file compiled alike twice is compiled once: the library in the
# colcon, catkin_make, catkin build and colcon-in-a-fresh-workspace builds, and everything on a
# second run. Paths under the checkout are hashed relative to the build directory (base_dir), so
# a fresh clone elsewhere finds the objects of an earlier one; the directory is not hashed
# (hash_dir off: only debug information names it).
#   RANGER_CCACHE=0            no compiler cache
#   RANGER_CCACHE_DIR=DIR      the cache (default ~/.cache/ranger_ros/ccache)
#   RANGER_CCACHE_MAXSIZE=SIZE (default 8G; a whole run's objects took 0.3 GB compressed)
# ranger_ccache_summary prints the run's hit rate (the statistics are zeroed when sourced).
ranger_ccache_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ranger_ccache_on=0
if [ "${RANGER_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null; then
  ranger_ccache_on=1
  export CCACHE_DIR=${RANGER_CCACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/ranger_ros/ccache}
  export CCACHE_BASEDIR=$ranger_ccache_root CCACHE_NOHASHDIR=true
  export CCACHE_MAXSIZE=${RANGER_CCACHE_MAXSIZE:-8G}
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
  mkdir -p "$CCACHE_DIR"
  ccache --zero-stats >/dev/null
fi

# "compiler cache: 812 of 1540 compilations were hits (52.7 %), 2.1 GB in ~/.cache/..."
ranger_ccache_summary() {
  if [ "$ranger_ccache_on" != 1 ]; then
    echo "compiler cache: off (RANGER_CCACHE=0 or no ccache)"
    return 0
  fi
  ccache --print-stats 2>/dev/null | awk -v dir="$CCACHE_DIR" '
    $1 == "direct_cache_hit" || $1 == "preprocessed_cache_hit" { hits += $2 }
    $1 == "cache_miss" { misses += $2 }
    $1 == "cache_size_kibibyte" { size = $2 }
    END {
      total = hits + misses
      rate = total > 0 ? 100.0 * hits / total : 0
      printf "compiler cache: %d of %d compilations were hits (%.1f %%), %.1f GB in %s\n", hits,
        total, rate, size / 1048576.0, dir
    }'
}
