#!/usr/bin/python3
"""The pose a navigation stack sees while mapping, against the simulator's truth (issue 54).

Starts `roslaunch evidential_slam simulator.launch rviz:=false` (its defaults; more launch
arguments after --) on a roscore of its own, and while the simulator drives its route, at every
scan (each `ground_truth_pose`, stamped t) takes what a tf lookup of map -> base_link at t gives
at that moment: the map -> odom broadcasts received so far, interpolated at t as tf does, composed
with the odometry (odom -> base_link at t). Against the truth at t it prints the position and
heading error, and the filter's lag: the clock at that moment minus the stamp of the newest
handled scan (`~pose`). Ends when the route ends (`~done`).
  /usr/bin/python3 bench/pose_lag.py [--port 11633] [--out DIR] [-- rate:=2 particles:=30 ...]
  /usr/bin/python3 bench/pose_lag.py --check [--junit FILE] -- duration:=40 particles:=30
With --check (the smoke test) it fails unless most scans were evaluated, the median lag is within
--max-lag, the final best path's median error (after the fit) within --max-final-error, and the
median error of the pose seen while mapping within --max-error: loose, as the online estimate may
follow a wrong particle for a while (1.1 m in one of three 30 s runs at K = 30), but a broken
transform chain (map -> odom missing, inverted or from another scan) is off by metres.
Needs a built workspace (scripts/setup); run it from a shell where scripts/env was sourced.
"""

import argparse
import bisect
import math
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import smoke_check  # bench/, this script's folder


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def compose(a, b):
    x, y, th = a
    c, s = math.cos(th), math.sin(th)
    return (x + c * b[0] - s * b[1], y + s * b[0] + c * b[1], th + b[2])


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


class Stamped:
    """Planar transforms by stamp (ns), looked up as tf does: exact, else interpolated between
    the two neighbours, else the newest within `extrapolate_ns` of it."""

    def __init__(self):
        self.stamps, self.poses = [], []

    def add(self, stamp, pose):
        i = bisect.bisect_left(self.stamps, stamp)
        if i < len(self.stamps) and self.stamps[i] == stamp:
            return  # tf keeps the first transform at a stamp
        self.stamps.insert(i, stamp)
        self.poses.insert(i, pose)

    def at(self, stamp):
        i = bisect.bisect_left(self.stamps, stamp)
        if i < len(self.stamps) and self.stamps[i] == stamp:
            return self.poses[i]
        if i == 0 or i == len(self.stamps):
            return None  # tf would refuse to extrapolate
        t0, t1 = self.stamps[i - 1], self.stamps[i]
        a, b = self.poses[i - 1], self.poses[i]
        u = (stamp - t0) / (t1 - t0)
        return (a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * wrap(b[2] - a[2]))


def percentile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))]


def aligned_errors(seen, truth):
    """Position errors after the rigid 2-D fit of `seen` onto `truth` (Kabsch, as the ATE's): the
    map frame's own offset from the world taken out."""
    n = len(seen)
    ms = [sum(p[i] for p in seen) / n for i in (0, 1)]
    mt = [sum(p[i] for p in truth) / n for i in (0, 1)]
    sxx = sxy = 0.0
    for (ax, ay, _), (bx, by, _) in zip(seen, truth):
        ax, ay, bx, by = ax - ms[0], ay - ms[1], bx - mt[0], by - mt[1]
        sxx += ax * bx + ay * by
        sxy += ax * by - ay * bx
    c, s = math.cos(math.atan2(sxy, sxx)), math.sin(math.atan2(sxy, sxx))
    return [math.hypot(c * (a[0] - ms[0]) - s * (a[1] - ms[1]) + mt[0] - b[0],
                       s * (a[0] - ms[0]) + c * (a[1] - ms[1]) + mt[1] - b[1])
            for a, b in zip(seen, truth)]


def measure(args):
    import rospy
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from std_msgs.msg import Bool
    from tf2_msgs.msg import TFMessage

    # rospy reads /use_sim_time once, at init: wait until the launch has set it (a busy machine
    # starts the master late), else the lag would be measured on the wall clock.
    import rosgraph
    master, deadline = rosgraph.Master("/pose_lag"), time.time() + 120
    while time.time() < deadline:
        try:
            if master.hasParam("/use_sim_time"):
                break
        except (OSError, rosgraph.MasterException):
            pass  # the master is not up yet
        time.sleep(0.5)
    rospy.init_node("pose_lag", anonymous=True)
    map_to_odom, odom_to_base = Stamped(), Stamped()
    pending = []  # truth poses waiting for their odometry
    rows = []
    state = {"pose_stamp": None, "done": False, "truths": 0}
    lock = threading.Lock()  # rospy runs each subscription's callbacks on a thread of its own

    def on_tf(msg):
        with lock:
            on_tf_locked(msg)

    def on_tf_locked(msg):
        for t in msg.transforms:
            p = (t.transform.translation.x, t.transform.translation.y, yaw_of(t.transform.rotation))
            if t.header.frame_id == "map" and t.child_frame_id == "odom":
                map_to_odom.add(t.header.stamp.to_nsec(), p)
            elif t.header.frame_id == "odom" and t.child_frame_id == "base_link":
                odom_to_base.add(t.header.stamp.to_nsec(), p)
        evaluate()

    def on_truth(msg):
        with lock:
            on_truth_locked(msg)

    def on_truth_locked(msg):
        state["truths"] += 1
        pending.append((msg.header.stamp.to_nsec(), (msg.pose.position.x, msg.pose.position.y,
                                                     yaw_of(msg.pose.orientation))))
        evaluate()

    def evaluate():
        now = rospy.Time.now().to_nsec()
        while pending:
            stamp, truth = pending[0]
            odom = odom_to_base.at(stamp)
            if odom is None and now - stamp < 1e9:
                return  # its odometry may still come
            pending.pop(0)
            correction = map_to_odom.at(stamp)
            if odom is None or correction is None or state["pose_stamp"] is None:
                continue
            seen = compose(correction, odom)
            rows.append((stamp * 1e-9, math.hypot(seen[0] - truth[0], seen[1] - truth[1]),
                         abs(wrap(seen[2] - truth[2])), (now - state["pose_stamp"]) * 1e-9,
                         seen, truth))

    def on_pose(msg):
        with lock:
            state["pose_stamp"] = msg.header.stamp.to_nsec()

    def on_done(msg):
        state["done"] = state["done"] or msg.data

    rospy.Subscriber("/tf", TFMessage, on_tf, queue_size=1000)
    rospy.Subscriber("/ground_truth_pose", PoseStamped, on_truth, queue_size=1000)
    rospy.Subscriber("/evidential_slam/pose", PoseWithCovarianceStamped, on_pose, queue_size=100)
    rospy.Subscriber("/gridmap_simulator/done", Bool, on_done, queue_size=1)
    deadline = time.time() + args.timeout
    while not rospy.is_shutdown() and not state["done"] and time.time() < deadline:
        time.sleep(0.2)
    # The final best path, for comparison: save_map writes it (trajectory.tum).
    from evidential_slam.srv import SaveMap
    final = {}
    try:
        rospy.wait_for_service("/evidential_slam/save_map", 10)
        directory = os.path.join(args.out, "final")
        if rospy.ServiceProxy("/evidential_slam/save_map", SaveMap)(directory).success:
            with open(os.path.join(directory, "trajectory.tum")) as f:
                for line in f:
                    if line.strip() and not line.startswith("#"):
                        v = line.split()
                        final[round(float(v[0]), 3)] = (float(v[1]), float(v[2]), 0.0)
    except (rospy.ROSException, rospy.ServiceException, OSError) as e:
        # rospy.ServiceException (a failed call) is not a ROSException.
        print(f"no final path: {e!r}")
    return rows, final, state["truths"]


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--port", type=int, default=11633, help="the roscore's port [11633]")
    ap.add_argument("--out", help="directory for the logs and pose_lag.csv (default: a new one)")
    ap.add_argument("--timeout", type=float, default=1800, help="wall s at most [1800]")
    ap.add_argument("--check", action="store_true",
                    help="fail unless the scans were evaluated and lag and error are within bounds")
    ap.add_argument("--max-lag", type=float, default=1.0,
                    help="with --check: median lag at most this, s [1.0]")
    ap.add_argument("--max-error", type=float, default=2.0,
                    help="with --check: median position error while mapping at most this, m [2.0]")
    ap.add_argument("--max-final-error", type=float, default=0.25,
                    help="with --check: the final best path's median error at most this, m [0.25]")
    ap.add_argument("--junit", help="with --check: write the verdict as a JUnit file")
    ap.add_argument("launch_args", nargs="*", help="after --: simulator.launch arguments")
    args = ap.parse_args()
    out = args.out = args.out or tempfile.mkdtemp(prefix="pose_lag.")
    os.makedirs(out, exist_ok=True)
    os.environ["ROS_MASTER_URI"] = f"http://localhost:{args.port}"
    os.environ["ROS_HOME"] = os.path.join(out, "ros_home")
    launch = ["roslaunch", "-p", str(args.port), "evidential_slam", "simulator.launch",
              "rviz:=false"] + args.launch_args
    print(f"running: {' '.join(launch)} (logs in {out})", flush=True)
    with open(os.path.join(out, "launch.log"), "w") as log:
        proc = subprocess.Popen(launch, stdout=log, stderr=subprocess.STDOUT)
    try:
        time.sleep(3)
        rows, final, truths = measure(args)
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
    if not rows:
        if args.check:
            check(args, ["no scan evaluated (see launch.log)"])
        sys.exit("no scan evaluated (see launch.log)")
    with open(os.path.join(out, "pose_lag.csv"), "w") as f:
        f.write("stamp,position_error_m,heading_error_rad,lag_s\n")
        for r in rows:
            f.write("%.3f,%.4f,%.5f,%.3f\n" % r[:4])
    err, head, lag = ([r[i] for r in rows] for i in (1, 2, 3))
    aligned = aligned_errors([r[4] for r in rows], [r[5] for r in rows])
    print(f"{len(rows)} scans over {rows[-1][0] - rows[0][0]:.0f} s of simulated time")
    print("| | median | 95 % | max |\n|---|---|---|---|")
    print("| position error (m) | %.3f | %.3f | %.3f |" % (statistics.median(err),
                                                          percentile(err, 0.95), max(err)))
    print("| position error after the run's best rigid fit (m) | %.3f | %.3f | %.3f |" % (
        statistics.median(aligned), percentile(aligned, 0.95), max(aligned)))
    pairs = [(final[round(r[0], 3)], r[5]) for r in rows if round(r[0], 3) in final]
    if pairs:
        fe = aligned_errors([p[0] for p in pairs], [p[1] for p in pairs])
        print("| the final best path, same fit (m) | %.3f | %.3f | %.3f |" % (
            statistics.median(fe), percentile(fe, 0.95), max(fe)))
    print("| heading error (deg) | %.2f | %.2f | %.2f |" % tuple(math.degrees(v) for v in (
        statistics.median(head), percentile(head, 0.95), max(head))))
    print("| lag behind the simulator (s) | %.2f | %.2f | %.2f |" % (
        statistics.median(lag), percentile(lag, 0.95), max(lag)))
    print(f"per scan: {os.path.join(out, 'pose_lag.csv')}")
    if args.check:
        failures = []
        if len(rows) < 0.8 * truths:
            failures.append(f"{len(rows)} of {truths} scans evaluated (< 80 %)")
        if statistics.median(lag) > args.max_lag:
            failures.append(f"median lag {statistics.median(lag):.2f} s > {args.max_lag} s")
        if statistics.median(err) > args.max_error:
            failures.append(f"median position error {statistics.median(err):.3f} m > "
                            f"{args.max_error} m")
        if not pairs:
            failures.append("no final path")
        elif statistics.median(fe) > args.max_final_error:
            failures.append(f"final path's median error {statistics.median(fe):.3f} m > "
                            f"{args.max_final_error} m")
        sys.exit(0 if check(args, failures) else 1)


def check(args, failures):
    """The smoke test's verdict (--check), also as a JUnit file (--junit)."""
    return smoke_check.report(failures, args.junit, "pose_lag", "pose_lag")


if __name__ == "__main__":
    smoke_check.run(main, "pose_lag", "pose_lag")
