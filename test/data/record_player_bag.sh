#!/usr/bin/env bash
# Re-records test/data/sim_player.bag: rawlog_player plays sim.rawlog at 5x and rosbag records
# what a robot would publish (/scan, /tf, /tf_static), bz2-compressed. Needs a built workspace.
#   test/data/record_player_bag.sh [PORT]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck disable=SC1091
set +u  # catkin's setup scripts read unset variables
source "$here/../../scripts/env"
set -u
port="${1:-11712}"
export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$(mktemp -d)"
roscore -p "$port" >/dev/null 2>&1 &
core=$!
trap 'kill $core 2>/dev/null || true' EXIT
sleep 3
rosparam set /use_sim_time true
rosbag record --bz2 -O "$here/sim_player.bag" /scan /tf /tf_static >/dev/null 2>&1 &
rec=$!
sleep 2
rosrun evidential_slam rawlog_player _rawlog:="$here/sim.rawlog" _rate:=5 _start_delay:=1 \
  _wait_for_subscriber:=0 >/dev/null 2>&1 &
player=$!
until [[ "$(timeout 2 rostopic echo -n1 /rawlog_player/done/data 2>/dev/null | head -1)" == True ]]; do
  sleep 1
done
sleep 1
kill -INT "$rec"
wait "$rec" || true
kill "$player" 2>/dev/null || true
rosbag info "$here/sim_player.bag"
