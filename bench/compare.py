"""Reads `BENCH <name> <key>=<value>` lines (stdin), prints the target table with
ratios to the peers measured in the same run, and saves them as JSON (argv[1])."""
import json
import sys

vals = {}
for line in sys.stdin:
    parts = line.split()
    # the first `key=value` after the name counts (some lines add e.g. `cpu_value=`)
    if len(parts) >= 3 and parts[0] == "BENCH" and "=" in parts[2]:
        k, v = parts[2].split("=", 1)
        try:
            vals[parts[1]] = float(v)
        except ValueError:
            pass

# (label, ours, peer or None, kind, target) with kind:
#  "ratio<=": ours/peer <= target; "ratio>=": peer/ours >= target (speedup);
#  "value>=" / "value<=": ours alone vs target; "vs_peer>=" / "vs_peer<=": ours vs peer value.
rows = [
    ("cotan L + mass, horse x4 (ms)", "cotan_mass_388k", "peer_igl_cotan_mass_388k", "ratio<=", 0.5),
    ("penalty system factor, symbolic+numeric (ms)", "penalty_factor_388k", "peer_cholmod_factor_388k", "ratio<=", 1.2),
    ("rank-1 update vs refactor (speed-up)", "rank1_update_388k", "penalty_refactor_388k", "ratio>=", 100.0),
    ("atlas, bunny (ms)", "atlas_bunny", "peer_xatlas_bunny", "ratio<=", 0.25),
    ("atlas packing efficiency", "atlas_bunny_packing", "peer_xatlas_bunny_packing", "vs_peer>=", None),
    ("atlas angle distortion mean", "atlas_bunny_angle_mean", "peer_xatlas_bunny_angle_mean", "vs_peer<=", None),
    ("atlas flipped triangles", "atlas_bunny_flips", None, "value<=", 0),
] + [
    row
    for name in ["avocado", "spot", "fandisk", "armadillo", "bunny", "horse", "bunny_x4", "horse_x4"]
    for row in [
        (f"atlas sweep {name} (ms)", f"atlas_sw_{name}", f"peer_xatlas_atlas_sw_{name}", "ratio<=", 0.25),
        (f"atlas sweep {name} CPU (ms)", f"atlas_sw_{name}_cpu", f"peer_xatlas_atlas_sw_{name}_cpu", "ratio<=", 0.25),
        (f"atlas sweep {name} area distortion", f"atlas_sw_{name}_area_distortion", None, "value<=", 1.5),
        (f"atlas sweep {name} charts", f"atlas_sw_{name}_charts", f"peer_xatlas_atlas_sw_{name}_charts", "vs_peer<=", None),
        (f"atlas sweep {name} packing", f"atlas_sw_{name}_packing", f"peer_xatlas_atlas_sw_{name}_packing", "vs_peer>=", None),
        (f"atlas sweep {name} flipped triangles", f"atlas_sw_{name}_flips", None, "value<=", 0),
    ]
] + [
    ("ray casting closest hit (rays/s)", "rays_per_s", None, "value>=", 2e6),
    ("ray casting any hit (rays/s)", "any_hit_rays_per_s", None, "value>=", 2e6),
    ("binary PLY read, 1M triangles (ms)", "ply_read_1m", None, "value<=", 500),
]

out = []
print(f"{'measurement':48} {'ours':>12} {'peer':>12} {'ratio':>8} {'target':>10}  ok")
for label, ours, peer, kind, target in rows:
    o = vals.get(ours)
    p = vals.get(peer) if peer else None
    ratio = None
    ok = None
    if o is not None:
        if kind == "ratio<=" and p:
            ratio = o / p
            ok = ratio <= target
        elif kind == "ratio>=" and p and o > 0:
            ratio = p / o
            ok = ratio >= target
        elif kind == "vs_peer>=" and p is not None:
            ok = o >= p
        elif kind == "vs_peer<=" and p is not None:
            ok = o <= p
        elif kind == "value>=":
            ok = o >= target
        elif kind == "value<=":
            ok = o <= target
    f = lambda x: "-" if x is None else f"{x:.4g}"
    t = "-" if target is None else ("<=" if "<=" in kind else ">=") + f"{target:g}"
    if kind.startswith("vs_peer"):
        t = ("<=" if "<=" in kind else ">=") + "peer"
    mark = {True: "yes", False: "NO", None: "n/a"}[ok]
    print(f"{label:48} {f(o):>12} {f(p):>12} {f(ratio):>8} {t:>10}  {mark}")
    out.append({"measurement": label, "ours": o, "peer": p, "ratio": ratio, "target": t, "ok": ok})

if len(sys.argv) > 1:
    with open(sys.argv[1], "w") as fh:
        json.dump({"rows": out, "raw": vals}, fh, indent=2)
