#!/usr/bin/env python3
"""Ray casting: agrisim's analytic BVH caster next to Open3D's RaycastingScene (Embree).

A benchmark script, not a test. It runs the Rust example `raycast_bench`, which generates the
greenhouse, casts LiDAR-like rays (single thread) and writes the scene as .glb plus the rays
and its hit distances as .npy; then it loads the .glb mesh into Open3D, casts the same rays
and prints both rates, their ratio and how well the hit distances agree. The mesh is a
tessellation (inscribed polygons: 16-gon cylinders, 16 x 8 UV spheres), so distances differ
by up to a few millimetres on curved objects, and rays grazing a silhouette may hit the
analytic shape but miss the mesh (or the reverse).

Needs numpy, pygltflib and open3d (Open3D 0.20 also needs Debian's libusb-1.0-0), e.g.:
    python3 -m venv .venv-bench && .venv-bench/bin/pip install open3d numpy pygltflib
    .venv-bench/bin/python python/bench_raycast.py [--rays N] [--config FILE] [--out DIR] [--no-run]

With --lidar-pattern the rays are the LiDAR's own (the MID-360 pattern from the Rust example
`pattern_rays` of agrisim-fmu-lidar, cast in packets as the FMU casts them).
With --camera the rays are the RGB-D camera's depth rays instead (one per pixel centre of
1280x720 D435i frames in the middle aisle, from the Rust example `depth_rays` of
agrisim-fmu-camera; --rays is then ignored, --poses sets the number of frames).
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_glb(path):
    """(vertices float32 N x 3, triangles uint32 M x 3) in the scene's z-up map frame, with
    every node transform applied (the root node rotates z-up into glTF's y-up; we undo it by
    applying the full node hierarchy, then rotating y-up back to z-up)."""
    from pygltflib import GLTF2

    g = GLTF2().load(path)
    blob = g.binary_blob()

    def accessor(i, comps):
        a = g.accessors[i]
        bv = g.bufferViews[a.bufferView]
        dtype = {5126: np.float32, 5125: np.uint32}[a.componentType]
        off = (bv.byteOffset or 0) + (a.byteOffset or 0)
        return np.frombuffer(blob, dtype=dtype, count=a.count * comps, offset=off).reshape(-1, comps)

    def local_matrix(n):
        if n.matrix:
            return np.array(n.matrix, dtype=np.float64).reshape(4, 4).T
        m = np.eye(4)
        x, y, z, w = n.rotation or [0, 0, 0, 1]
        m[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
        m[:3, :3] *= np.array(n.scale or [1, 1, 1])[None, :]
        m[:3, 3] = n.translation or [0, 0, 0]
        return m

    verts, tris, base = [], [], 0
    # glTF y-up -> map z-up: +90 deg about x.
    y_up_to_z_up = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]], dtype=np.float64)

    def walk(ni, parent):
        nonlocal base
        n = g.nodes[ni]
        m = parent @ local_matrix(n)
        if n.mesh is not None:
            for p in g.meshes[n.mesh].primitives:
                v = accessor(p.attributes.POSITION, 3).astype(np.float64)
                v = (np.c_[v, np.ones(len(v))] @ m.T)[:, :3]
                t = accessor(p.indices, 1).reshape(-1, 3).astype(np.uint32)
                verts.append(v)
                tris.append(t + base)
                base += len(v)
        for c in n.children or []:
            walk(c, m)

    for ni in g.scenes[g.scene or 0].nodes:
        walk(ni, y_up_to_z_up)
    return np.concatenate(verts).astype(np.float32), np.concatenate(tris).astype(np.uint32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rays", type=int, default=2_000_000)
    ap.add_argument("--config", help="greenhouse TOML (the keys of [greenhouse]); default: the paper's setup")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench_raycast"))
    ap.add_argument("--no-run", action="store_true", help="reuse the files of a previous Rust run")
    ap.add_argument("--camera", action="store_true", help="the camera's depth rays (1280x720 frames) instead of LiDAR rays")
    ap.add_argument("--poses", type=int, default=2, help="with --camera: frames of rays")
    ap.add_argument("--lidar-pattern", action="store_true",
                    help="the LiDAR's own scan pattern (MID-360, 12 frames from each of 8 spots) instead of random LiDAR-like rays")
    args = ap.parse_args()

    if not args.no_run and args.lidar_pattern:
        cmd = ["cargo", "run", "--release", "-q", "-p", "agrisim-fmu-lidar", "--example", "pattern_rays", "--", "--out", args.out]
        print("$", " ".join(cmd), flush=True)
        subprocess.run(cmd, cwd=ROOT, check=True)
    elif not args.no_run and args.camera:
        cmd = ["cargo", "run", "--release", "-q", "-p", "agrisim-fmu-camera", "--example", "depth_rays", "--",
               "--poses", str(args.poses), "--out", args.out]
        print("$", " ".join(cmd), flush=True)
        subprocess.run(cmd, cwd=ROOT, check=True)
    elif not args.no_run:
        cmd = ["cargo", "run", "--release", "-q", "-p", "agrisim-raycast", "--example", "raycast_bench", "--",
               "--rays", str(args.rays), "--out", args.out]
        if args.config:
            cmd += ["--config", args.config]
        print("$", " ".join(cmd), flush=True)
        subprocess.run(cmd, cwd=ROOT, check=True)

    import open3d as o3d

    rust = json.load(open(os.path.join(args.out, "rust.json")))
    rays = np.load(os.path.join(args.out, "rays.npy"))
    dist = np.load(os.path.join(args.out, "dist.npy"))
    lo, hi = rust["min_range"], rust["max_range"]

    t = time.perf_counter()
    v, f = load_glb(os.path.join(args.out, "scene.glb"))
    t_load = time.perf_counter() - t
    t = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene(nthreads=1)
    scene.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))
    rt = o3d.core.Tensor(rays)
    scene.cast_rays(rt[:1000], nthreads=1)  # builds the BVH lazily: keep it out of the timing
    t_build = time.perf_counter() - t

    timings = {}
    for nthreads in (1, 0):
        best = None
        for _ in range(2):
            t = time.perf_counter()
            ans = scene.cast_rays(rt, nthreads=nthreads)
            s = time.perf_counter() - t
            best = s if best is None else min(best, s)
        timings[nthreads] = best
    t_hit = ans["t_hit"].numpy().astype(np.float64)
    o3d_dist = np.where((t_hit >= lo) & (t_hit <= hi), t_hit, np.inf)

    n = len(rays)
    o3d_1 = n / timings[1]
    o3d_all = n / timings[0]
    both = np.isfinite(dist) & np.isfinite(o3d_dist)
    d = np.abs(dist[both] - o3d_dist[both])
    same_hit_miss = np.mean(np.isfinite(dist) == np.isfinite(o3d_dist))
    print(f"scene              {rust['objects']} objects -> {len(f)} triangles (glb load {t_load:.2f} s, Embree build {t_build:.2f} s)")
    print(f"rays               {n}")
    print(f"agrisim (analytic) {rust['rays_per_s']:.3e} rays/s, 1 thread")
    print(f"Open3D (Embree)    {o3d_1:.3e} rays/s, 1 thread;  {o3d_all:.3e} rays/s, {os.cpu_count()} threads")
    print(f"ratio agrisim / Open3D, 1 thread: {rust['rays_per_s'] / o3d_1:.2f}")
    if "single_ray_rays_per_s" in rust:
        print(f"  (rays go in packets as the sensor casts them; as single rays agrisim casts "
              f"{rust['single_ray_rays_per_s']:.3e} rays/s: ratio {rust['single_ray_rays_per_s'] / o3d_1:.2f})")
    print(f"hit/miss agreement {100 * same_hit_miss:.3f} % of rays")
    print(f"|distance diff| where both hit ({both.sum()} rays): median {np.median(d) * 1e3:.3f} mm, "
          f"p95 {np.percentile(d, 95) * 1e3:.2f} mm, p99 {np.percentile(d, 99) * 1e3:.1f} mm, max {d.max():.3f} m")
    print(f"within 1 mm {100 * np.mean(d < 1e-3):.2f} %, within 1 cm {100 * np.mean(d < 1e-2):.2f} %")
    json.dump({
        "rays": n, "agrisim_rays_per_s": rust["rays_per_s"], "open3d_rays_per_s_1thread": o3d_1,
        "open3d_rays_per_s_all_threads": o3d_all, "ratio_1thread": rust["rays_per_s"] / o3d_1,
        "agrisim_single_ray_rays_per_s": rust.get("single_ray_rays_per_s"),
        "hit_miss_agreement": float(same_hit_miss), "median_abs_diff_m": float(np.median(d)),
        "p99_abs_diff_m": float(np.percentile(d, 99)), "within_1cm": float(np.mean(d < 1e-2)),
        "triangles": int(len(f)),
    }, open(os.path.join(args.out, "compare.json"), "w"), indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
