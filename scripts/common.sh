# Shared by scripts/setup, demo, test and offline (sourced, not run). Sets:
#   REPO  the repository root (the package), WS  its catkin workspace (<repo>/.ws),
#   CATKIN_ARGS  the catkin_make arguments every script uses (so no script forces a re-configure).
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)"
WS="$REPO/.ws"
PKG=evidential_slam
OFFLINE_BIN="$WS/devel/lib/$PKG/evidential_slam_offline"
CATKIN_ARGS=(-C "$WS" -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3)
JOBS="${JOBS:-2}"

# Debian's python3 (and its ROS modules) before any pyenv/venv python3 on PATH.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:${PATH:-}"
# ROS writes logs and caches under ROS_HOME (default ~/.ros): keep them in the workspace.
export ROS_HOME="${ROS_HOME:-$WS/ros_home}"
export ROS_LOG_DIR="${ROS_LOG_DIR:-$ROS_HOME/log}"

say() { printf '[%s] %s\n' "$(basename "$0")" "$*"; }
die() { printf '[%s] error: %s\n' "$(basename "$0")" "$*" >&2; exit 1; }
