#!/usr/bin/env python3
"""KITTI camera-0 poses files for motions a car route never makes, for `scfloam simulate --replay`
(docs/odometry.md, "Session 38"): a robot that brakes and spins on the spot, a hand-held walk,
an aggressive car. Smooth at 100 Hz (speed and turn rates through smoothsteps), kept at 10 Hz.

  unusual_motions.py KIND OUT.txt      KIND: spin90 | spin120 | spin180 | handheld | aggressive
  scfloam simulate --out SEQ --replay OUT.txt --sensor os1-64 --motion-distortion [--scan-format pcd]

The replay takes x, y and the rotation from the file (z follows the simulated terrain).
Needs numpy and scipy (Debian: python3-numpy python3-scipy; scripts/install-deps.sh installs both).
"""
import sys

import numpy as np
from scipy.spatial.transform import Rotation

# KITTI's velodyne-to-camera transform (calib.txt of the 2011-10-03 drives), as src/io/kitti.cpp.
TR = np.eye(4)
TR[:3] = np.array([4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02,
                   -7.210626507497e-03, 8.081198471645e-03, -9.999413164504e-01, -5.403984729748e-02,
                   9.999738645903e-01, 4.859485810390e-04, -7.206933692422e-03, -2.921968648686e-01]).reshape(3, 4)
STEP_S = 0.01


def smooth(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def integrate(speed, yaw_rate, pitch, roll, duration_s):
    """Lidar poses every 0.1 s of a vehicle driven by speed(t) along its heading, turning at yaw_rate(t)."""
    x = y = yaw = 0.0
    poses = []
    for i in range(int(round(duration_s / STEP_S)) + 1):
        t = i * STEP_S
        if i % 10 == 0:
            pose = np.eye(4)
            pose[:3, :3] = Rotation.from_euler("zyx", [yaw, pitch(t), roll(t)]).as_matrix()
            pose[:3, 3] = [x, y, 0.0]
            poses.append(pose)
        x += speed(t) * np.cos(yaw) * STEP_S
        y += speed(t) * np.sin(yaw) * STEP_S
        yaw += yaw_rate(t) * STEP_S
    return poses


def spin(rate_deg):
    """10 m/s for 8 s, braking to a stop by 10.5 s, two turns on the spot (0.4 s ramps), driving off."""
    rate = np.radians(rate_deg)
    stop_s, spin_s = 10.5, 4 * np.pi / rate + 0.4

    def speed(t):
        s = t - stop_s - 0.5
        if t < 8:
            return 10.0
        if t < stop_s:
            return 10.0 * (1 - smooth((t - 8) / 2.5))
        return 0.0 if s <= spin_s else 8.0 * smooth((s - spin_s) / 3.0)

    def yaw_rate(t):
        s = t - stop_s - 0.5
        return rate * min(smooth(s / 0.4), smooth((spin_s - s) / 0.4)) if 0 <= s <= spin_s else 0.0

    zero = lambda t: 0.0
    return integrate(speed, yaw_rate, zero, zero, stop_s + 0.5 + spin_s + 12)


def handheld(pitch_deg=8.0, roll_deg=5.0):
    """A 90 s walk at 1.4 m/s: 30 deg/s turns for 3 s every 15 s, a +-10 deg heading sway at
    0.5 Hz, pitch and roll swinging at 0.8-1.9 Hz."""
    phase = np.random.default_rng(3).uniform(0, 2 * np.pi, 5)
    speed = lambda t: 1.4 * smooth(t / 2.0)
    yaw_rate = lambda t: (np.radians(30) if (t % 15) > 12 else 0.0) + \
        np.radians(10) * np.pi * np.cos(np.pi * t + phase[0])
    pitch = lambda t: np.radians(pitch_deg) * (0.7 * np.sin(2 * np.pi * 0.9 * t + phase[1]) +
                                               0.3 * np.sin(2 * np.pi * 1.7 * t + phase[2]))
    roll = lambda t: np.radians(roll_deg) * (0.7 * np.sin(2 * np.pi * 0.8 * t + phase[3]) +
                                             0.3 * np.sin(2 * np.pi * 1.9 * t + phase[4]))
    return integrate(speed, yaw_rate, pitch, roll, 90.0)


def aggressive():
    """12 m/s, braking at 8 m/s^2 to 7.2 m/s, a 45 deg/s U-turn, 4 m/s^2 up to 14 m/s, chicanes."""
    def speed(t):
        if t < 5:
            return 12.0
        if t < 5.6:
            return 12.0 - 8.0 * (t - 5)
        return 7.2 if t < 11 else min(14.0, 7.2 + 4.0 * (t - 11))

    def yaw_rate(t):
        if 6 <= t < 10:
            return np.radians(45) * min(smooth((t - 6) / 0.5), smooth((10 - t) / 0.5))
        return np.radians(20) * np.sin(2 * np.pi * (t - 14) / 4.0) if t >= 14 else 0.0

    zero = lambda t: 0.0
    return integrate(speed, yaw_rate, zero, zero, 40.0)


KINDS = {"spin90": lambda: spin(90), "spin120": lambda: spin(120), "spin180": lambda: spin(180),
         "handheld": handheld, "aggressive": aggressive}


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in KINDS:
        sys.exit(__doc__)
    poses = KINDS[sys.argv[1]]()
    tr_inv = np.linalg.inv(TR)
    with open(sys.argv[2], "w") as out:
        for pose in poses:
            camera = TR @ pose @ tr_inv
            out.write(" ".join("%.9e" % v for v in camera[:3].reshape(-1)) + "\n")
    print(sys.argv[1], len(poses), "poses ->", sys.argv[2])


if __name__ == "__main__":
    main()
