#!/usr/bin/python3
"""Benchmark: evidential_slam_offline against MRPT's rbpf-slam, in one run.

For every log it runs
  ours           evidential_slam_offline --particles K (default 100)
  mrpt-standard  rbpf-slam, standard proposal, K = 100  (bench/mrpt_standard_k100.ini)
  mrpt-optimal   rbpf-slam, optimal proposal,  K = 25   (bench/mrpt_optimal_k25.ini)
and measures, from outside, the wall time and the peak RSS of the process (os.wait4 rusage), and
the ATE of the estimated path against the ground truth ("t x y phi" per line, LOG.rawlog.GT.txt or
LOG.GT.txt):
association by timestamp (nearest within 0.05 s), best rigid 2-D alignment without scale
(Umeyama/Kabsch), RMSE of the positions -- the same method for every method.

MRPT's path (--mrpt-path) is by default its log_estimated_path.txt: the particles' mean pose after
every rawlog entry, with the scan timestamp; or the most likely particle's path, rebuilt like ours.
Ours is trajectory.tum: the best particle's path, one pose per scan.
Run i (1..N) uses seed i for every method; the table reports medians.

Standard library only; run with /usr/bin/python3.  See --help.
"""

import argparse
import bisect
import datetime
import json
import math
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DEFAULT_DATA_DIR = "/usr/share/mrpt/datasets/graphslam-engine-demos/action_observations_map"
DEFAULT_LOGS = ["simul", "range_030_bearing_015"]
DEFAULT_OFFLINE = os.path.join(REPO, ".ws", "devel", "lib", "evidential_slam",
                               "evidential_slam_offline")
ATE_MAX_DT = 0.05  # s, same window as the runner's --ground-truth ATE

MRPT_METHODS = [
    # (name, K, ini file)
    ("mrpt-standard", 100, os.path.join(HERE, "mrpt_standard_k100.ini")),
    ("mrpt-optimal", 25, os.path.join(HERE, "mrpt_optimal_k25.ini")),
]


# ------------------------------------------------------------------------------------------------
# Trajectories and ATE
# ------------------------------------------------------------------------------------------------

def _data_lines(path):
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and line[0] not in "#%":
                yield line.split()


def read_ground_truth(path):
    """`t x y phi` per line -> [(t, x, y)] sorted by t."""
    return sorted((float(v[0]), float(v[1]), float(v[2])) for v in _data_lines(path))


def read_tum(path):
    """TUM `t x y z qx qy qz qw` -> [(t, x, y)]."""
    return [(float(v[0]), float(v[1]), float(v[2])) for v in _data_lines(path)]


def read_mrpt_estimated_path(path):
    """rbpf-slam's log_estimated_path.txt: `step x y z yaw pitch roll timestamp` -> [(t, x, y)]."""
    out = []
    for v in _data_lines(path):
        if len(v) < 8:
            raise ValueError("%s: expected 8 columns (MRPT >= 2.x writes a timestamp), got %d"
                             % (path, len(v)))
        out.append((float(v[7]), float(v[1]), float(v[2])))
    return out


def read_mrpt_best_particle_path(log_dir):
    """MRPT's most likely particle's path as one pose per rawlog entry, like our trajectory.tum:
    most_likely_path.txt holds that particle's pose at every filter update (`x y yaw`, after an
    initial pose), the updates being the steps marked in log_times.txt; between updates the pose
    is the last update composed with the odometry since then (log_odometry_path.txt).
    Returns [(t, x, y)], or None when the files do not line up."""
    steps = [(int(v[0]), v[3] == "1") for v in _data_lines(os.path.join(log_dir, "log_times.txt"))]
    ml = [tuple(map(float, v[:3])) for v in _data_lines(os.path.join(log_dir,
                                                                     "most_likely_path.txt"))]
    odo = {int(v[0]): (float(v[1]), float(v[2]), float(v[4]))
           for v in _data_lines(os.path.join(log_dir, "log_odometry_path.txt"))}
    stamps = {int(v[0]): float(v[7])
              for v in _data_lines(os.path.join(log_dir, "log_estimated_path.txt"))}
    updates = [step for step, inserted in steps if inserted]
    if len(ml) != len(updates) + 1 or not updates or updates[0] != 0:
        return None
    out = []
    k = -1
    for step, inserted in steps:
        if inserted:
            k += 1
        if step not in odo or step not in stamps:
            return None
        bx, by, bth = ml[k + 1]
        ox, oy, oth = odo[updates[k]]
        sx, sy, sth = odo[step]
        # relative odometry in the frame of the update's odometry pose, applied to the ML pose
        c, s_ = math.cos(oth), math.sin(oth)
        dx, dy = c * (sx - ox) + s_ * (sy - oy), -s_ * (sx - ox) + c * (sy - oy)
        c, s_ = math.cos(bth), math.sin(bth)
        out.append((stamps[step], bx + c * dx - s_ * dy, by + s_ * dx + c * dy))
    return out


def associate(estimate, truth, max_dt=ATE_MAX_DT):
    """Pairs each estimated pose with the ground-truth pose nearest in time (within max_dt)."""
    times = [g[0] for g in truth]
    pairs = []
    for t, x, y in estimate:
        i = bisect.bisect_left(times, t)
        best = None
        for j in (i - 1, i):
            if 0 <= j < len(times) and abs(times[j] - t) <= max_dt:
                if best is None or abs(times[j] - t) < abs(times[best] - t):
                    best = j
        if best is not None:
            pairs.append(((x, y), (truth[best][1], truth[best][2])))
    return pairs


def ate_rmse(estimate, truth, max_dt=ATE_MAX_DT):
    """(rmse_m, matched): rigid 2-D alignment (rotation + translation, no scale) of the estimate
    onto the truth minimising the squared position error, then the RMSE. None if < 2 pairs."""
    pairs = associate(estimate, truth, max_dt)
    n = len(pairs)
    if n < 2:
        return None, n
    mpx = sum(p[0] for p, _ in pairs) / n
    mpy = sum(p[1] for p, _ in pairs) / n
    mqx = sum(q[0] for _, q in pairs) / n
    mqy = sum(q[1] for _, q in pairs) / n
    dot = cross = 0.0
    for (px, py), (qx, qy) in pairs:
        ax, ay, bx, by = px - mpx, py - mpy, qx - mqx, qy - mqy
        dot += ax * bx + ay * by
        cross += ax * by - ay * bx
    th = math.atan2(cross, dot)
    c, s = math.cos(th), math.sin(th)
    sq = 0.0
    for (px, py), (qx, qy) in pairs:
        ax, ay = px - mpx, py - mpy
        rx = c * ax - s * ay + mqx
        ry = s * ax + c * ay + mqy
        sq += (rx - qx) ** 2 + (ry - qy) ** 2
    return math.sqrt(sq / n), n


# ------------------------------------------------------------------------------------------------
# Running and measuring a process
# ------------------------------------------------------------------------------------------------

def measured_run(cmd, run_dir, env=None):
    """Runs cmd (stdin /dev/null, stdout/stderr to files in run_dir). Returns a dict with rc,
    wall time, CPU time and peak RSS of the child (os.wait4 rusage)."""
    os.makedirs(run_dir, exist_ok=True)
    with open(os.path.join(run_dir, "stdout.txt"), "wb") as out, \
            open(os.path.join(run_dir, "stderr.txt"), "wb") as err, \
            open(os.devnull, "rb") as devnull:
        t0 = time.monotonic()
        proc = subprocess.Popen(cmd, stdin=devnull, stdout=out, stderr=err, env=env)
        _, status, ru = os.wait4(proc.pid, 0)
        wall = time.monotonic() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    return {
        "cmd": cmd,
        "rc": proc.returncode,
        "wall_time_s": wall,
        "cpu_time_s": ru.ru_utime + ru.ru_stime,
        "peak_rss_mb": ru.ru_maxrss / 1024.0,  # Linux: KiB
    }


def tail(path, n=5):
    """The MRPT exception's `Message:` line if there is one, else the last n lines."""
    try:
        with open(path, errors="replace") as f:
            lines = f.readlines()
    except OSError:
        return ""
    msg = [line.strip() for line in lines if line.strip().startswith("Message:")]
    return msg[-1] if msg else "".join(lines[-n:]).rstrip()


def mrpt_config(template, out_dir, seed, overrides):
    """The template's text with logOutput_dir, RANDOM_SEED and the KEY=VALUE overrides set."""
    with open(template) as f:
        lines = f.read().splitlines()
    settings = [("logOutput_dir", out_dir), ("RANDOM_SEED", str(seed))] + overrides
    for key, value in settings:
        pat = re.compile(r"^\s*" + re.escape(key) + r"\s*=")
        hits = [i for i, line in enumerate(lines) if pat.match(line)]
        if hits:
            for i in hits:
                lines[i] = "%s = %s" % (key, value)
        else:  # not in the template: add it to [MappingApplication]
            i = next(i for i, line in enumerate(lines) if line.strip() == "[MappingApplication]")
            lines.insert(i + 1, "%s = %s" % (key, value))
    return "\n".join(lines) + "\n"


def run_mrpt(name, template, rawlog, gt, run_dir, seed, overrides, rbpf, path_kind):
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    os.makedirs(run_dir)
    log_dir = os.path.join(run_dir, "rbpf")
    ini = os.path.join(run_dir, "config.ini")
    with open(ini, "w") as f:
        f.write(mrpt_config(template, log_dir, seed, overrides))
    r = measured_run([rbpf, ini, rawlog], run_dir)
    r.update(method=name, seed=seed)
    if r["rc"] != 0:
        r["error"] = "rbpf-slam exited with %s: %s" % (r["rc"],
                                                     tail(os.path.join(run_dir, "stderr.txt")))
        return r
    try:
        mean = read_mrpt_estimated_path(os.path.join(log_dir, "log_estimated_path.txt"))
    except (OSError, ValueError, IndexError) as e:
        r["error"] = "no usable log_estimated_path.txt: %s" % e
        return r
    try:
        best = read_mrpt_best_particle_path(log_dir)
    except (OSError, ValueError, IndexError):
        best = None
    if path_kind == "best-particle" and best is None:
        r["error"] = "cannot rebuild the most likely particle's path from %s" % log_dir
        return r
    est = best if path_kind == "best-particle" else mean
    r["poses"] = len(est)
    try:  # filter updates: the steps log_times.txt marks as inserted
        r["updates"] = sum(1 for v in _data_lines(os.path.join(log_dir, "log_times.txt"))
                           if v[3] == "1")
    except (OSError, IndexError):
        r["updates"] = None
    if gt:
        r["ate_m"], r["ate_matched"] = ate_rmse(est, gt)
        # Both path definitions, whichever the table uses.
        r["ate_mean_path_m"] = ate_rmse(mean, gt)[0]
        r["ate_best_particle_m"] = ate_rmse(best, gt)[0] if best else None
    return r


def ours_name(resolution):
    """Method label of our runner: 'ours' at its default resolution, 'ours-<res>m' otherwise."""
    return "ours" if resolution is None else "ours-%gm" % resolution


def run_ours(binary, rawlog, gt_path, gt, run_dir, seed, particles, threads, resolution=None,
             preset=None, params=(), profile=False):
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    out_dir = os.path.join(run_dir, "out")
    cmd = [binary, "--rawlog", rawlog, "--out", out_dir, "--particles", str(particles),
           "--seed", str(seed), "--quiet"]
    if gt_path:
        cmd += ["--ground-truth", gt_path]
    if threads is not None:
        cmd += ["--threads", str(threads)]
    if resolution is not None:
        cmd += ["--resolution", str(resolution)]
    if preset is not None:
        cmd += ["--preset", preset]
    for kv in params:
        cmd += ["--param", kv]
    if profile:
        cmd += ["--profile"]
    r = measured_run(cmd, run_dir)
    r.update(method=ours_name(resolution), seed=seed)
    if r["rc"] != 0:
        r["error"] = "evidential_slam_offline exited with %s: %s" % (
            r["rc"], tail(os.path.join(run_dir, "stderr.txt")))
        return r
    try:
        with open(os.path.join(out_dir, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        r["error"] = "no readable summary.json: %s" % e
        return r
    # The runner's own numbers, next to the ones measured from outside.
    r["internal_wall_time_s"] = summary.get("wall_time_s")
    r["internal_peak_rss_mb"] = summary.get("peak_rss_mb")
    r["internal_ate_m"] = summary.get("ate_rmse_m")
    r["threads"] = summary.get("threads")
    # Filter updates: every processed scan after the first (which initialises the particles).
    r["updates"] = max(0, summary.get("scans_processed", 0) - 1)
    r["groups_per_update"] = summary.get("groups_per_update")
    if profile:
        try:
            with open(os.path.join(out_dir, "profile.txt")) as f:
                r["profile"] = f.read()
        except OSError:
            r["profile"] = None
    est = read_tum(os.path.join(out_dir, "trajectory.tum"))
    r["poses"] = len(est)
    if gt:
        r["ate_m"], r["ate_matched"] = ate_rmse(est, gt)
        if r["internal_ate_m"] is not None and r["ate_m"] is not None \
                and abs(r["internal_ate_m"] - r["ate_m"]) > 1e-3 + 1e-3 * r["ate_m"]:
            r["warning"] = "runner ATE %.4f m differs from the benchmark's %.4f m" % (
                r["internal_ate_m"], r["ate_m"])
    return r


# ------------------------------------------------------------------------------------------------
# Report
# ------------------------------------------------------------------------------------------------

def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def fmt(v, digits):
    return "n/a" if v is None else "%.*f" % (digits, v)


def ratio(a, b):
    return None if a is None or b in (None, 0) else a / b


def summarise(results, durations):
    rows = []
    for log, methods in results.items():
        for method, info in methods.items():
            ok = [r for r in info["runs"] if "error" not in r]
            wall = median([r["wall_time_s"] for r in ok])
            rows.append({
                "duration_s": durations.get(log),
                "speed_x": ratio(durations.get(log), wall),
                "log": log, "method": method, "K": info["K"],
                "runs_ok": len(ok), "runs": len(info["runs"]),
                "wall_time_s": median([r["wall_time_s"] for r in ok]),
                "cpu_time_s": median([r["cpu_time_s"] for r in ok]),
                "peak_rss_mb": median([r["peak_rss_mb"] for r in ok]),
                "ate_m": median([r.get("ate_m") for r in ok]),
                "ate_m_min": min([r["ate_m"] for r in ok if r.get("ate_m") is not None],
                                 default=None),
                "ate_m_max": max([r["ate_m"] for r in ok if r.get("ate_m") is not None],
                                 default=None),
                "ate_mean_path_m": median([r.get("ate_mean_path_m") for r in ok]),
                "ate_best_particle_m": median([r.get("ate_best_particle_m") for r in ok]),
                "updates": median([r.get("updates") for r in ok]),
                # CPU time per particle and filter update, ms
                "cpu_ms_per_particle_update": median([
                    1e3 * r["cpu_time_s"] / (r["updates"] * info["K"]) for r in ok
                    if r.get("updates")]),
                "groups_per_update": median([r.get("groups_per_update") for r in ok]),
                "profile": next((r["profile"] for r in ok if r.get("profile")), None),
            })
    return rows


def markdown(rows, runs, mrpt_path):
    out = []
    out.append("Medians of %d run(s) (seeds 1..%d). Wall time and peak RSS measured from outside "
               "the process (os.wait4); x real time: the log's duration (span of its ground-truth "
               "stamps) over the wall time; ATE: timestamp association, rigid 2-D alignment, "
               "position RMSE. MRPT's path: %s." % (
                   runs, runs, "the particles' mean pose at every step" if mrpt_path == "mean"
                   else "the most likely particle's path"))
    out.append("")
    out.append("| log | method | K | wall time s | x real time | peak RSS MB | ATE m |")
    out.append("|---|---|---:|---:|---:|---:|---:|")
    for r in rows:
        note = "" if r["runs_ok"] == r["runs"] else " (%d/%d runs failed)" % (
            r["runs"] - r["runs_ok"], r["runs"])
        out.append("| %s | %s%s | %d | %s | %s | %s | %s |" % (
            r["log"], r["method"], note, r["K"], fmt(r["wall_time_s"], 1),
            fmt(r["speed_x"], 1), fmt(r["peak_rss_mb"], 0), fmt(r["ate_m"], 3)))
    by = {(r["log"], r["method"]): r for r in rows}
    logs = list(dict.fromkeys(r["log"] for r in rows))
    ratio_lines = []
    ours_methods = list(dict.fromkeys(r["method"] for r in rows if r["method"].startswith("ours")))
    for log in logs:
        for name in ours_methods:
            ours = by.get((log, name))
            if not ours:
                continue
            for ref in ("mrpt-standard", "mrpt-optimal"):
                m = by.get((log, ref))
                if not m:
                    continue
                ratio_lines.append("| %s | %s / %s | %s | %s | %s |" % (
                    log, name, ref,
                    fmt(ratio(ours["wall_time_s"], m["wall_time_s"]), 2),
                    fmt(ratio(ours["peak_rss_mb"], m["peak_rss_mb"]), 2),
                    fmt(ratio(ours["ate_m"], m["ate_m"]), 2)))
    if ratio_lines:
        out.append("")
        out.append("| log | ratio | wall time | peak RSS | ATE |")
        out.append("|---|---|---:|---:|---:|")
        out.extend(ratio_lines)
    out.append("")
    out.append("CPU time (user + system, median; less sensitive to a busy machine than wall "
               "time) and the ATE range over the runs:")
    out.append("")
    for r in rows:
        extra = ""
        if r.get("ate_best_particle_m") is not None:
            extra = "; median ATE of the mean path %s m, of the most likely particle's path %s m" \
                % (fmt(r["ate_mean_path_m"], 3), fmt(r["ate_best_particle_m"], 3))
        per_update = ""
        if r.get("cpu_ms_per_particle_update") is not None:
            per_update = ", %s ms per particle-update (%s updates%s)" % (
                fmt(r["cpu_ms_per_particle_update"], 2), fmt(r["updates"], 0),
                "" if r.get("groups_per_update") is None
                else ", %s groups per update" % fmt(r["groups_per_update"], 1))
        out.append("- %s / %s: CPU %s s%s, ATE %s .. %s m%s" % (
            r["log"], r["method"], fmt(r["cpu_time_s"], 1), per_update, fmt(r["ate_m_min"], 3),
            fmt(r["ate_m_max"], 3), extra))
    for r in rows:
        if r.get("profile"):
            out.append("")
            out.append("Profile of %s / %s (the first run; `--profile`):" % (r["log"], r["method"]))
            out.append("")
            out.append("```")
            out.extend(r["profile"].rstrip("\n").split("\n"))
            out.append("```")
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------------------------------------

def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Runs evidential_slam_offline and MRPT's rbpf-slam (standard proposal K=100, "
                    "optimal proposal K=25) on the same logs and compares wall time, peak RSS "
                    "and ATE.")
    p.add_argument("--runs", type=int, default=1, help="runs per log and method (seeds 1..N); "
                   "the table shows medians (default 1)")
    p.add_argument("--logs", default=",".join(DEFAULT_LOGS),
                   help="comma-separated log names (NAME.rawlog in --data-dir) or paths to "
                        ".rawlog files; ground truth is LOG.rawlog.GT.txt or LOG.GT.txt when "
                        "present; MRPT reads LOG.sf.rawlog when present (default %(default)s)")
    p.add_argument("--data-dir", default=DEFAULT_DATA_DIR,
                   help="directory of the logs (default %(default)s)")
    only = p.add_mutually_exclusive_group()
    only.add_argument("--ours-only", action="store_true", help="run only evidential_slam")
    only.add_argument("--mrpt-only", action="store_true", help="run only rbpf-slam")
    p.add_argument("--out", default=os.path.join(REPO, "out", "benchmark"),
                   help="output directory: results.json, results.md, runs/ "
                        "(default %(default)s)")
    p.add_argument("--particles", type=int, default=100, help="our particle count (default 100)")
    p.add_argument("--resolutions", dest="resolutions_text", default="", metavar="LIST",
                   help="comma-separated grid resolutions (m) to run ours at, each its own row, "
                        "e.g. 'default,0.1' (default: the runner's default only)")
    p.add_argument("--preset", default=None, metavar="NAME",
                   help="our --preset NAME (config/NAME.yaml), e.g. 'sim' for MRPT's simulated "
                        "logs (default: none, the runner's defaults)")
    p.add_argument("--threads", type=int, default=None,
                   help="our --threads (default: the runner's default, all cores)")
    p.add_argument("--offline", default=DEFAULT_OFFLINE,
                   help="evidential_slam_offline binary (default: the workspace built by "
                        "scripts/setup)")
    p.add_argument("--rbpf-slam", default=shutil.which("rbpf-slam", path="/usr/bin:" +
                                                       os.environ.get("PATH", "")),
                   help="rbpf-slam binary (default: from PATH)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="set one of our SLAM parameters by its ROS name (repeatable; passed to "
                        "evidential_slam_offline --param), e.g. resample_threshold=0.3")
    p.add_argument("--mrpt-set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a key in both MRPT configs (repeatable), e.g. "
                        "enableLikelihoodCache=0")
    p.add_argument("--profile", action="store_true",
                   help="run ours with --profile: the update's time by section, ns per visited "
                        "cell and the compute floor, in results.md (slower, more memory)")
    p.add_argument("--mrpt-path", choices=["mean", "best-particle"], default="mean",
                   help="MRPT path for the table's ATE: 'mean' = log_estimated_path.txt, the "
                        "particles' mean pose after every step; 'best-particle' = the most likely "
                        "particle's path (as our trajectory.tum) with odometry between filter "
                        "updates. Both are saved in results.json (default %(default)s)")
    a = p.parse_args(argv)
    if a.runs < 1:
        p.error("--runs must be >= 1")
    a.overrides = []
    for kv in a.mrpt_set:
        if "=" not in kv:
            p.error("--mrpt-set wants KEY=VALUE, got %r" % kv)
        k, v = kv.split("=", 1)
        a.overrides.append((k.strip(), v.strip()))
    a.resolutions = []
    for item in (a.resolutions_text or "default").split(","):
        item = item.strip()
        if item in ("", "default"):
            a.resolutions.append(None)
            continue
        try:
            a.resolutions.append(float(item))
        except ValueError:
            p.error("--resolutions wants numbers or 'default', got %r" % item)
    return a


def resolve_log(name, data_dir):
    if os.path.sep in name or name.endswith(".rawlog"):
        path = name if os.path.isabs(name) or os.path.exists(name) else \
            os.path.join(data_dir, name)
    else:
        path = os.path.join(data_dir, name + ".rawlog")
    label = os.path.basename(path)
    if label.endswith(".rawlog"):
        label = label[:-len(".rawlog")]
    # Ground truth: LOG.rawlog.GT.txt (MRPT's datasets) or LOG.GT.txt (the Radish logs).
    gt = next((g for g in (path + ".GT.txt", path[:-len(".rawlog")] + ".GT.txt")
               if path.endswith(".rawlog") and os.path.exists(g)), None)
    # rbpf-slam crashes on observation-only rawlogs: it reads LOG.sf.rawlog (the same data as
    # actions + sensory frames) when there is one.
    sf = path[:-len(".rawlog")] + ".sf.rawlog" if path.endswith(".rawlog") else None
    mrpt_rawlog = os.path.abspath(sf) if sf and os.path.exists(sf) else os.path.abspath(path)
    return (label, os.path.abspath(path), (os.path.abspath(gt) if gt else None),
            mrpt_rawlog)


def log_duration(gt):
    """The log's real duration (s): the span of its ground-truth stamps (one per scan)."""
    return gt[-1][0] - gt[0][0] if gt and len(gt) > 1 else None


def main(argv):
    a = parse_args(argv)
    logs = [resolve_log(n.strip(), a.data_dir) for n in a.logs.split(",") if n.strip()]
    missing = [p for _, p, _, _ in logs if not os.path.isfile(p)]
    if missing:
        sys.exit("benchmark: log not found: %s" % ", ".join(missing))
    run_ours_ = not a.mrpt_only
    run_mrpt_ = not a.ours_only
    if run_ours_ and not os.access(a.offline, os.X_OK):
        sys.exit("benchmark: %s not found or not executable; build it first with scripts/setup "
                 "(or pass --offline, or --mrpt-only)" % a.offline)
    if run_mrpt_ and not (a.rbpf_slam and os.access(a.rbpf_slam, os.X_OK)):
        sys.exit("benchmark: rbpf-slam not found (Debian package mrpt-apps); or pass --mrpt-only "
                 "/ --ours-only / --rbpf-slam")

    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    methods = []
    if run_ours_:
        for res in a.resolutions:
            methods.append((ours_name(res), a.particles, res))
    if run_mrpt_:
        methods.extend(MRPT_METHODS)

    results = {label: {m: {"K": k, "runs": []} for m, k, _ in methods} for label, _, _, _ in logs}
    gts = {label: (read_ground_truth(gt) if gt else None) for label, _, gt, _ in logs}
    durations = {label: log_duration(gts[label]) for label in gts}
    failures = 0
    for run in range(1, a.runs + 1):
        for label, rawlog, gt_path, mrpt_rawlog in logs:
            gt = gts[label]
            for method, k, ini in methods:
                run_dir = os.path.join(out, "runs", label, method, "run%d" % run)
                print("[benchmark] run %d/%d  %-22s %-14s K=%-3d ..." % (
                    run, a.runs, label, method, k), end="", flush=True)
                if method.startswith("ours"):
                    r = run_ours(a.offline, rawlog, gt_path, gt, run_dir, run, k, a.threads, ini,
                                 a.preset, a.param, a.profile)
                else:
                    r = run_mrpt(method, ini, mrpt_rawlog, gt, run_dir, run, a.overrides,
                                 a.rbpf_slam, a.mrpt_path)
                results[label][method]["runs"].append(r)
                if "error" in r:
                    failures += 1
                    print(" FAILED\n    %s" % r["error"].replace("\n", "\n    "), flush=True)
                else:
                    print(" %6.1f s %6.0f MB  ATE %s m" % (
                        r["wall_time_s"], r["peak_rss_mb"], fmt(r.get("ate_m"), 3)), flush=True)
                    if "warning" in r:
                        print("    warning: " + r["warning"], flush=True)

    rows = summarise(results, durations)
    md = markdown(rows, a.runs, a.mrpt_path)
    record = {
        "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "host": {"machine": platform.machine(), "cpus": os.cpu_count(),
                 "kernel": platform.release()},
        "runs": a.runs,
        "ate": {"association_max_dt_s": ATE_MAX_DT, "alignment": "SE(2), no scale",
                "mrpt_path": a.mrpt_path,
                "ours_path": "trajectory.tum"},
        "mrpt_overrides": dict(a.overrides),
        "ours_preset": a.preset,
        "ours_params": list(a.param),
        "logs": {label: {"rawlog": p, "mrpt_rawlog": m, "ground_truth": g,
                         "duration_s": durations[label]} for label, p, g, m in logs},
        "summary": rows,
        "results": results,
    }
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(record, f, indent=2)
    with open(os.path.join(out, "results.md"), "w") as f:
        f.write(md)
    print()
    print(md, end="")
    print("\n[benchmark] wrote %s and %s" % (os.path.join(out, "results.md"),
                                             os.path.join(out, "results.json")))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
