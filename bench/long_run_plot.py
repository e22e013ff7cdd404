#!/usr/bin/python3
"""Plots a long run (bench/long_run.sh): resident memory and per-frame odometry time against
frames, and writes a markdown table per block of 2000 frames.
usage: long_run_plot.py OUT_DIR PNG TABLE_MD"""
import csv
import json
import statistics
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out_dir, png, table_path = sys.argv[1:4]
mem = list(csv.DictReader(open(f"{out_dir}/memory.csv")))
frames = list(csv.DictReader(open(f"{out_dir}/frames.csv")))
try:
    summary = json.load(open(f"{out_dir}/summary.json"))
except FileNotFoundError:  # a run still going on or stopped: its CSVs so far
    summary = {"mode": "unfinished run"}
ms = [float(r["features_ms"]) + float(r["registration_ms"]) for r in frames]
n = len(ms)
block = 2000 if n >= 4000 else max(1, n // 10)

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
ax1.plot([int(r["frames_read"]) for r in mem], [float(r["rss_mb"]) for r in mem], lw=1)
ax1.set_ylabel("resident memory (MB)")
ax1.set_title(f"long run: {n} frames ({summary['mode']}), one {summary.get('keyframe_storage', {}).get('keyframes', '?')}-keyframe map")
ax1.grid(alpha=0.3)
step = 200
xs, med, p95 = [], [], []
for a in range(0, n, step):
    chunk = sorted(ms[a:a + step])
    xs.append(a + len(chunk) / 2)
    med.append(statistics.median(chunk))
    p95.append(chunk[min(len(chunk) - 1, int(0.95 * len(chunk)))])
ax2.plot(xs, med, lw=1, label="median per 200 frames")
ax2.plot(xs, p95, lw=1, label="p95 per 200 frames")
ax2.set_xlabel("frame")
ax2.set_ylabel("odometry ms/frame\n(features + registration)")
ax2.set_ylim(bottom=0)
ax2.grid(alpha=0.3)
ax2.legend()
fig.tight_layout()
fig.savefig(png, dpi=110)


loops = []
try:
    loops = list(csv.DictReader(open(f"{out_dir}/loops.csv")))
except FileNotFoundError:
    pass


def loops_in(a, b):
    return sum(1 for r in loops if a <= int(r["current_frame"]) < b and r["verdict"] == "accepted")


def rss_at(frame):
    best = None
    for r in mem:
        if int(r["frames_read"]) <= frame:
            best = float(r["rss_mb"])
    return best if best is not None else float("nan")


rows = ["| frames | RSS at end (MB) | median ms/frame | p95 ms/frame | loops accepted |",
        "| --- | --- | --- | --- | --- |"]
for a in range(0, n, block):
    chunk = sorted(ms[a:a + block])
    rows.append(f"| {a}-{a + len(chunk) - 1} | {rss_at(a + len(chunk)):.0f} | {statistics.median(chunk):.2f} | "
                f"{chunk[min(len(chunk) - 1, int(0.95 * len(chunk)))]:.2f} | {loops_in(a, a + len(chunk))} |")
open(table_path, "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
