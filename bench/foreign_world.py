#!/usr/bin/env python3
"""A LiDAR sequence from a world that scfloam's own simulator did not make.

Every accuracy figure of scfloam on simulated data comes from src/sim/, so tuning against that
simulator's habits would go unnoticed there. This script is a second, deliberately different
generator, written apart from src/sim/ and sharing no code or layout with it: a hilly rural
ring road with gabled houses, hedges, tree rows and utility poles instead of a grid city; a
32-beam sensor with 1 degree spacing (no scfloam preset, so the beams must be learned from the
scans), mounted 1.85 m up, spinning clockwise, column-major points, intensity 0-255; raw sweeps
(each column cast from the pose at its firing time, per-point `t` in seconds from the stamp);
oncoming cars; per-beam calibration errors (elevation, azimuth, range bias). Output: a folder of
binary PCD scans named by their stamps, `times.txt`, `gt_tum.txt` (sensor poses at the stamps,
TUM format) and `beam_calibration.yaml` (the errors drawn). numpy only.

  /usr/bin/python3 bench/foreign_world.py --out DIR [--laps 2] [--seed 1] [--jobs 2]
      [--frames N] [--perfect-calibration | --calibration-errors el,az,bias]
  scfloam run DIR -m optimized -o OUT --deterministic
  scfloam eval --gt DIR/gt_tum.txt --est OUT/poses_tum.txt
"""
import argparse
import math
import os
import sys
from multiprocessing import Pool

import numpy as np

SCAN_PERIOD = 0.1
COLUMNS = 2000
BEAMS_DEG = np.linspace(15.0, -16.0, 32)
MOUNT_HEIGHT = 1.85
MAX_RANGE = 120.0
MIN_RANGE = 1.2


# ---------------------------------------------------------------- terrain
class Terrain:
    """Rolling hills: a sum of long plane waves, slopes up to ~6 %."""

    def __init__(self, rng):
        self.waves = []
        for _ in range(4):
            wavelength = rng.uniform(180.0, 420.0)
            ang = rng.uniform(0, math.pi)
            k = 2 * math.pi / wavelength
            amp = rng.uniform(0.012, 0.022) / k  # slope amplitude 1.2-2.2 % each
            self.waves.append((k * math.cos(ang), k * math.sin(ang), rng.uniform(0, 6.3), amp))

    def height(self, x, y):
        h = np.zeros(np.broadcast(x, y).shape)
        for kx, ky, ph, a in self.waves:
            h = h + a * np.sin(kx * x + ky * y + ph)
        return h

    def gradient(self, x, y):
        gx = np.zeros(np.broadcast(x, y).shape)
        gy = np.zeros_like(gx)
        for kx, ky, ph, a in self.waves:
            c = a * np.cos(kx * x + ky * y + ph)
            gx = gx + kx * c
            gy = gy + ky * c
        return gx, gy


# ---------------------------------------------------------------- road and drive
def ring_road(rng, radius):
    """A closed, smooth, non-circular road: r(theta) with two harmonics, sampled every 0.25 m."""
    a2, a3 = rng.uniform(0.12, 0.2), rng.uniform(0.05, 0.1)
    p2, p3 = rng.uniform(0, 6.3), rng.uniform(0, 6.3)
    th = np.linspace(0, 2 * math.pi, 20000, endpoint=False)
    r = radius * (1 + a2 * np.sin(2 * th + p2) + a3 * np.sin(3 * th + p3))
    pts = np.stack([r * np.cos(th), r * np.sin(th)], 1)
    seg = np.linalg.norm(np.diff(np.vstack([pts, pts[:1]]), axis=0), axis=1)
    s = np.concatenate([[0], np.cumsum(seg)])
    length = s[-1]
    n = int(length / 0.25)
    su = np.linspace(0, length, n, endpoint=False)
    closed = np.vstack([pts, pts[:1]])
    xy = np.stack([np.interp(su, s, closed[:, 0]), np.interp(su, s, closed[:, 1])], 1)
    return xy, length


def tangent_and_curvature(xy):
    d1 = (np.roll(xy, -1, 0) - np.roll(xy, 1, 0)) / 2
    d2 = np.roll(xy, -1, 0) - 2 * xy + np.roll(xy, 1, 0)
    yaw = np.arctan2(d1[:, 1], d1[:, 0])
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(np.linalg.norm(d1, axis=1) ** 3, 1e-9)
    return yaw, kappa


def speed_profile(rng, s, kappa, laps_length):
    """Cruise speed that wanders smoothly (6-13 m/s), capped by 2 m/s^2 lateral acceleration,
    then limited to +-1.3 m/s^2 by a forward and a backward pass."""
    v = 9.5 + np.zeros_like(s)
    for _ in range(3):
        wl = rng.uniform(150, 500)
        v += rng.uniform(0.8, 1.6) * np.sin(2 * math.pi * s / wl + rng.uniform(0, 6.3))
    v = np.clip(v, 6.0, 13.0)
    v = np.minimum(v, np.sqrt(2.0 / np.maximum(np.abs(kappa), 1e-6)))
    v[0] = 3.0  # pull away from a near stop
    ds = np.diff(s)
    for i in range(1, len(v)):
        v[i] = min(v[i], math.sqrt(v[i - 1] ** 2 + 2 * 1.3 * ds[i - 1]))
    for i in range(len(v) - 2, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * 1.3 * ds[i]))
    return v


class Drive:
    """Sensor pose as a function of time: along the road's right lane, attitude from the terrain."""

    def __init__(self, rng, terrain, road_xy, road_len, laps):
        self.terrain = terrain
        yaw, kappa = tangent_and_curvature(road_xy)
        n = len(road_xy)
        reps = int(math.ceil(laps)) + 1
        s_all = np.arange(n * reps) * (road_len / n)
        idx = np.arange(n * reps) % n
        v = speed_profile(rng, s_all, kappa[idx], road_len)
        dt = np.diff(s_all) / (0.5 * (v[1:] + v[:-1]))
        t_all = np.concatenate([[0], np.cumsum(dt)])
        self.s_of_t = (t_all, s_all)
        self.road_xy, self.road_len, self.n = road_xy, road_len, n
        self.end_s = laps * road_len
        self.duration = float(np.interp(self.end_s, s_all, t_all))
        # small body motion: smooth pitch/roll wobble (suspension), radians
        self.wob = [(rng.uniform(0.6, 2.5), rng.uniform(0, 6.3), rng.uniform(0.0004, 0.0009)) for _ in range(4)]

    def xy_yaw(self, s):
        f = (s % self.road_len) / self.road_len * self.n
        i0 = np.floor(f).astype(int) % self.n
        i1 = (i0 + 1) % self.n
        w = (f - np.floor(f))[..., None]
        p = (1 - w) * self.road_xy[i0] + w * self.road_xy[i1]
        d = self.road_xy[i1] - self.road_xy[i0]
        yaw = np.arctan2(d[..., 1], d[..., 0])
        lane = 1.8  # right lane: offset to the right of the travel direction
        p = p + lane * np.stack([np.sin(yaw), -np.cos(yaw)], -1)
        return p, yaw

    def pose(self, t):
        """t: array of times -> (R [n,3,3], p [n,3])."""
        t = np.atleast_1d(np.asarray(t, float))
        s = np.interp(t, *self.s_of_t)
        # heading from a short chord so that yaw is smooth between road samples
        pa, _ = self.xy_yaw(s - 1.0)
        pb, _ = self.xy_yaw(s + 1.0)
        xy, _ = self.xy_yaw(s)
        yaw = np.arctan2(pb[:, 1] - pa[:, 1], pb[:, 0] - pa[:, 0])
        gx, gy = self.terrain.gradient(xy[:, 0], xy[:, 1])
        up = np.stack([-gx, -gy, np.ones_like(gx)], 1)
        up /= np.linalg.norm(up, axis=1, keepdims=True)
        fwd = np.stack([np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)], 1)
        fwd = fwd - (fwd * up).sum(1, keepdims=True) * up
        fwd /= np.linalg.norm(fwd, axis=1, keepdims=True)
        left = np.cross(up, fwd)
        R = np.stack([fwd, left, up], 2)
        pitch = sum(a * np.sin(f * t + ph) for f, ph, a in self.wob[:2])
        roll = sum(a * np.sin(f * t + ph) for f, ph, a in self.wob[2:])
        R = R @ rot_y(pitch) @ rot_x(roll)
        z = self.terrain.height(xy[:, 0], xy[:, 1]) + MOUNT_HEIGHT
        # the mount sits on the body: lift along the body's up, not the world's
        p = np.stack([xy[:, 0], xy[:, 1], z - MOUNT_HEIGHT], 1) + MOUNT_HEIGHT * R[:, :, 2]
        return R, p


def rot_x(a):
    a = np.atleast_1d(a)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(a):
    a = np.atleast_1d(a)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


# ---------------------------------------------------------------- world objects
class World:
    """Convex polyhedra (houses with gabled roofs, hedges, cars, fences), vertical cylinders
    (trunks, poles) and porous spheres (tree crowns), placed along the ring road."""

    def __init__(self, rng, terrain, road_xy, road_len):
        self.terrain = terrain
        self.road_xy = road_xy
        polys, cyls, spheres = [], [], []
        yaw, _ = tangent_and_curvature(road_xy)
        n = len(road_xy)
        step = road_len / n

        def at(s, offset):
            i = int((s % road_len) / step) % n
            p, y = road_xy[i], yaw[i]
            right = np.array([math.sin(y), -math.cos(y)])
            return p + offset * right, y

        for side in (+1, -1):  # +1: right of travel, -1: left
            s = rng.uniform(0, 20)
            while s < road_len - 10:
                zone = rng.uniform()
                span = rng.uniform(40, 140)
                end = min(s + span, road_len - 5)
                if zone < 0.55:  # houses
                    while s < end:
                        w = rng.uniform(8, 15)
                        depth = rng.uniform(7, 12)
                        setback = rng.uniform(9, 22)
                        c, y = at(s + w / 2, side * (setback + depth / 2))
                        y += rng.normal(0, math.radians(4))
                        wall_h = rng.uniform(2.8, 6.5)
                        pitch = math.radians(rng.uniform(20, 42))
                        ridge_along = rng.uniform() < 0.7
                        polys.append(("house", house_planes(c, y, w, depth, wall_h, pitch, ridge_along, terrain),
                                      rng.uniform(0.2, 0.6)))
                        if rng.uniform() < 0.5:  # a hedge or fence in front
                            hc, _ = at(s + w / 2, side * (7.5 + rng.uniform(0, 1.5)))
                            tall = rng.uniform(0.9, 1.8)
                            thick = rng.uniform(0.5, 1.0) if rng.uniform() < 0.6 else 0.06
                            polys.append(("hedge" if thick > 0.1 else "fence",
                                          box_planes(hc, y, w * 0.9, thick, tall, terrain), 0.45))
                        if rng.uniform() < 0.25:  # a parked car on the verge
                            cc, _ = at(s + rng.uniform(0, w), side * rng.uniform(5.2, 6.0))
                            polys.append(("car", box_planes(cc, y, 4.3, 1.8, 1.45, terrain, lift=0.2),
                                          rng.uniform(0.1, 0.8)))
                        s += w + rng.uniform(3, 16)
                elif zone < 0.85:  # tree row
                    while s < end:
                        c, _ = at(s, side * rng.uniform(6.5, 9.5))
                        z0 = float(terrain.height(c[0], c[1]))
                        trunk_h = rng.uniform(1.8, 3.5)
                        cyls.append((c[0], c[1], rng.uniform(0.12, 0.3), z0, z0 + trunk_h + 1.0, rng.uniform(0.25, 0.4)))
                        r = rng.uniform(1.6, 3.6)
                        spheres.append((c[0], c[1], z0 + trunk_h + r * 0.8, r, rng.uniform(0.6, 1.4)))
                        s += rng.uniform(5, 11)
                else:  # open field: a few bushes and lone trees well off the road
                    while s < end:
                        c, _ = at(s, side * rng.uniform(10, 40))
                        z0 = float(terrain.height(c[0], c[1]))
                        r = rng.uniform(0.8, 3.0)
                        spheres.append((c[0], c[1], z0 + r * 0.7, r, rng.uniform(0.4, 1.0)))
                        s += rng.uniform(10, 30)
                s = end + rng.uniform(0, 15)
        # utility poles along the left side every 35-50 m
        s = 0.0
        while s < road_len - 20:
            c, _ = at(s, -rng.uniform(5.5, 6.5))
            z0 = float(terrain.height(c[0], c[1]))
            cyls.append((c[0], c[1], 0.14, z0, z0 + 9.0, 0.35))
            s += rng.uniform(35, 50)
        self.polys = polys
        self.cyls = np.array(cyls, float).reshape(-1, 6)
        self.spheres = np.array(spheres, float).reshape(-1, 5)
        # bounding circles of the polyhedra, for culling
        self.poly_center = np.array([p[1][1] for p in polys])
        self.poly_radius = np.array([p[1][2] for p in polys])
        # distance to the road centre on a raster, for the ground's material
        lo = road_xy.min(0) - 150
        hi = road_xy.max(0) + 150
        self.raster_lo, self.raster_res = lo, 1.0
        gx = np.arange(lo[0], hi[0], 1.0)
        gy = np.arange(lo[1], hi[1], 1.0)
        X, Y = np.meshgrid(gx, gy, indexing="ij")
        cells = np.stack([X.ravel(), Y.ravel()], 1)
        sub = road_xy[::4]
        best = np.empty(len(cells))
        for k in range(0, len(cells), 4096):
            best[k:k + 4096] = np.linalg.norm(cells[k:k + 4096, None, :] - sub[None, :, :], axis=2).min(1)
        self.road_dist = best.reshape(X.shape)

    def dist_to_road(self, x, y):
        i = np.clip(((x - self.raster_lo[0]) / self.raster_res).astype(int), 0, self.road_dist.shape[0] - 1)
        j = np.clip(((y - self.raster_lo[1]) / self.raster_res).astype(int), 0, self.road_dist.shape[1] - 1)
        return self.road_dist[i, j]


def _frame_planes(c, yaw, terrain):
    cy, sy = math.cos(yaw), math.sin(yaw)
    ax = np.array([cy, sy, 0.0])   # along the long side
    ay = np.array([-sy, cy, 0.0])  # across
    z0 = float(terrain.height(c[0], c[1]))
    return ax, ay, z0


def box_planes(c, yaw, length, width, height, terrain, lift=0.0):
    ax, ay, z0 = _frame_planes(c, yaw, terrain)
    ctr = np.array([c[0], c[1], 0.0])
    planes = []
    for n, half in ((ax, length / 2), (-ax, length / 2), (ay, width / 2), (-ay, width / 2)):
        planes.append(np.append(n, n @ ctr + half))
    planes.append(np.array([0, 0, 1.0, z0 + lift + height]))
    planes.append(np.array([0, 0, -1.0, -(z0 + lift - 0.5)]))  # sunk into the slope
    radius = math.hypot(length, width) / 2 + 0.1
    return np.array(planes), np.array([c[0], c[1]]), radius


def house_planes(c, yaw, length, depth, wall_h, pitch, ridge_along, terrain):
    """Walls, a floor and two roof slopes: one convex polyhedron (the gables are the end walls)."""
    planes, centre, radius = box_planes(c, yaw, length, depth, 100.0, terrain)
    ax, ay, z0 = _frame_planes(c, yaw, terrain)
    planes = planes[[0, 1, 2, 3, 5]]
    across, half = (ay, depth / 2) if ridge_along else (ax, length / 2)
    ctr = np.array([c[0], c[1], 0.0])
    t = math.tan(pitch)
    eave = z0 + wall_h
    for sgn in (+1, -1):
        # z + t * sgn * (across . (x - ctr)) <= eave + t * half
        n = np.array([t * sgn * across[0], t * sgn * across[1], 1.0])
        d = eave + t * half + t * sgn * (across @ ctr)
        norm = np.linalg.norm(n)
        planes = np.vstack([planes, np.append(n / norm, d / norm)])
    return planes, centre, radius


# ---------------------------------------------------------------- ray casting
def cast(world, movers, O, D, rng):
    """First hits of rays O + t D (O, D: [N,3], D unit). Returns range t, reflectance, cos incidence."""
    N = len(D)
    t_hit = np.full(N, np.inf)
    refl = np.zeros(N)
    cosi = np.ones(N)

    # ground: march a geometric grid of distances, then bisect the first crossing
    ts = np.geomspace(0.5, MAX_RANGE + 5, 90)
    g = O[:, 2:3] + ts[None, :] * D[:, 2:3] - world.terrain.height(O[:, 0:1] + ts * D[:, 0:1], O[:, 1:2] + ts * D[:, 1:2])
    below = g < 0
    has = below.any(1)
    k = np.argmax(below, 1)
    ok = has & (k > 0)
    idx = np.nonzero(ok)[0]
    lo, hi = ts[k[idx] - 1].copy(), ts[k[idx]].copy()
    o, d = O[idx], D[idx]
    for _ in range(22):
        mid = 0.5 * (lo + hi)
        gm = o[:, 2] + mid * d[:, 2] - world.terrain.height(o[:, 0] + mid * d[:, 0], o[:, 1] + mid * d[:, 1])
        neg = gm < 0
        hi = np.where(neg, mid, hi)
        lo = np.where(neg, lo, mid)
    tg = 0.5 * (lo + hi)
    px, py = o[:, 0] + tg * d[:, 0], o[:, 1] + tg * d[:, 1]
    road = world.dist_to_road(px, py) < 4.2
    # grass is rough: a few centimetres of relief the road does not have
    rough = np.where(road, 0.0, 0.03 * np.sin(px * 7.1 + 3 * np.sin(py * 5.3)) * np.sin(py * 6.7))
    tg = tg - rough / np.maximum(-d[:, 2], 0.02)
    gx, gy = world.terrain.gradient(px, py)
    nrm = np.stack([-gx, -gy, np.ones_like(gx)], 1)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    t_hit[idx] = np.maximum(tg, 0.3)
    refl[idx] = np.where(road, 0.12, 0.35)
    cosi[idx] = np.abs((nrm * d).sum(1))

    origin = O.mean(0)
    az = np.arctan2(D[:, 1], D[:, 0])

    def candidates(centres, radii):
        rel = centres[:, :2] - origin[:2]
        dist = np.linalg.norm(rel, axis=1)
        near = dist < MAX_RANGE + radii + 2
        ang = np.arctan2(rel[:, 1], rel[:, 0])
        half = np.arcsin(np.clip((radii + 2.0) / np.maximum(dist, 1e-3), 0, 1))
        half = np.where(dist <= radii + 2.0, math.pi, half)
        return near, ang, half

    def ray_mask(ang, half):
        diff = np.abs((az - ang + math.pi) % (2 * math.pi) - math.pi)
        return diff <= half

    # convex polyhedra
    all_polys = list(world.polys) + movers
    if all_polys:
        centres = np.array([p[1][1] for p in all_polys])
        radii = np.array([p[1][2] for p in all_polys])
        near, ang, half = candidates(centres, radii)
        for i in np.nonzero(near)[0]:
            sel = np.nonzero(ray_mask(ang[i], half[i]))[0]
            if len(sel) == 0:
                continue
            planes = all_polys[i][1][0]
            o, d = O[sel], D[sel]
            denom = d @ planes[:, :3].T
            num = planes[:, 3][None, :] - o @ planes[:, :3].T
            with np.errstate(divide="ignore", invalid="ignore"):
                tt = num / denom
            enter = np.where(denom < 0, tt, -np.inf)
            leave = np.where(denom > 0, tt, np.inf)
            parallel_out = (denom == 0) & (num < 0)
            t_in = enter.max(1)
            t_out = leave.min(1)
            hit = (t_in <= t_out) & (t_in > 0.2) & ~parallel_out.any(1) & (t_in < t_hit[sel])
            if not hit.any():
                continue
            face = np.argmax(enter[hit], 1)
            h = sel[hit]
            t_hit[h] = t_in[hit]
            refl[h] = all_polys[i][2]
            cosi[h] = np.abs((planes[face, :3] * D[h]).sum(1))
            if all_polys[i][0] == "hedge":  # leaves: the return comes from inside the hedge
                t_hit[h] += rng.exponential(0.15, len(h))

    # vertical cylinders
    if len(world.cyls):
        c = world.cyls
        near, ang, half = candidates(c[:, :2], c[:, 2])
        for i in np.nonzero(near)[0]:
            sel = np.nonzero(ray_mask(ang[i], half[i]))[0]
            if len(sel) == 0:
                continue
            o, d = O[sel], D[sel]
            ox, oy = o[:, 0] - c[i, 0], o[:, 1] - c[i, 1]
            a = d[:, 0] ** 2 + d[:, 1] ** 2
            b = 2 * (ox * d[:, 0] + oy * d[:, 1])
            cc = ox ** 2 + oy ** 2 - c[i, 2] ** 2
            disc = b * b - 4 * a * cc
            okd = (disc > 0) & (a > 1e-9)
            tt = np.where(okd, (-b - np.sqrt(np.maximum(disc, 0))) / (2 * np.maximum(a, 1e-9)), np.inf)
            z = o[:, 2] + tt * d[:, 2]
            hit = okd & (tt > 0.2) & (z >= c[i, 3]) & (z <= c[i, 4]) & (tt < t_hit[sel])
            if hit.any():
                h = sel[hit]
                t_hit[h] = tt[hit]
                refl[h] = c[i, 5]
                nx = (ox[hit] + tt[hit] * d[hit, 0]) / c[i, 2]
                ny = (oy[hit] + tt[hit] * d[hit, 1]) / c[i, 2]
                cosi[h] = np.abs(nx * d[hit, 0] + ny * d[hit, 1])

    # porous tree crowns: the ray enters and stops after an exponential depth, or passes
    if len(world.spheres):
        sp = world.spheres
        near, ang, half = candidates(sp[:, :2], sp[:, 3])
        for i in np.nonzero(near)[0]:
            sel = np.nonzero(ray_mask(ang[i], half[i]))[0]
            if len(sel) == 0:
                continue
            o, d = O[sel], D[sel]
            oc = o - sp[i, :3]
            b = (oc * d).sum(1)
            cc = (oc * oc).sum(1) - sp[i, 3] ** 2
            disc = b * b - cc
            okd = disc > 0
            sq = np.sqrt(np.maximum(disc, 0))
            t0, t1 = -b - sq, -b + sq
            depth = rng.exponential(sp[i, 4], len(sel))
            th = np.maximum(t0, 0.2) + depth
            hit = okd & (t1 > 0.2) & (th < t1) & (th < t_hit[sel])
            if hit.any():
                h = sel[hit]
                t_hit[h] = th[hit]
                refl[h] = 0.5
                cosi[h] = rng.uniform(0.2, 1.0, len(h))
    return t_hit, refl, cosi


# ---------------------------------------------------------------- movers
def oncoming_cars(rng, drive, t):
    """Boxes driving the other lane towards the ego car, at the frame's time (not per column)."""
    out = []
    for s0, v in drive.traffic:
        s = s0 - v * t
        if s < -50:
            continue
        p, y = drive.xy_yaw(np.array([s]))
        p = p[0] - 3.6 * np.array([math.sin(y[0]), -math.cos(y[0])])  # left lane
        out.append(("car", box_planes(p, float(y[0]), 4.5, 1.8, 1.5, drive.terrain, lift=0.25), 0.5))
    return out


# ---------------------------------------------------------------- one scan
def write_pcd(path, pts):
    tmp = path + ".tmp"
    header = ("# .PCD v0.7 - foreign_world.py\nVERSION 0.7\nFIELDS x y z intensity t\nSIZE 4 4 4 4 4\n"
              "TYPE F F F F F\nCOUNT 1 1 1 1 1\nWIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
              "POINTS %d\nDATA binary\n" % (len(pts), len(pts)))
    with open(tmp, "wb") as f:
        f.write(header.encode())
        f.write(pts.astype(np.float32).tobytes())
    os.replace(tmp, path)


CTX = {}


def render(frame):
    world, drive, calib, out, stamps, seed = CTX["args"]
    rng = np.random.default_rng(seed * 100003 + frame)
    t0 = stamps[frame]
    col_t = np.arange(COLUMNS) * (SCAN_PERIOD / COLUMNS)
    R, p = drive.pose(t0 + col_t)  # a pose per column: a raw, motion-distorted sweep
    # clockwise from behind the car, as a Velodyne spins
    az = math.pi - col_t / SCAN_PERIOD * 2 * math.pi
    el = np.radians(BEAMS_DEG)
    true_el = el + calib["el"]
    A = az[:, None] + calib["az"][None, :]
    dirs = np.stack([np.cos(true_el)[None, :] * np.cos(A), np.cos(true_el)[None, :] * np.sin(A),
                     np.broadcast_to(np.sin(true_el)[None, :], A.shape)], -1)  # [C,B,3] sensor
    Dw = np.einsum("cij,cbj->cbi", R, dirs).reshape(-1, 3)
    Ow = np.repeat(p, len(el), axis=0)
    movers = oncoming_cars(rng, drive, t0 + SCAN_PERIOD / 2)
    t_hit, refl, cosi = cast(world, movers, Ow, Dw, rng)
    t_hit = np.where(np.isfinite(t_hit), t_hit, 2 * MAX_RANGE)
    rng_m = t_hit + calib["bias"][None, :].repeat(COLUMNS, 0).ravel() + rng.normal(0, 0.02, len(t_hit))
    strength = refl * np.maximum(cosi, 0.05) * (25.0 / np.maximum(t_hit, 1.0)) ** 2
    keep = ((t_hit < MAX_RANGE) & (rng_m > MIN_RANGE) & (strength > 0.003)
            & (rng.uniform(size=len(t_hit)) > 0.015))
    # reported along the nominal beam, in the sensor frame at the firing time
    nominal = np.stack([np.cos(el)[None, :] * np.cos(az)[:, None], np.cos(el)[None, :] * np.sin(az)[:, None],
                        np.broadcast_to(np.sin(el)[None, :], (COLUMNS, len(el)))], -1).reshape(-1, 3)
    xyz = nominal * rng_m[:, None]
    inten = np.clip(255 * (refl * (0.5 + 0.5 * cosi)) + rng.normal(0, 4, len(refl)), 0, 255)
    tt = np.repeat(col_t, len(el))
    pts = np.column_stack([xyz, inten, tt])[keep]
    write_pcd(os.path.join(out, "%.9f.pcd" % (1.7e9 + t0)), pts)
    return frame


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--laps", type=float, default=2.0)
    ap.add_argument("--radius", type=float, default=110.0, help="mean radius of the ring road, m")
    ap.add_argument("--frames", type=int, default=0, help="stop after this many scans (0: the whole drive)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count())
    ap.add_argument("--perfect-calibration", action="store_true",
                    help="no per-beam elevation, azimuth or range errors (noise and dropouts stay)")
    ap.add_argument("--calibration-errors", default="el,az,bias",
                    help="which per-beam errors to keep, of el, az, bias (comma-separated; "
                         "the others are zero; --perfect-calibration keeps none)")
    a = ap.parse_args()
    keep = {k for k in a.calibration_errors.split(",") if k}
    if not keep <= {"el", "az", "bias"}:
        ap.error("--calibration-errors takes el, az and bias")
    if not (a.laps > 0 and a.radius >= 40 and a.frames >= 0 and a.jobs >= 1):
        ap.error("--laps must be > 0, --radius >= 40, --frames >= 0, --jobs >= 1")
    rng = np.random.default_rng(a.seed)
    terrain = Terrain(rng)
    road_xy, road_len = ring_road(rng, a.radius)
    drive = Drive(rng, terrain, road_xy, road_len, a.laps)
    drive.traffic = [(rng.uniform(0, a.laps * road_len + 300), rng.uniform(7, 14))
                     for _ in range(int(drive.duration / 12))]
    world = World(rng, terrain, road_xy, road_len)
    calib = {"el": rng.normal(0, math.radians(0.03), len(BEAMS_DEG)),
             "az": rng.normal(0, math.radians(0.03), len(BEAMS_DEG)),
             "bias": rng.normal(0, 0.01, len(BEAMS_DEG))}
    # Drawn all the same, so that the world and the drive do not change.
    calib = {k: (v if k in keep and not a.perfect_calibration else np.zeros_like(v)) for k, v in calib.items()}
    n = int(drive.duration / SCAN_PERIOD)
    if a.frames:
        n = min(n, a.frames)
    stamps = np.arange(n) * SCAN_PERIOD
    os.makedirs(a.out, exist_ok=True)
    R, p = drive.pose(stamps)
    write_text(os.path.join(a.out, "gt_tum.txt"), "".join(
        "%.9f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n" % (1.7e9 + t, *pi, *quat(Ri)) for t, Ri, pi in zip(stamps, R, p)))
    write_text(os.path.join(a.out, "times.txt"), "".join("%.9f\n" % (1.7e9 + t) for t in stamps))
    # The calibration errors drawn, beam by beam from the top: the ground truth of a calibration.
    # A beam's true elevation / azimuth is its nominal one plus its offset; its reported range
    # is the true range plus its bias.
    fmt = lambda v: "[" + ", ".join("%.6g" % x for x in v) + "]"
    write_text(os.path.join(a.out, "beam_calibration.yaml"),
               "# true elevation / azimuth = nominal + offset; reported range = true range + bias\n"
               "elevation_deg: %s\nelevation_offset_deg: %s\nazimuth_offset_deg: %s\nrange_bias_m: %s\n"
               % (fmt(BEAMS_DEG), fmt(np.degrees(calib["el"])), fmt(np.degrees(calib["az"])), fmt(calib["bias"])))
    print("foreign_world: road %.0f m, %d houses/hedges/cars, %d trunks and poles, %d crowns, %d frames (%.0f s)"
          % (road_len, len(world.polys), len(world.cyls), len(world.spheres), n, n * SCAN_PERIOD), flush=True)
    CTX["args"] = (world, drive, calib, a.out, stamps, a.seed)
    with Pool(a.jobs) as pool:
        for k, _ in enumerate(pool.imap(render, range(n), chunksize=4)):
            if k % 100 == 0:
                print("  frame %d / %d" % (k, n), flush=True)


def write_text(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def quat(R):
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return x, y, z, w


if __name__ == "__main__":
    sys.exit(main())
