# Shared by scripts/setup, demo, test and offline (sourced, not run). Sets:
#   REPO  the repository root (the package), WS  its catkin workspace (<repo>/.ws),
#   CATKIN_ARGS  the catkin_make arguments every script uses (so no script forces a re-configure).
# With ES_SANITIZE=address,undefined (or thread) the workspace is <repo>/.ws-asan (.ws-tsan),
# built with those sanitizers (RelWithDebInfo at -O1 -g1) and without the clang fuzz targets.
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
PKG=evidential_slam
case "${ES_SANITIZE:-}" in
  "")
    WS="$REPO/.ws"
    BUILD_TYPE=Release
    CATKIN_ARGS=(-C "$WS" -DCMAKE_BUILD_TYPE=$BUILD_TYPE -DPYTHON_EXECUTABLE=/usr/bin/python3)
    ;;
  address,undefined | thread)
    if [[ "$ES_SANITIZE" == thread ]]; then WS="$REPO/.ws-tsan"; else WS="$REPO/.ws-asan"; fi
    # GCC 12 warns of uninitialised std::function members inside <regex> when instrumenting (a
    # false positive in libstdc++'s headers); the Release build keeps the warning.
    san_flags="-fsanitize=$ES_SANITIZE -fno-omit-frame-pointer -Wno-maybe-uninitialized"
    [[ "$ES_SANITIZE" == thread ]] || san_flags+=" -fno-sanitize-recover=undefined"
    BUILD_TYPE=RelWithDebInfo
    # -O1 and line tables only (-g1): the reports keep file:line, the build takes much less time
    # than -O2 -g (it is the longest part of a sanitizer run on 2 cores).
    opt_flags="-O1 -g1 -DNDEBUG"
    CATKIN_ARGS=(-C "$WS" -DCMAKE_BUILD_TYPE=$BUILD_TYPE -DPYTHON_EXECUTABLE=/usr/bin/python3
      "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$opt_flags" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$opt_flags"
      "-DCMAKE_CXX_FLAGS=$san_flags" "-DCMAKE_C_FLAGS=$san_flags"
      "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=$ES_SANITIZE"
      "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=$ES_SANITIZE" -DES_BUILD_FUZZERS=OFF)
    unset san_flags opt_flags
    ;;
  *)
    printf '[%s] error: ES_SANITIZE=%s: use address,undefined or thread\n' "$(basename "$0")" \
      "$ES_SANITIZE" >&2
    exit 1
    ;;
esac
# ccache, when installed, caches compilations across rebuilds, workspaces and worktrees: paths
# under the repository are hashed relative to it (CCACHE_BASEDIR), so two clones share entries.
if command -v ccache >/dev/null 2>&1 && [[ "${ES_NO_CCACHE:-0}" != 1 ]]; then
  CATKIN_ARGS+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$REPO}"
  # A rebuild after a header edit compiles the same sources with new contents: never stale.
  export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
fi
OFFLINE_BIN="$WS/devel/lib/$PKG/evidential_slam_offline"
JOBS="${JOBS:-2}"

# Debian's python3 (and its ROS modules) before any pyenv/venv python3 on PATH.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:${PATH:-}"
# ROS writes logs and caches under ROS_HOME (default ~/.ros): keep them in the workspace.
export ROS_HOME="${ROS_HOME:-$WS/ros_home}"
export ROS_LOG_DIR="${ROS_LOG_DIR:-$ROS_HOME/log}"

say() { printf '[%s] %s\n' "$(basename "$0")" "$*"; }
die() { printf '[%s] error: %s\n' "$(basename "$0")" "$*" >&2; exit 1; }
