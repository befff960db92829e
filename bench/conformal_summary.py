"""Prints one mesh's numbers for bench/conformal_bench.sh (reads the report.json files)."""
import json, os, statistics, sys

m, out, walls = sys.argv[1], sys.argv[2], [float(w) for w in sys.argv[3:]]
r = json.load(open(os.path.join(out, m, "report.json")))
n = json.load(open(os.path.join(out, m + "-nomulti", "report.json")))
met = r["metrics"]
print(f"== {m}: wall median {statistics.median(walls):.2f} s over {len(walls)} run(s)")
for stage, ms in r["timings_ms"]:
    print(f"   {stage:18s} {ms / 1000:7.2f} s")
for c in met["components"]:
    d = c.get("distortion", {})
    print(f"   component {c['component']}: genus {c['genus']} boundaries {c['boundaries']} method {c['method']} "
          f"zero points {c['zero_points']} patches {c['patches']} flips {d.get('flipped')} "
          f"angle(away) {d.get('angle_mean_away_from_singularities')} log-area std {d.get('log_area_std')} "
          f"conj.res {c.get('conjugate_residual')} (wedge system {c.get('conjugate_residual_wedge_system')})")
rf = met.get("refinement")
if rf:
    print(f"   refinement: {rf['levels']} level(s), {rf['triangles_in']} -> {rf['triangles']} triangles; "
          f"angle(away) per level {rf['angle_mean_away_by_level']}, unmapped share per level {rf.get('unmapped_area_share_by_level')}")
fs, fn = met["feature_size"], n["metrics"]["feature_size"]
if fs and fn:
    print(f"   feature-size CV multiscale {fs['cv']:.3f}  no-multiscale {fn['cv']:.3f}  ratio {fs['cv'] / fn['cv']:.2f} (target <= 0.5)")
    fc, fnc = met.get("feature_size_centre_lambda"), n["metrics"].get("feature_size_centre_lambda")
    if fc and fnc:
        print(f"   (centre-triangle λ, the measure of sessions 10-12: {fc['cv']:.3f} / {fnc['cv']:.3f} = {fc['cv'] / fnc['cv']:.2f})")
    fw, fnw = met.get("feature_size_fixed_window"), n["metrics"].get("feature_size_fixed_window")
    if fw and fnw:
        print(f"   (fixed 24-texel window: {fw['cv']:.3f} / {fnw['cv']:.3f} = {fw['cv'] / fnw['cv']:.2f}; adaptive windows saturated {fs.get('saturated')})")
    # The no-multiscale texture is statistically uniform in texel space, so its CV in
    # texels is the estimator's own spread (the floor a perfectly uniform result would
    # still show on the surface); the part above it is what the conformal factor adds.
    floor = fn["cv_texels"]
    ex = lambda cv: max(cv * cv - floor * floor, 0.0) ** 0.5
    if ex(fn["cv"]) > 0:
        print(f"   estimator floor (no-multiscale CV in texels) {floor:.3f}; excess over it multiscale {ex(fs['cv']):.3f} "
              f"no-multiscale {ex(fn['cv']):.3f} ratio {ex(fs['cv']) / ex(fn['cv']):.2f}")
s = met["seams"]
atlas_path = os.path.join(out, m + "-atlas", "model.glb")
sys.path.insert(0, os.path.dirname(__file__))
from glb_seams import seam_length
al, an = seam_length(atlas_path)
ol, on = seam_length(os.path.join(out, m, "model.glb"))
print(f"   seams: {s['seam_edges']} edges, length {s['seam_length']:.4g} (from the GLB: {ol:.4g}); fieldtex atlas {al:.4g} ({an} edges); "
      f"ratio {ol / al:.3f} (target <= 0.25); colour jump ratio {s['ratio']:.2f} (target <= 1.5)")
print(f"   texel density CV {met['texel_density']['density_cv']:.3f}")
qi = os.path.join(out, m + "-qi", "report.json")
if os.path.exists(qi):
    q = json.load(open(qi))
    for c in q["metrics"].get("mass_spring", []):
        st = c["stats"]
        print(f"   mass-spring comp {c['component']}: angle {st['before']['angle_mean']:.3f} -> {st['after']['angle_mean']:.3f}, "
              f"log-area std {st['before']['log_area_std']:.3f} -> {st['after']['log_area_std']:.3f}, flips {st['after']['flipped']}, "
              f"iterations {st['iterations']}")
    for stage, ms in q["timings_ms"]:
        if stage == "mass-spring":
            print(f"   mass-spring time {ms / 1000:.2f} s (target < 5 s)")
