#!/usr/bin/env python3
"""Loop edges of a run against the simulator's ground truth (docs/loop_closure.md).

  loop_edges_vs_truth.py chi2 RUN SEQ     each loop edge's error and whitened chi2 under its
                                          own information (graph.g2o): calibrates
                                          loop_registration.information_inflation
  loop_edges_vs_truth.py oracle RUN SEQ   re-solve RUN's pose graph from its odometry chain with
                                          variants of the loop edges (measured or true, fixed or
                                          tight information) and print the keyframe ATE of each

RUN is a `scfloam run` output folder (graph.g2o, poses_kitti.txt, keyframes_kitti.txt), SEQ
the simulated KITTI-layout sequence it ran on (poses.txt, calib.txt). Needs numpy and scipy
(Debian: python3-numpy python3-scipy). The oracle's solver is plain Gauss-Newton with numeric
Jacobians on the residual of src/backend/pose_graph_costs.hpp, without robust kernels: fine
for a few hundred keyframes, not a replacement for the C++ one.
"""
import sys

import numpy as np
import scipy.sparse as sparse
import scipy.sparse.linalg as sparse_linalg
from scipy.spatial.transform import Rotation

G2O_TO_OURS = [3, 4, 5, 0, 1, 2]  # g2o orders the information [t; r], the residual is [r; t]


def pose34(row):
    T = np.eye(4)
    T[:3] = np.asarray(row).reshape(3, 4)
    return T


def velodyne_from_camera(seq):
    for line in open(seq + "/calib.txt"):
        if line.startswith("Tr:"):
            return pose34([float(v) for v in line.split()[1:]])
    return np.eye(4)


def ground_truth_lidar(seq):
    Tr = velodyne_from_camera(seq)
    Tr_inv = np.linalg.inv(Tr)
    return [Tr_inv @ pose34(r) @ Tr for r in np.loadtxt(seq + "/poses.txt")]


def keyframe_frames(run):
    """Keyframe -> frame: the frame whose (optimized) pose is the keyframe's."""
    frames = np.loadtxt(run + "/poses_kitti.txt")
    out, f = [], 0
    for k in np.loadtxt(run + "/keyframes_kitti.txt"):
        while np.abs(frames[f] - k).max() > 1e-6:
            f += 1
        out.append(f)
        f += 1
    return out


def read_g2o(run):
    """Nodes {id: 4x4} and edges [from, to, Z (4x4), information (ours), is_loop]."""
    nodes, edges = {}, []
    for line in open(run + "/graph.g2o"):
        t = line.split()
        if not t:
            continue
        if t[0] == "VERTEX_SE3:QUAT":
            v = np.array(t[2:], float)
            T = np.eye(4)
            T[:3, 3], T[:3, :3] = v[:3], Rotation.from_quat(v[3:7]).as_matrix()
            nodes[int(t[1])] = T
        elif t[0] == "EDGE_SE3:QUAT":
            a, b, v = int(t[1]), int(t[2]), np.array(t[3:], float)
            Z = np.eye(4)
            Z[:3, 3], Z[:3, :3] = v[:3], Rotation.from_quat(v[3:7]).as_matrix()
            info, k = np.zeros((6, 6)), 7
            for i in range(6):
                for j in range(i, 6):
                    info[i, j] = info[j, i] = v[k]
                    k += 1
            edges.append([a, b, Z, info[np.ix_(G2O_TO_OURS, G2O_TO_OURS)], abs(a - b) != 1])
    return nodes, edges


def residual(Ta, Tb, Z):
    E = np.linalg.inv(Z) @ np.linalg.inv(Ta) @ Tb
    return np.concatenate([Rotation.from_matrix(E[:3, :3]).as_rotvec(), E[:3, 3]])


def plus(T, d):  # the pose graph's right perturbation, tangent [dt; dtheta]
    out = T.copy()
    out[:3, 3] = T[:3, 3] + d[:3]
    out[:3, :3] = T[:3, :3] @ Rotation.from_rotvec(d[3:]).as_matrix()
    return out


def ate(X, G):
    pe, pg = np.array([x[:3, 3] for x in X]), np.array([g[:3, 3] for g in G])
    me, mg = pe.mean(0), pg.mean(0)
    U, _, Vt = np.linalg.svd((pe - me).T @ (pg - mg))
    D = np.eye(3)
    D[2, 2] = np.sign(np.linalg.det(Vt.T @ U.T))
    R = Vt.T @ D @ U.T
    return float(np.sqrt((((pe - me) @ R.T - (pg - mg)) ** 2).sum(1).mean()))


def solve(edges, n, iterations=10, h=1e-6):
    X = [np.eye(4)]  # start from the odometry chain, node 0 fixed
    for a, b, Z, _, is_loop in edges:
        if not is_loop:
            X.append(X[-1] @ Z)
    for _ in range(iterations):
        rows, cols, vals, g = [], [], [], np.zeros(6 * n)
        for a, b, Z, info, _ in edges:
            r = residual(X[a], X[b], Z)
            J = np.zeros((6, 12))
            for k in range(6):
                d = np.zeros(6)
                d[k] = h
                J[:, k] = (residual(plus(X[a], d), X[b], Z) - r) / h
                J[:, 6 + k] = (residual(X[a], plus(X[b], d), Z) - r) / h
            idx = np.r_[6 * a:6 * a + 6, 6 * b:6 * b + 6]
            H = J.T @ info @ J
            rows += list(np.repeat(idx, 12))
            cols += list(np.tile(idx, 12))
            vals += list(H.ravel())
            g[idx] += J.T @ info @ r
        H = sparse.coo_matrix((vals, (rows, cols)), shape=(6 * n, 6 * n)).tocsc()
        dx = np.zeros(6 * n)
        dx[6:] = sparse_linalg.spsolve(H[6:, 6:], -g[6:])
        X = [plus(X[i], dx[6 * i:6 * i + 6]) for i in range(n)]
        if np.abs(dx).max() < 1e-8:
            break
    return X


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("chi2", "oracle"):
        sys.exit(__doc__)
    what, run, seq = sys.argv[1:]
    gt_frames = ground_truth_lidar(seq)
    kf = keyframe_frames(run)
    nodes, edges = read_g2o(run)
    G0_inv = np.linalg.inv(gt_frames[kf[0]])
    G = [G0_inv @ gt_frames[kf[i]] for i in range(len(nodes))]
    true_edge = lambda a, b: np.linalg.inv(G[a]) @ G[b]

    if what == "chi2":
        chi2, rot, tra = [], [], []
        for a, b, Z, info, is_loop in edges:
            if not is_loop:
                continue
            e = residual(np.eye(4), true_edge(a, b), Z)
            chi2.append(e @ info @ e)
            rot.append(np.linalg.norm(e[:3]))
            tra.append(np.linalg.norm(e[3:]))
        chi2 = np.array(chi2)
        print("%d loop edges: chi2/6 mean %.1f median %.1f p90 %.1f; error median %.2e rad %.4f m, "
              "p90 %.2e rad %.4f m, max %.2e rad %.4f m (a false loop shows here)"
              % (len(chi2), chi2.mean() / 6, np.median(chi2) / 6, np.percentile(chi2, 90) / 6,
                 np.median(rot), np.median(tra), np.percentile(rot, 90), np.percentile(tra, 90),
                 np.max(rot), np.max(tra)))
        return

    def fixed(rot_sigma, t_sigma):
        return np.diag([rot_sigma ** -2] * 3 + [t_sigma ** -2] * 3)

    variants = [
        ("as run", False, None),
        ("true loops, as run's information", True, None),
        ("measured loops, tight (2e-4 rad, 1 cm)", False, fixed(2e-4, 0.01)),
        ("true loops, tight (2e-4 rad, 1 cm)", True, fixed(2e-4, 0.01)),
        ("true loops, tight translation only (0.05 rad, 1 cm)", True, fixed(0.05, 0.01)),
        ("true loops, tight rotation only (2e-4 rad, 0.1 m)", True, fixed(2e-4, 0.1)),
    ]
    chain = solve([e for e in edges if not e[4]], len(nodes), iterations=0)
    print("odometry chain alone: keyframe ATE %.4f m" % ate(chain, G))
    for name, true_loops, info in variants:
        variant = []
        for a, b, Z, edge_info, is_loop in edges:
            if is_loop:
                Z = true_edge(a, b) if true_loops else Z
                edge_info = info if info is not None else edge_info
            variant.append([a, b, Z, edge_info, is_loop])
        print("%-55s keyframe ATE %.4f m" % (name, ate(solve(variant, len(nodes)), G)))


if __name__ == "__main__":
    main()
