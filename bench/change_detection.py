#!/usr/bin/python3
"""Benchmark: what-changed and kidnap detection on generated scenarios (issue 52).

Draws --runs scenarios from one seed (printed; fresh each run unless --seed is given) with
bench/scenarios.py — office, corridor and loop worlds; clean runs, kidnaps (0.3-3 m, 0-90 deg, at
a random time on the way back) and runs with objects (people crossing, a box parked then removed,
a door opening or closing) — simulates each (evidential_slam_simulate --objects --truth-scans),
maps it (evidential_slam_offline, defaults, K = --particles) and feeds the probabilistic peer
(evidential_slam_logodds_baseline: OctoMap's clamped log-odds grid, the same scans at our poses).

Scores, with the issue's definitions, after aligning the SLAM frame to the truth on the poses
before the first event:
  ordinary wall cells  held as hit (m(o) + m(0) >= 0.5) within 0.1 m of a true wall and hit by a
                       true beam before any event;
  ghost cells          endpoints of the true ranges cast from the filter's own pose on processed
                       scans while it is lost (> 0.15 m or 3 deg off), more than 0.15 m from every
                       true wall, in space true beams had crossed before the kidnap;
  moved-object cells   endpoints of beams that ended on an object (from the filter's pose), in
                       space crossed before the object came or after it left;
  cell value           the largest value of the layer in the cell's 3 x 3 neighbourhood;
  AUC                  per-cell ROC AUC, positives against the ordinary walls of the same runs,
                       pooled over the runs: anomaly, EC and the peer's sum of |delta log-odds|
                       over the updates that flipped a cell;
  alarm                a kidnap (>= 0.5 m) that leaves the filter lost (> 0.15 m or 3 deg off at
                       the 20th processed scan after it) is detected when the alarm fires within
                       20 processed scans of it; false alarms are rising alarms on clean runs and
                       before the first event of the others, per hour of that driving. The peer's
                       alarm is the same detector (factor 4 over the largest of the last 50 quiet
                       scans, at least 5, 2 scans in a row, none before the window holds 50 scans)
                       on the number of cells a scan flips.
  /usr/bin/python3 bench/change_detection.py [--runs 50] [--seed S] [--smoke]
"""

import argparse
import functools
import json
import math
import multiprocessing
import os
import random
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import scenarios as S  # noqa: E402
import smoke_check  # noqa: E402

REPO = os.path.dirname(HERE)
BIN = os.path.join(REPO, ".ws", "devel", "lib", "evidential_slam")
LOST_M, LOST_RAD = 0.15, math.radians(3.0)
DETECT_SCANS = 20
KINDS = ["clean", "kidnap", "objects"]


def run(cmd, log):
    with open(log, "w") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n  see {log}")


def read_npy(path):
    return np.load(path)


class Grid:
    """A saved map's layers and geometry (layers/map.yaml)."""

    def __init__(self, out_dir):
        d = os.path.join(out_dir, "layers")
        meta = open(os.path.join(d, "map.yaml")).read()
        o = re.search(r"origin: \[([-\d.e]+), ([-\d.e]+)", meta)
        self.x0, self.y0 = float(o.group(1)), float(o.group(2))
        self.res = float(re.search(r"resolution: ([\d.]+)", meta).group(1))
        self.layers = {n: read_npy(os.path.join(d, n + ".npy"))
                       for n in ("occupied", "conflict", "anomaly", "external_conflict")}
        self.h, self.w = self.layers["occupied"].shape

    def cells(self, x, y):
        """Flat indices of points (slam frame) and a mask of those inside the grid."""
        c = np.floor((np.asarray(x) - self.x0) / self.res).astype(np.int64)
        r = np.floor((np.asarray(y) - self.y0) / self.res).astype(np.int64)
        ok = (c >= 0) & (c < self.w) & (r >= 0) & (r < self.h)
        return r * self.w + c, ok

    def mask(self, x, y):
        m = np.zeros(self.h * self.w, dtype=bool)
        idx, ok = self.cells(x, y)
        m[idx[ok]] = True
        return m.reshape(self.h, self.w)


def read_flip_grid(path, grid):
    with open(path) as f:
        x0, y0, res, w, h = f.readline().split()
        a = np.loadtxt(f, dtype=np.float32, ndmin=2)
    assert int(w) == grid.w and int(h) == grid.h, "peer grid does not match the map"
    return a


def dilate(mask, radius):
    """True within `radius` cells (Euclidean) of a True cell."""
    out = mask.copy()
    h, w = mask.shape
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            if (dx or dy) and dx * dx + dy * dy <= radius * radius:
                out[max(0, dy):h + min(0, dy), max(0, dx):w + min(0, dx)] |= \
                    mask[max(0, -dy):h + min(0, -dy), max(0, -dx):w + min(0, -dx)]
    return out


def max3(a):
    out = a.copy()
    h, w = a.shape
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dx or dy:
                np.maximum(out[max(0, dy):h + min(0, dy), max(0, dx):w + min(0, dx)],
                           a[max(0, -dy):h + min(0, -dy), max(0, -dx):w + min(0, -dx)],
                           out=out[max(0, dy):h + min(0, dy), max(0, dx):w + min(0, dx)])
    return out


def auc(pos, neg):
    """ROC AUC of pos against neg (ties count one half; NaN values left out); None without both."""
    pos, neg = np.asarray(pos, dtype=np.float64), np.asarray(neg, dtype=np.float64)
    pos, neg = pos[~np.isnan(pos)], neg[~np.isnan(neg)]
    if len(pos) == 0 or len(neg) == 0:
        return None
    allv = np.concatenate([pos, neg])
    _, inv, counts = np.unique(allv, return_inverse=True, return_counts=True)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    ranks = (start + (counts + 1) / 2.0)[inv]
    r_pos = ranks[:len(pos)].sum()
    return float((r_pos - len(pos) * (len(pos) + 1) / 2.0) / (len(pos) * len(neg)))


class Align:
    """Rigid transform world -> slam frame: the best fit of trajectory to truth on [t_lo, t_hi)."""

    def __init__(self, est, gt, t_hi):
        sel = [(e, g) for e, g in zip(est, gt) if e[0] < t_hi]
        E = np.array([[e[1], e[2]] for e, _ in sel])
        G = np.array([[g[1], g[2]] for _, g in sel])
        me, mg = E.mean(0), G.mean(0)
        a, b = G - mg, E - me
        sxx = (a * b).sum()
        sxy = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()
        self.angle = math.atan2(sxy, sxx)
        c, s = math.cos(self.angle), math.sin(self.angle)
        self.R = np.array([[c, -s], [s, c]])
        self.t = me - self.R @ mg

    def points(self, x, y):
        p = self.R @ np.vstack([np.ravel(x), np.ravel(y)]) + self.t[:, None]
        return p[0], p[1]

    def pose(self, x, y, th):
        px_, py_ = self.points([x], [y])
        return px_[0], py_[0], th + self.angle


def read_tum(path):
    out = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                v = [float(x) for x in line.split()]
                out.append((v[0], v[1], v[2], 2.0 * math.atan2(v[6], v[7])))
    return out


def read_conflict(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or line.startswith("stamp"):
                continue
            v = line.strip().split(",")
            rows.append((float(v[0]), float(v[3]), int(v[6])))
    return rows


def read_peer_scans(path):
    rows = []
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                t, s, n = line.split()
                rows.append((float(t), float(s), int(n)))
    return rows


def peer_alarm(values, factor=4.0, floor=5.0, window=50, warmup=50, confirm=2):
    """conflict_alarm.cpp's detector (its defaults) on a series: per scan, alarm yes/no."""
    base, out, above = [], [], 0
    for v in values:
        b = max(base) if base else 0.0
        a = len(base) >= min(warmup, window) and v > floor and v > factor * b
        above = above + 1 if a else 0
        out.append(above >= confirm)
        if not a:
            base.append(v)
            base = base[-window:]
    return out


def endpoints(poses, laser, ranges, keep):
    """World/slam endpoints of rays `keep` (N, n bool) of scans at `poses` (N, 3)."""
    n = ranges.shape[1]
    bearings = -0.5 * math.pi + math.pi * np.arange(n) / (n - 1)
    sx = poses[:, 0] + laser[0] * np.cos(poses[:, 2]) - laser[1] * np.sin(poses[:, 2])
    sy = poses[:, 1] + laser[0] * np.sin(poses[:, 2]) + laser[1] * np.cos(poses[:, 2])
    a = poses[:, 2:3] + laser[2] + bearings[None, :]
    ex = sx[:, None] + ranges * np.cos(a)
    ey = sy[:, None] + ranges * np.sin(a)
    return ex[keep], ey[keep]


def free_times(grid, align, stamps, poses, laser, ranges, objects, every=3, step=0.04):
    """First and last stamp at which a true beam crossed each cell (slam frame; inf / -inf)."""
    first = np.full(grid.h * grid.w, np.inf)
    last = np.full(grid.h * grid.w, -np.inf)
    n = ranges.shape[1]
    bearings = -0.5 * math.pi + math.pi * np.arange(n) / (n - 1)
    for j in range(0, len(stamps), every):
        x, y, th = poses[j]
        sx = x + laser[0] * math.cos(th) - laser[1] * math.sin(th)
        sy = y + laser[0] * math.sin(th) + laser[1] * math.cos(th)
        r = ranges[j]
        ok = r > 0.15
        if not ok.any():
            continue
        a = th + laser[2] + bearings[ok]
        rr = r[ok] - 0.1
        ts = np.arange(0.0, rr.max(), step)
        m = ts[None, :] < rr[:, None]
        px_ = (sx + ts[None, :] * np.cos(a)[:, None])[m]
        py_ = (sy + ts[None, :] * np.sin(a)[:, None])[m]
        qx, qy = align.points(px_, py_)
        idx, inside = grid.cells(qx, qy)
        idx = np.unique(idx[inside])
        t = stamps[j]
        first[idx] = np.minimum(first[idx], t)
        last[idx] = t
    return first.reshape(grid.h, grid.w), last.reshape(grid.h, grid.w)


def score_run(sc, work, out, peer_flip, peer_scans):
    """Cells and alarm outcomes of one scenario."""
    stamps, gt_poses, laser, ranges, objects = S.read_truth_scans(sc["truth"])
    est = read_tum(os.path.join(out, "trajectory.tum"))
    gt = [(t, p[0], p[1], p[2]) for t, p in zip(stamps, gt_poses)]
    assert len(est) == len(gt), "trajectory and truth differ in length"
    t_event = sc["t_event"]
    align = Align(est, gt, t_event)
    grid = Grid(out)
    est_by_t = {round(e[0], 3): e for e in est}
    idx_by_t = {round(t, 3): j for j, t in enumerate(stamps)}
    conflict = read_conflict(os.path.join(out, "conflict.csv"))
    processed = [round(r[0], 3) for r in conflict]

    # True walls in the slam frame.
    wy, wx = np.nonzero(sc["world"].occ)
    qx, qy = align.points((wx + 0.5) * S.RES, (wy + 0.5) * S.RES)
    wall = grid.mask(qx, qy)
    near01, near015 = dilate(wall, 2), dilate(wall, 3)
    hit = (grid.layers["occupied"] + grid.layers["conflict"]) >= 0.5
    before = stamps < t_event
    ex, ey = endpoints(gt_poses[before], laser, ranges[before],
                       (ranges[before] > 0) & (objects[before] < 0))
    qx, qy = align.points(ex, ey)
    walls = hit & near01 & grid.mask(qx, qy)
    first, last = free_times(grid, align, stamps, gt_poses, laser, ranges, objects)

    positive = np.zeros_like(walls)
    result = {"seed": sc["seed"], "world": sc["world_name"], "kind": sc["kind"]}
    if sc["kind"] == "kidnap":
        k = sc["kidnap"]
        after = [t for t in processed if t >= k["t"] - 1e-6]
        errs = []
        lost_scans = []
        for t in after:
            e = est_by_t[t]
            g = gt_poses[idx_by_t[t]]
            tx, ty, tth = align.pose(*g)
            d = math.hypot(e[1] - tx, e[2] - ty)
            da = abs(math.remainder(e[3] - tth, 2 * math.pi))
            errs.append((d, da))
            if d > LOST_M or da > LOST_RAD:
                lost_scans.append(idx_by_t[t])
        check = errs[min(DETECT_SCANS, len(errs)) - 1] if errs else (0.0, 0.0)
        result["kidnap_m"] = k["distance"]
        result["kidnap_deg"] = math.degrees(abs(k["dtheta"]))
        result["lost"] = check[0] > LOST_M or check[1] > LOST_RAD
        result["error_at_20"] = [round(check[0], 3), round(math.degrees(check[1]), 2)]
        if lost_scans:
            j = np.array(lost_scans)
            ep = np.array([[est_by_t[round(stamps[i], 3)][1], est_by_t[round(stamps[i], 3)][2],
                            est_by_t[round(stamps[i], 3)][3]] for i in j])
            ex, ey = endpoints(ep, laser, ranges[j], (ranges[j] > 0) & (objects[j] < 0))
            ghost = grid.mask(ex, ey) & ~near015 & (first < k["t"])
            positive |= ghost
        alarms = [r for r in conflict if r[0] >= k["t"] - 1e-6][:DETECT_SCANS]
        fired = [i for i, r in enumerate(alarms) if r[2]]
        result["delay_scans"] = fired[0] if fired else None
        result["delay_s"] = round(alarms[fired[0]][0] - k["t"], 2) if fired else None
        pa = peer_alarm([r[2] for r in peer_scans])
        pk = [a for r, a in zip(peer_scans, pa) if r[0] >= k["t"] - 1e-6][:DETECT_SCANS]
        pf = [i for i, a in enumerate(pk) if a]
        result["peer_delay_scans"] = pf[0] if pf else None
    elif sc["kind"] == "objects":
        for t in processed:
            j = idx_by_t[t]
            if not (objects[j] >= 0).any():
                continue
            e = est_by_t[t]
            for k in np.unique(objects[j][objects[j] >= 0]):
                o = sc["objects"][k]
                keep = (objects[j] == k)[None, :]
                ex, ey = endpoints(np.array([[e[1], e[2], e[3]]]), laser, ranges[j:j + 1], keep)
                m = grid.mask(ex, ey) & ((first < o["t0"]) | (last > o["t1"]))
                positive |= m
    walls &= ~positive
    np.savez_compressed(os.path.join(work, "cells.npz"), positive=positive, walls=walls,
                        first=first, last=last)
    values = {"anomaly": max3(grid.layers["anomaly"]),
              "ec": max3(grid.layers["external_conflict"]),
              "peer": max3(peer_flip)}
    result["pos"] = {n: v[positive].tolist() for n, v in values.items()}
    result["walls"] = {n: v[walls].tolist() for n, v in values.items()}
    # False alarms: rising alarms before the first event (all of a clean run).
    clean = [r for r in conflict if r[0] < t_event]
    rising = sum(1 for a, b in zip([0] + [r[2] for r in clean], [r[2] for r in clean])
                 if b and not a)
    pa = peer_alarm([r[2] for r in peer_scans])
    pclean = [a for r, a in zip(peer_scans, pa) if r[0] < t_event]
    prising = sum(1 for a, b in zip([False] + pclean, pclean) if b and not a)
    result["clean_s"] = (min(t_event, stamps[-1]) - stamps[0])
    result["false_alarms"] = rising
    result["false_alarm_stamps"] = [r[0] for i, r in enumerate(clean)
                                    if r[2] and (i == 0 or not clean[i - 1][2])]
    result["peer_false_alarms"] = prising
    result["ate"] = json.load(open(os.path.join(out, "summary.json")))["ate_rmse_m"]
    return result


def make_scenario(seed, kind, work, args):
    rng = random.Random(seed)
    world_name = rng.choice(sorted(S.WORLDS))
    world, out_wp, back_wp = S.WORLDS[world_name](rng)
    wp = out_wp + back_wp
    os.makedirs(work, exist_ok=True)
    png = os.path.join(work, "world.png")
    world.write_png(png)
    S.write_waypoints(os.path.join(work, "route.txt"), wp)
    base = [args.sim, "--map", png, "--resolution", str(S.RES), "--origin-x", "0", "--origin-y",
            "0", "--waypoints", os.path.join(work, "route.txt"), "--linear-speed",
            str(args.speed), "--seed", str(seed % 100000), "--quiet"]
    sc = {"seed": seed, "kind": kind, "world_name": world_name, "world": world,
          "kidnap": None, "objects": [], "t_event": float("inf")}
    if kind != "clean":
        dry = os.path.join(work, "dry.rawlog")
        run(base + ["--out", dry, "--truth-scans", dry + ".scans"], dry + ".log")
        stamps, poses, _, _, _ = S.read_truth_scans(dry + ".scans")
        kidnap, objects = S.draw_events(rng, kind, world, wp, len(out_wp), stamps, poses)
        if kind == "kidnap" and kidnap is None or kind == "objects" and not objects:
            return None
        sc["kidnap"], sc["objects"] = kidnap, objects
    cmd = list(base)
    if sc["kidnap"]:
        k = sc["kidnap"]
        cmd += ["--kidnap", "%.3f,%.3f,%.3f,%.4f" % (k["t"], k["dx"], k["dy"], k["dtheta"])]
        sc["t_event"] = k["t"]
    if sc["objects"]:
        S.write_objects(os.path.join(work, "objects.txt"), sc["objects"])
        cmd += ["--objects", os.path.join(work, "objects.txt")]
        # A change is when an object comes, or leaves when it was there from the start.
        sc["t_event"] = min(o["t0"] if o["t0"] > 1.0 else o["t1"] for o in sc["objects"])
    rawlog = os.path.join(work, "sim.rawlog")
    sc["truth"] = rawlog + ".scans"
    run(cmd + ["--out", rawlog, "--truth-scans", sc["truth"]], rawlog + ".log")
    sc["rawlog"] = rawlog
    return sc


def run_scenario(seed, kind, args):
    work = os.path.join(args.work, str(seed))
    sc = make_scenario(seed, kind, work, args)
    if sc is None:
        return None
    out = os.path.join(work, "slam")
    run(["nice", "-n", "10", args.offline, "--rawlog", sc["rawlog"], "--ground-truth",
         sc["rawlog"] + ".GT.txt", "--out", out, "--particles", str(args.particles), "--threads",
         "1", "--seed", str(seed % 100000), "--quiet"] + sum((["--param", p] for p in args.param),
                                                             []), out + ".log")
    grid = Grid(out)
    window = "%.6f,%.6f,%.6f,%.6f" % (grid.x0, grid.y0, grid.x0 + (grid.w - 0.5) * grid.res,
                                      grid.y0 + (grid.h - 0.5) * grid.res)
    peer = os.path.join(work, "peer")
    run(["nice", "-n", "10", args.peer, "--rawlog", sc["rawlog"], "--trajectory",
         os.path.join(out, "trajectory.tum"), "--stamps", os.path.join(out, "conflict.csv"),
         "--grid-out", peer + ".grid.txt", "--window", window, "--flip-out", peer + ".flip.txt",
         "--scan-out", peer + ".scans.txt"], peer + ".log")
    flip = read_flip_grid(peer + ".flip.txt", grid)
    r = score_run(sc, work, out, flip, read_peer_scans(peer + ".scans.txt"))
    r["objects"] = [o["kind"] for o in sc["objects"]]
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return r


def check(results, junit):
    """The smoke test's verdict (--check): every scenario scored with cells of both kinds, the
    anomaly layer above chance and above EC and the peer on both, every kidnap that left the
    filter lost detected, no false alarm. Writes a JUnit file when asked; True when all hold."""
    kinds = {k: [r for r in results if r["kind"] == k] for k in KINDS}
    failures = []

    def pooled(kind, layer, part):
        return sum((r[part][layer] for r in kinds[kind]), [])

    for kind in ("kidnap", "objects"):
        if not pooled(kind, "anomaly", "pos") or not pooled(kind, "anomaly", "walls"):
            failures.append(f"no {kind} cells to score")
            continue
        a = {n: auc(pooled(kind, n, "pos"), pooled(kind, n, "walls"))
             for n in ("anomaly", "ec", "peer")}
        if not (a["anomaly"] >= 0.8 and a["anomaly"] > a["ec"] and a["anomaly"] > a["peer"]):
            failures.append(f"{kind}: AUC anomaly {a['anomaly']:.3f}, EC {a['ec']:.3f}, "
                            f"peer {a['peer']:.3f}")
    for r in kinds["kidnap"]:
        if r["kidnap_m"] >= 0.5 and r["lost"] and r["delay_scans"] is None:
            failures.append(f"kidnap of scenario {r['seed']} not detected")
    for r in results:
        if r["false_alarms"]:
            failures.append(f"{r['false_alarms']} false alarm(s) in scenario {r['seed']}")
    return smoke_check.report(failures, junit, "change_detection")


def run_task(task, args):
    return run_scenario(task[0], task[1], args)


def fmt(v, spec="%.3f"):
    return "—" if v is None else spec % v


def summarize(results, args, seed):
    print(f"\n### Change detection, {len(results)} generated scenarios, seed {seed}\n")
    kinds = {k: [r for r in results if r["kind"] == k] for k in KINDS}
    print("scenarios: " + ", ".join(f"{len(v)} {k}" for k, v in kinds.items()) +
          "; worlds: " + ", ".join(f"{sum(r['world'] == w for r in results)} {w}"
                                  for w in sorted(S.WORLDS)))
    print("\n| cells | n pos / walls | AUC anomaly | AUC EC | AUC log-odds peer | median anomaly "
          "pos / walls | median EC pos / walls |")
    print("|---|---|---|---|---|---|---|")
    for kind, label in (("kidnap", "ghost vs walls"), ("objects", "moved object vs walls")):
        rs = kinds[kind]
        pos = {n: sum((r["pos"][n] for r in rs), []) for n in ("anomaly", "ec", "peer")}
        neg = {n: sum((r["walls"][n] for r in rs), []) for n in ("anomaly", "ec", "peer")}
        med = {n: (float(np.nanmedian(pos[n])) if pos[n] else None,
                   float(np.nanmedian(neg[n])) if neg[n] else None) for n in pos}
        nans = sum(int(np.isnan(np.asarray(pos[n] + neg[n], dtype=float)).sum()) for n in pos)
        if nans:
            print(f"({label}: {nans} cell values are NaN, left out)")
        print(f"| {label} | {len(pos['anomaly'])} / {len(neg['anomaly'])} | "
              f"{fmt(auc(pos['anomaly'], neg['anomaly']))} | {fmt(auc(pos['ec'], neg['ec']))} | "
              f"{fmt(auc(pos['peer'], neg['peer']))} | {fmt(med['anomaly'][0], '%.2f')} / "
              f"{fmt(med['anomaly'][1], '%.2f')} | {fmt(med['ec'][0], '%.2f')} / "
              f"{fmt(med['ec'][1], '%.2f')} |")
    ks = [r for r in kinds["kidnap"] if r["kidnap_m"] >= 0.5 and r["lost"]]
    hours = sum(r["clean_s"] for r in results) / 3600.0
    fa = sum(r["false_alarms"] for r in results)
    pfa = sum(r["peer_false_alarms"] for r in results)
    det = [r for r in ks if r["delay_scans"] is not None]
    pdet = [r for r in ks if r["peer_delay_scans"] is not None]
    print("\n| alarm | recall (kidnaps >= 0.5 m, filter lost) | median delay (scans / s) | "
          "false alarms (per hour of clean driving) |")
    print("|---|---|---|---|")
    print(f"| conflict alarm | {len(det)} / {len(ks)} | "
          f"{fmt(np.median([r['delay_scans'] for r in det]) if det else None, '%.0f')} / "
          f"{fmt(np.median([r['delay_s'] for r in det]) if det else None, '%.1f')} | "
          f"{fa} in {hours:.2f} h ({fa / hours if hours else 0:.1f}/h) |")
    print(f"| log-odds peer (flipped cells) | {len(pdet)} / {len(ks)} | "
          f"{fmt(np.median([r['peer_delay_scans'] for r in pdet]) if pdet else None, '%.0f')} "
          f"/ — | {pfa} in {hours:.2f} h ({pfa / hours if hours else 0:.1f}/h) |")
    recovered = [r for r in kinds["kidnap"] if not r["lost"]]
    print(f"\nkidnaps: {len(kinds['kidnap'])}, of which {len(recovered)} left the filter within "
          f"{LOST_M} m / 3 deg by the {DETECT_SCANS}th scan, "
          f"{sum(r['kidnap_m'] < 0.5 for r in kinds['kidnap'])} under 0.5 m; "
          f"ATE median {np.median([r['ate'] for r in results]):.3f} m")
    missed = [r for r in ks if r["delay_scans"] is None]
    for r in missed:
        print(f"  missed kidnap: scenario {r['seed']} ({r['world']}, {r['kidnap_m']:.2f} m, "
              f"{r['kidnap_deg']:.0f} deg, error at scan 20 {r['error_at_20']})")
    for r in results:
        if r["false_alarms"]:
            print(f"  false alarm(s): scenario {r['seed']} ({r['world']}, {r['kind']}) at "
                  f"{', '.join('%.1f s' % t for t in r['false_alarm_stamps'])}")
    print(f"\nrerun: /usr/bin/python3 bench/change_detection.py --runs {args.runs} --seed {seed}"
          f" --particles {args.particles}" + (" --smoke" if args.smoke else ""))


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=50, help="scenarios [50]")
    ap.add_argument("--seed", type=int, help="scenario set (default: fresh, printed)")
    ap.add_argument("--particles", type=int, default=30)
    ap.add_argument("--speed", type=float, default=0.6, help="m/s [0.6]")
    ap.add_argument("--smoke", action="store_true", help="6 scenarios at K = 10 (CI-sized)")
    ap.add_argument("--param", action="append", default=[], help="NAME=VALUE for the SLAM")
    ap.add_argument("--work", default="/tmp/change_detection", help="work directory")
    ap.add_argument("--bin", default=BIN, help="directory of the built programs")
    ap.add_argument("--keep", action="store_true", help="keep each scenario's files")
    ap.add_argument("--json", help="also write the per-scenario results here (after each one)")
    ap.add_argument("--jobs", type=int, default=1, help="scenarios run at once [1]")
    ap.add_argument("--summarize", help="only print the tables of a --json file")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 unless the smoke test's conditions hold (check())")
    ap.add_argument("--junit", help="with --check: write the verdict as a JUnit file")
    args = ap.parse_args()
    if args.summarize:
        with open(args.summarize) as f:
            saved = json.load(f)
        summarize(saved["results"], args, saved["seed"])
        return
    if args.smoke:
        args.runs, args.particles = min(args.runs, 6), min(args.particles, 10)
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(1, 10**6)
    print(f"seed {seed} (rerun: --seed {seed})", flush=True)
    args.sim = os.path.join(args.bin, "evidential_slam_simulate")
    args.offline = os.path.join(args.bin, "evidential_slam_offline")
    args.peer = os.path.join(args.bin, "evidential_slam_logodds_baseline")
    results = []
    t0 = time.time()
    # Scenario i is of kind i mod 3; one whose events cannot be placed is skipped.
    tasks = [(seed * 1000 + i, KINDS[i % len(KINDS)]) for i in range(4 * args.runs)]
    with multiprocessing.Pool(max(1, args.jobs)) as pool:
        for r in pool.imap(functools.partial(run_task, args=args), tasks):
            if r is None:
                continue
            results.append(r)
            brief = {k: v for k, v in r.items()
                     if k not in ("pos", "walls", "false_alarm_stamps")}
            print(f"[{len(results)}/{args.runs} {time.time() - t0:.0f} s] " + json.dumps(brief),
                  flush=True)
            if args.json:
                with open(args.json, "w") as f:
                    json.dump({"seed": seed, "results": results}, f)
            if len(results) >= args.runs:
                pool.terminate()
                break
    summarize(results, args, seed)
    if args.check and not check(results, args.junit):
        sys.exit(1)


if __name__ == "__main__":
    smoke_check.run(main, "change_detection")
