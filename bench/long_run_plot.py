#!/usr/bin/python3
"""Plots a long run (bench/long_run.sh): resident memory (and malloc's in-use and retained
bytes, where memory.csv has them) and per-frame odometry time against frames, and writes a
markdown table per block of 2000 frames.
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
mem_frames = [int(r["frames_read"]) for r in mem]
ax1.plot(mem_frames, [float(r["rss_mb"]) for r in mem], lw=1, label="resident (RSS)")
if mem and "heap_in_use_mb" in mem[0]:  # runs before session 7 recorded RSS only
    ax1.plot(mem_frames, [float(r["heap_in_use_mb"]) for r in mem], lw=1, label="malloc in use")
    ax1.plot(mem_frames, [float(r["heap_free_mb"]) for r in mem], lw=1, label="malloc free, retained")
    ax1.legend()
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


def sample_at(frame):
    """The first memory sample taken once `frame` frames were read (for the last block: as
    reading ended, before the final solve and the outputs); the last sample if none."""
    for r in mem:
        if int(r["frames_read"]) >= frame:
            return r
    return mem[-1] if mem else None


def peak_rss(a, b):
    rss = [float(r["rss_mb"]) for r in mem if a <= int(r["frames_read"]) < b]
    return f"{max(rss):.0f}" if rss else "n/a"


def frames_per_s(a, b):
    """Frames read per wall second between the samples nearest frames a and b."""
    ra, rb = sample_at(a), sample_at(b)
    if ra is None or rb is None or float(rb["elapsed_s"]) <= float(ra["elapsed_s"]):
        return float("nan")
    return (int(rb["frames_read"]) - int(ra["frames_read"])) / (float(rb["elapsed_s"]) - float(ra["elapsed_s"]))


def max_queues(a, b):
    """Deepest detection and closure queues sampled while frames a..b were read."""
    rows_in = [r for r in mem if a <= int(r["frames_read"]) < b and "closure_queue" in r]
    if not rows_in:
        return "n/a"
    return f"{max(int(r['detection_queue']) for r in rows_in)} / {max(int(r['closure_queue']) for r in rows_in)}"


def mb(row, key):
    return f"{float(row[key]):.0f}" if row is not None and key in row else "n/a"


rows = ["| frames | frames/s | RSS at end (MB) | peak RSS (MB) | malloc in use (MB) | malloc retained free (MB) | "
        "max queues det. / clos. | median ms/frame | p95 ms/frame | loops accepted |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
for a in range(0, n, block):
    chunk = sorted(ms[a:a + block])
    end = sample_at(a + len(chunk))
    rows.append(f"| {a}-{a + len(chunk) - 1} | {frames_per_s(a, a + len(chunk)):.1f} | {mb(end, 'rss_mb')} | {peak_rss(a, a + len(chunk))} | "
                f"{mb(end, 'heap_in_use_mb')} | {mb(end, 'heap_free_mb')} | {max_queues(a, a + len(chunk))} | "
                f"{statistics.median(chunk):.2f} | {chunk[min(len(chunk) - 1, int(0.95 * len(chunk)))]:.2f} | "
                f"{loops_in(a, a + len(chunk))} |")
open(table_path, "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
