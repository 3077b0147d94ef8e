#!/usr/bin/python3
"""Drives or watches a running evidential_slam node for scripts/soak (parts b, c and d).

A robot in a 10 m x 10 m room, odometry exact, stepping 1 m back and forth along x so that every
scan passes the motion gate (every scan is a full filter update, and the map stops growing once
the room is seen). Publishes /tf (odom -> base_link) and /scan (360 rays) at --rate Hz, reads the
node's heartbeat on /diagnostics, its resident memory (/proc/PID/status) and the CPU time of its
filter thread ("slam_worker" in /proc/PID/task/*/comm).

  flood  --minutes M: publish for M minutes, then wait for the queue to drain; print the counts
         (sent, received, handled, drops by kind, queue length) and RSS at start, middle and end;
         exit 1 when a scan is not accounted for (received != handled + dropped) or one sent was
         not received.
  watch  --minutes M: another publisher (rosbag play) feeds the node; count the scans on /scan,
         sample the node as flood does, wait for the scans to stop and the queue to drain; exit
         1 when a scan is not accounted for or one on /scan was not received.
  saves  --saves S --save-dir DIR [--block B --max-seconds T --warmup W]: publish scans for W
         seconds (counted nowhere), then in blocks of B seconds, calling ~save_map into DIR
         throughout every other block, until S calls (or T seconds) and as many blocks with
         saves as without; print the filter thread's CPU
         seconds per handled scan in each kind of block (both see the same load).
"""
import argparse
import math
import os
import sys
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

HALF = 5.0  # the room's half size (m)
RAYS = 360
ANGLES = [-math.pi + i * (2 * math.pi / RAYS) for i in range(RAYS)]


def room_ranges(x):
    """Ranges from (x, 0) facing +x to the walls of the square room (|x|, |y| <= HALF)."""
    ranges = []
    for a in ANGLES:
        c, s = math.cos(a), math.sin(a)
        tx = (HALF - x) / c if c > 1e-12 else (-HALF - x) / c if c < -1e-12 else math.inf
        ty = HALF / s if s > 1e-12 else -HALF / s if s < -1e-12 else math.inf
        ranges.append(min(tx, ty))
    return ranges


class Heartbeat:
    def __init__(self):
        self.lock = threading.Lock()
        self.values = {}
        self.count = 0
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=10)

    def on_diagnostics(self, msg):
        for status in msg.status:
            if status.name.endswith("heartbeat"):
                with self.lock:
                    self.values = {kv.key: kv.value for kv in status.values}
                    self.count += 1

    def get(self, key, default=0.0):
        with self.lock:
            return float(self.values.get(key, default))

    def wait_newer(self, timeout=5.0):
        with self.lock:
            seen = self.count
        end = time.time() + timeout
        while time.time() < end:
            with self.lock:
                if self.count > seen:
                    return True
            time.sleep(0.05)
        return False


def rss_mb(pid):
    with open("/proc/%d/status" % pid) as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def worker_cpu(pid):
    """CPU seconds (user, system) of the node's slam_worker thread."""
    tick = os.sysconf("SC_CLK_TCK")
    for tid in os.listdir("/proc/%d/task" % pid):
        base = "/proc/%d/task/%s/" % (pid, tid)
        try:
            with open(base + "comm") as fh:
                if fh.read().strip() != "slam_worker":
                    continue
            with open(base + "stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
            return int(fields[11]) / tick, int(fields[12]) / tick
        except OSError:
            continue
    raise RuntimeError("no slam_worker thread in process %d" % pid)


def worker_cpu_s(pid):
    """CPU seconds (user + system) of the node's slam_worker thread."""
    return sum(worker_cpu(pid))


class Robot:
    def __init__(self):
        self.tf = rospy.Publisher("/tf", TFMessage, queue_size=1000)
        self.static_tf = rospy.Publisher("/tf_static", TFMessage, queue_size=1, latch=True)
        laser = TransformStamped()
        laser.header.stamp = rospy.Time.now()
        laser.header.frame_id = "base_link"
        laser.child_frame_id = "laser"
        laser.transform.rotation.w = 1.0
        self.static_tf.publish(TFMessage([laser]))
        self.pub = rospy.Publisher("/scan", LaserScan, queue_size=1000)
        self.sent = 0
        self.ranges = {x: room_ranges(x) for x in (-0.5, 0.5)}

    def step(self):
        x = -0.5 if self.sent % 2 == 0 else 0.5
        stamp = rospy.Time.now()
        t = TransformStamped()
        t.header.stamp = stamp
        t.header.frame_id = "odom"
        t.child_frame_id = "base_link"
        t.transform.translation.x = x
        t.transform.rotation.w = 1.0
        self.tf.publish(TFMessage([t]))
        scan = LaserScan()
        scan.header.stamp = stamp
        scan.header.frame_id = "laser"
        scan.angle_min = float(ANGLES[0])
        scan.angle_increment = 2 * math.pi / RAYS
        scan.angle_max = float(ANGLES[-1])
        scan.range_min = 0.05
        scan.range_max = 20.0
        scan.ranges = self.ranges[x]
        self.pub.publish(scan)
        self.sent += 1


def wait_for_node(hb, robot):
    end = time.time() + 60
    while time.time() < end and not rospy.is_shutdown():
        if robot.pub.get_num_connections() > 0 and hb.wait_newer(2.0):
            return
        time.sleep(0.2)
    sys.exit("soak_node: the node did not come up (no subscriber on /scan or no heartbeat)")


def drain(hb, timeout):
    """Waits until every received scan is accounted for (or the time-out)."""
    end = time.time() + timeout
    while time.time() < end:
        hb.wait_newer()
        if hb.get("queue length") == 0 and accounted(hb) >= hb.get("scans received"):
            return True
    return False


DROPS = ["dropped: queue full", "dropped: malformed", "dropped: no transform",
         "dropped: older stamp", "dropped: stamp outlier", "refused: limits"]


def accounted(hb):
    # "handled" counts the worker's scans, whose later drops (older stamp, outlier, limits) are
    # among them; the others never reached the worker.
    return (hb.get("scans handled") + hb.get("dropped: queue full") + hb.get("dropped: malformed")
            + hb.get("dropped: no transform"))


def print_rss(part, samples):
    """The RSS at the start, middle and end of the samples (t, rss, ...), and its range."""
    rss = [s[1] for s in samples]
    mid = samples[len(samples) // 2]
    print("%s: RSS start %.1f MB (t = %.0f s), middle %.1f MB (t = %.0f s), end %.1f MB "
          "(t = %.0f s); min %.1f, max %.1f" % (
              part, samples[0][1], samples[0][0], mid[1], mid[0], samples[-1][1],
              samples[-1][0], min(rss), max(rss)))


def check_accounted(part, drained, received, hb):
    """Prints and checks that the queue drained and every received scan is accounted for."""
    ok = True
    if not drained:
        print("%s: FAIL: the queue did not drain within 300 s" % part)
        ok = False
    lost = received - accounted(hb)
    print("%s: received - (handled + queue full + malformed + no transform) = %d" % (part, lost))
    if lost != 0:
        print("%s: FAIL: scans not accounted for" % part)
        ok = False
    return ok


def flood(args, hb, robot):
    period = 1.0 / args.rate
    duration = args.minutes * 60.0
    samples = []  # (t, rss, received, handled, queue)
    t0 = time.time()
    next_sample = t0
    next_pub = t0
    queue_max = 0.0
    while not rospy.is_shutdown():
        now = time.time()
        if now - t0 >= duration:
            break
        if now >= next_pub:
            robot.step()
            next_pub += period
            if next_pub < now - 1.0:
                next_pub = now  # behind by a second: do not burst
        if now >= next_sample:
            queue_max = max(queue_max, hb.get("queue length"))
            samples.append((now - t0, rss_mb(args.pid), hb.get("scans received"),
                            hb.get("scans handled"), hb.get("queue length")))
            next_sample += 10.0
        time.sleep(max(0.0, min(next_pub, next_sample) - time.time()))
    publish_s = time.time() - t0
    handled_publishing = hb.get("scans handled")
    drained = drain(hb, 300.0)
    time.sleep(2.0)
    hb.wait_newer()
    received = hb.get("scans received")
    handled = hb.get("scans handled")
    drops = {k: hb.get(k) for k in DROPS}
    print("flood: %.0f s at %.0f Hz: sent %d, received %d, handled %d (%.1f per s while "
          "publishing: published/handled rate %.1f)" % (
              publish_s, args.rate, robot.sent, received, handled,
              handled_publishing / publish_s, robot.sent / max(1.0, handled_publishing)))
    print("flood: " + ", ".join("%s %d" % (k, v) for k, v in drops.items()))
    print("flood: queue length max %d of %d (sampled every 10 s)" % (
        queue_max, hb.get("queue capacity")))
    print_rss("flood", samples)
    for s in samples:
        print("flood:   t %6.0f s  RSS %7.1f MB  received %8d  handled %7d  queue %5d" % s)
    ok = check_accounted("flood", drained, received, hb)
    if robot.sent != received:
        print("flood: FAIL: %d scans sent but not received" % (robot.sent - received))
        ok = False
    return ok


def watch(args, hb):
    """Another publisher (rosbag play) feeds the node: counts the scans on /scan, samples the
    node for --minutes, then waits until the scans stop and the queue drains."""
    seen = {"n": 0, "last": time.time()}

    def on_scan(_):
        seen["n"] += 1
        seen["last"] = time.time()

    rospy.Subscriber("/scan", LaserScan, on_scan, queue_size=100000)
    samples = []  # (t, rss, seen, received, handled, queue, queue-full drops, restarts)
    t0 = time.time()
    while not rospy.is_shutdown() and time.time() - t0 < args.minutes * 60.0:
        hb.wait_newer()
        samples.append((time.time() - t0, rss_mb(args.pid), seen["n"], hb.get("scans received"),
                        hb.get("scans handled"), hb.get("queue length"),
                        hb.get("dropped: queue full"), hb.get("restarts")))
        time.sleep(max(0.0, t0 + 10.0 * len(samples) - time.time()))
    while time.time() - seen["last"] < 5.0:  # the publisher stops at the same time
        time.sleep(0.5)
    drained = drain(hb, 300.0)
    time.sleep(2.0)
    hb.wait_newer()
    received, handled = hb.get("scans received"), hb.get("scans handled")
    print("watch: %.0f s: scans on /scan %d, received %d, handled %d, restarts %d" % (
        time.time() - t0, seen["n"], received, handled, hb.get("restarts")))
    print("watch: " + ", ".join("%s %d" % (k, hb.get(k)) for k in DROPS))
    print("watch: queue length max %d of %d (sampled every 10 s)" % (
        max(s[5] for s in samples), hb.get("queue capacity")))
    print_rss("watch", samples)
    for s in samples:
        print("watch:   t %6.0f s  RSS %7.1f MB  on /scan %8d  received %8d  handled %7d  "
              "queue %5d  queue full %8d  restarts %4d" % s)
    ok = check_accounted("watch", drained, received, hb)
    if seen["n"] != received:
        print("watch: FAIL: %d scans on /scan, %d received by the node" % (seen["n"], received))
        ok = False
    return ok


def saves(args, hb, robot):
    """Blocks of --block seconds, saving in every other one, so both kinds see the same load."""
    from evidential_slam.srv import SaveMap
    state = {"saving": False, "calls": 0, "failed": 0, "first_error": "", "stop": False}

    def saver():
        rospy.wait_for_service("/evidential_slam/save_map", 30)
        call = rospy.ServiceProxy("/evidential_slam/save_map", SaveMap, persistent=True)
        while not state["stop"] and state["calls"] < args.saves and not rospy.is_shutdown():
            if not state["saving"]:
                time.sleep(0.05)
                continue
            try:
                r = call(args.save_dir)
                ok, why = r.success, r.message
            except rospy.ServiceException as e:
                ok, why = False, str(e)
            state["calls"] += 1
            if not ok:
                state["failed"] += 1
                state["first_error"] = state["first_error"] or why

    thread = threading.Thread(target=saver, daemon=True)
    if args.saves > 0:
        thread.start()
    period = 1.0 / args.rate
    # Warm-up, counted in no block: the filter's CPU per scan grows while the map fills in (in
    # the first 60 s a scan cost about 2/3 of a later one), which would favour the first block.
    start = next_pub = time.time()
    while not rospy.is_shutdown() and time.time() - start < args.warmup:
        robot.step()
        next_pub += period
        time.sleep(max(0.0, next_pub - time.time()))
    if args.warmup > 0:
        hb.wait_newer()
        print("saves: %.0f s warm-up: %d scans handled, counted in no block" % (
            args.warmup, hb.get("scans handled")), flush=True)
    totals = {False: [0.0, 0.0], True: [0.0, 0.0]}  # saving -> [cpu s, handled]
    blocks = {False: 0, True: 0}
    t0 = time.time()
    # (wall, monotonic, (user, system) CPU s, handled, calls) at the start of the block
    mark = (time.time(), time.monotonic(), worker_cpu(args.pid), hb.get("scans handled"),
            state["calls"])
    next_pub = t0
    while not rospy.is_shutdown():
        now = time.time()
        if now - mark[0] >= args.block:
            hb.wait_newer()
            cpu, handled, calls = worker_cpu(args.pid), hb.get("scans handled"), state["calls"]
            user, system = cpu[0] - mark[2][0], cpu[1] - mark[2][1]
            totals[state["saving"]][0] += user + system
            totals[state["saving"]][1] += handled - mark[3]
            blocks[state["saving"]] += 1
            # One line per block; the monotonic times match `perf record --clockid monotonic`.
            print("saves: block %d %s saves: monotonic %.3f-%.3f s, %d calls, %d scans handled, "
                  "filter thread CPU %.2f s (user %.2f, system %.2f), %.2f ms per scan, "
                  "load %s" % (blocks[False] + blocks[True], "with" if state["saving"] else
                              "without", mark[1], time.monotonic(), calls - mark[4],
                              handled - mark[3], user + system, user, system,
                              1000.0 * (user + system) / max(1.0, handled - mark[3]),
                              os.getloadavg()[0]), flush=True)
            mark = (time.time(), time.monotonic(), cpu, handled, calls)
            done = now - t0 >= args.max_seconds or (args.saves > 0 and state["calls"] >= args.saves)
            if done and blocks[True] == blocks[False]:
                break
            state["saving"] = args.saves > 0 and not state["saving"]
        if now >= next_pub:
            robot.step()
            next_pub = max(next_pub + period, now - 1.0)
        time.sleep(max(0.0, min(next_pub, mark[0] + args.block) - time.time()))
    state["saving"] = False
    state["stop"] = True
    wall = time.time() - t0
    ms = {k: 1000.0 * v[0] / max(1.0, v[1]) for k, v in totals.items()}
    print("saves: %.0f s, %d scans sent, queue-full drops %d; %d save_map calls (%d failed%s); "
          "node RSS %.1f MB" % (wall, robot.sent, hb.get("dropped: queue full"), state["calls"],
                                state["failed"],
                                (": " + state["first_error"]) if state["failed"] else "",
                                rss_mb(args.pid)))
    for k in (False, True):
        print("saves: %d blocks of %.0f s %s saves: %d scans handled, filter thread CPU %.2f s, "
              "%.2f ms per scan" % (blocks[k], args.block, "with" if k else "without",
                                     totals[k][1], totals[k][0], ms[k]))
    print("RESULT without_ms=%.3f with_ms=%.3f saves=%d failed=%d" % (
        ms[False], ms[True], state["calls"], state["failed"]))
    return state["failed"] == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mode", choices=["flood", "saves", "watch"])
    ap.add_argument("--pid", type=int, required=True, help="the node's process id")
    ap.add_argument("--rate", type=float, default=100.0, help="scans per second")
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--scans", type=int, default=300)
    ap.add_argument("--saves", type=int, default=0)
    ap.add_argument("--save-dir", default="/tmp/soak_saves")
    ap.add_argument("--max-seconds", type=float, default=1e9, help="stop after this")
    ap.add_argument("--block", type=float, default=60.0, help="seconds with, then without saves")
    ap.add_argument("--warmup", type=float, default=0.0, help="seconds of scans before the blocks")
    args = ap.parse_args()
    rospy.init_node("soak_driver", disable_signals=True)
    hb = Heartbeat()
    if args.mode == "watch":
        if not hb.wait_newer(60.0):
            sys.exit("soak_node: the node did not come up (no heartbeat)")
        sys.exit(0 if watch(args, hb) else 1)
    robot = Robot()
    wait_for_node(hb, robot)
    ok = flood(args, hb, robot) if args.mode == "flood" else saves(args, hb, robot)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
