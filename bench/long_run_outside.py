#!/usr/bin/python3
"""The long run seen from outside (for runs stopped before their end, when long_run has not
written its own CSVs): /tmp/scenes-sampler-style samples of t_s, rchar (bytes read) and
VmRSS every 5 s. Frames read = (rchar - rchar0) / bytes per lap frame + frames at start.
usage: long_run_outside.py SAMPLES_CSV BYTES_PER_FRAME FRAMES_AT_FIRST_SAMPLE PNG"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

samples, per_frame, frames0, png = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
rows = list(csv.DictReader(open(samples)))
r0 = float(rows[0]["rchar"])
t = [float(r["t_s"]) for r in rows]
frames = [frames0 + (float(r["rchar"]) - r0) / per_frame for r in rows]
rss = [float(r["rss_kb"]) / 1024 for r in rows]
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
ax1.plot(frames, rss, lw=1)
ax1.set_ylabel("resident memory (MB)")
ax1.set_title("long run (optimized mode, patrol lap replayed), sampled from /proc every 5 s")
ax1.grid(alpha=0.3)
fx, rate = [], []
for i in range(12, len(rows), 12):  # frames per second over one minute
    fx.append(frames[i])
    rate.append((frames[i] - frames[i - 12]) / (t[i] - t[i - 12]))
ax2.plot(fx, rate, lw=1)
ax2.set_xlabel("frame")
ax2.set_ylabel("frames/s per minute\n(nice 10 on a shared machine)")
ax2.set_ylim(bottom=0)
ax2.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(png, dpi=110)
for i in range(0, len(rows), max(1, len(rows) // 12)):
    print(f"{t[i]:.0f} s  frame {frames[i]:.0f}  RSS {rss[i]:.0f} MB")
print(f"{t[-1]:.0f} s  frame {frames[-1]:.0f}  RSS {rss[-1]:.0f} MB")
