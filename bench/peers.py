"""Benchmark peers for fieldtex, measured on the same inputs as the Rust benchmarks.

Prints one line per measurement, `BENCH <name> median_ms=<x>` or `BENCH <name> value=<x>`,
the same format as the Rust bench binaries, so bench/run.sh can print ratios.
Peers: libigl (cotan Laplacian + mass), CHOLMOD via scikit-sparse (penalty system
factorisation), xatlas (atlas on the bunny, and the atlas size sweep).

`--atlas-sweep NAME=MESH ...` runs only the xatlas size sweep: for each mesh, the median
time of `xatlas.Atlas.generate` (3 runs below 50K triangles, 1 above) and its mean CPU
time (all threads; compare with `atlas_NAME_cpu` when the machine is loaded) with the padding
and resolution of our defaults (4 texels, 1024), its chart count, and its packing
efficiency (UV triangle area over the atlas rectangle, the definition of
`AtlasStats::packing_efficiency`), as `peer_xatlas_atlas_NAME*` lines.
"""
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"


def median_ms(f, runs):
    ts = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        ts.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(ts)


def emit(name, key, value):
    print(f"BENCH {name} {key}={value:.6g}", flush=True)


def penalty_vertices(n):
    # Every 50th vertex: 2 % of the vertices, the same rule as the Rust bench.
    return np.arange(0, n, 50)


def bench_igl_cholmod(quick):
    import igl

    v, f = igl.read_triangle_mesh(str(DATA / "meshes" / "horse.ply"))
    v, f = igl.upsample(v, f)  # 1 -> 4 subdivision, ~388K triangles
    print(f"# refined horse: {v.shape[0]} vertices, {f.shape[0]} triangles", flush=True)

    def lap_mass():
        igl.cotmatrix(v, f)
        igl.massmatrix(v, f, igl.MASSMATRIX_TYPE_VORONOI)

    emit("peer_igl_cotan_mass_388k", "median_ms", median_ms(lap_mass, 3 if quick else 5))
    try:
        from sksparse.cholmod import cholesky
    except ImportError:
        print("# CHOLMOD peer missing (scikit-sparse not installed)", flush=True)
        return
    l = -igl.cotmatrix(v, f)
    n = l.shape[0]
    p = np.zeros(n)
    p[penalty_vertices(n)] = 1e8
    a = sp.csc_matrix(l + sp.diags(p))
    emit("peer_cholmod_factor_388k", "median_ms", median_ms(lambda: cholesky(a), 3 if quick else 5))


def angle_distortion(v3, f3, uv, fuv):
    """Area-weighted mean and 95th percentile of sigma1/sigma2 per triangle."""
    p0, p1, p2 = v3[f3[:, 0]], v3[f3[:, 1]], v3[f3[:, 2]]
    e1 = p1 - p0
    e2 = p2 - p0
    area3 = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    x = e1 / np.maximum(np.linalg.norm(e1, axis=1, keepdims=True), 1e-300)
    nrm = np.cross(e1, e2)
    y = np.cross(nrm, x)
    y /= np.maximum(np.linalg.norm(y, axis=1, keepdims=True), 1e-300)
    a = np.stack([np.einsum("ij,ij->i", e1, x), np.einsum("ij,ij->i", e1, y)], 1)
    b = np.stack([np.einsum("ij,ij->i", e2, x), np.einsum("ij,ij->i", e2, y)], 1)
    q0, q1, q2 = uv[fuv[:, 0]], uv[fuv[:, 1]], uv[fuv[:, 2]]
    du1 = q1 - q0
    du2 = q2 - q0
    s = np.zeros(len(f3))
    for i in range(len(f3)):
        m3 = np.array([[a[i, 0], b[i, 0]], [a[i, 1], b[i, 1]]])
        m2 = np.array([[du1[i, 0], du2[i, 0]], [du1[i, 1], du2[i, 1]]])
        try:
            j = m2 @ np.linalg.inv(m3)
            sv = np.linalg.svd(j, compute_uv=False)
            s[i] = sv[0] / max(sv[1], 1e-300)
        except np.linalg.LinAlgError:
            s[i] = np.inf
    ok = np.isfinite(s) & (area3 > 0)
    w = area3[ok]
    mean = float(np.sum(s[ok] * w) / np.sum(w))
    order = np.argsort(s[ok])
    cw = np.cumsum(w[order]) / np.sum(w)
    p95 = float(s[ok][order][np.searchsorted(cw, 0.95)])
    return mean, p95


def bench_xatlas(quick):
    import igl
    import xatlas

    v, f = igl.read_triangle_mesh(str(DATA / "meshes" / "stanford-bunny.obj"))
    t0 = time.perf_counter()
    vmap, idx, uvs = xatlas.parametrize(v, f)
    ms = (time.perf_counter() - t0) * 1e3
    emit("peer_xatlas_bunny", "median_ms", ms)
    d1 = uvs[idx[:, 1]] - uvs[idx[:, 0]]
    d2 = uvs[idx[:, 2]] - uvs[idx[:, 0]]
    uv_area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    lo = uvs.min(0)
    hi = uvs.max(0)
    emit("peer_xatlas_bunny_packing", "value", float(uv_area.sum() / np.prod(hi - lo)))
    f3 = vmap[idx]
    mean, p95 = angle_distortion(v, f3, uvs, idx)
    emit("peer_xatlas_bunny_angle_mean", "value", mean)
    emit("peer_xatlas_bunny_angle_p95", "value", p95)


def bench_xatlas_sweep(specs, quick):
    import igl
    import xatlas

    for spec in specs:
        name, path = spec.split("=", 1)
        v, f = igl.read_triangle_mesh(path)
        runs = 1 if quick or len(f) > 50_000 else 3
        ts = []
        cpu = []
        atlas = None
        for _ in range(runs):
            atlas = xatlas.Atlas()
            atlas.add_mesh(v, f)
            po = xatlas.PackOptions()
            po.padding = 4
            po.resolution = 1024
            t0 = time.perf_counter()
            c0 = time.process_time()
            atlas.generate(pack_options=po)
            ts.append((time.perf_counter() - t0) * 1e3)
            cpu.append((time.process_time() - c0) * 1e3)
        vmap, idx, uvs = atlas[0]
        d1 = uvs[idx[:, 1]] - uvs[idx[:, 0]]
        d2 = uvs[idx[:, 2]] - uvs[idx[:, 0]]
        # UVs are normalised by the atlas width and height: area over the rectangle.
        eff = float(0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum())
        print(f"# xatlas {name}: {len(f)} triangles, {atlas.width}x{atlas.height}, "
              f"{atlas.atlas_count} atlas(es)", flush=True)
        emit(f"peer_xatlas_atlas_{name}", "median_ms", statistics.median(ts))
        emit(f"peer_xatlas_atlas_{name}_cpu", "value", statistics.mean(cpu))
        emit(f"peer_xatlas_atlas_{name}_charts", "value", atlas.chart_count)
        emit(f"peer_xatlas_atlas_{name}_packing", "value", eff / max(atlas.atlas_count, 1))


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    if "--atlas-sweep" in sys.argv:
        k = sys.argv.index("--atlas-sweep")
        bench_xatlas_sweep([a for a in sys.argv[k + 1:] if "=" in a], quick)
        sys.exit(0)
    bench_igl_cholmod(quick)
    if "--no-xatlas" not in sys.argv:
        bench_xatlas(quick)
