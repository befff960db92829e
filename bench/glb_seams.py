"""Total UV-seam length of a GLB (first mesh primitive): edges whose two triangles use
different UVs at a shared (welded) position. Used by bench/conformal_bench.sh to compare
against `fieldtex atlas` output. Usage: python3 bench/glb_seams.py model.glb"""
import json, math, struct, sys
from collections import defaultdict

def read(path):
    d = open(path, "rb").read()
    jl = struct.unpack_from("<I", d, 12)[0]
    js = json.loads(d[20:20 + jl])
    bin_off = 20 + jl + 8
    def acc(i):
        a = js["accessors"][i]
        bv = js["bufferViews"][a["bufferView"]]
        off = bin_off + bv.get("byteOffset", 0) + a.get("byteOffset", 0)
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
        fmt = {5126: "f", 5125: "I", 5123: "H", 5121: "B"}[a["componentType"]]
        vals = struct.unpack_from("<" + fmt * (n * a["count"]), d, off)
        return [vals[k * n:(k + 1) * n] for k in range(a["count"])]
    p = js["meshes"][0]["primitives"][0]
    pos = acc(p["attributes"]["POSITION"])
    uv = acc(p["attributes"]["TEXCOORD_0"])
    idx = [i[0] for i in acc(p["indices"])]
    return pos, uv, idx

def seam_length(path):
    pos, uv, idx = read(path)
    weld = {}
    wid = [weld.setdefault(tuple(round(c, 6) for c in q), len(weld)) for q in pos]
    edges = defaultdict(list)
    for t in range(0, len(idx), 3):
        tri = idx[t:t + 3]
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            wa, wb = wid[a], wid[b]
            key = (min(wa, wb), max(wa, wb))
            ua, ub = (a, b) if wa < wb else (b, a)
            edges[key].append((tuple(round(c, 7) for c in uv[ua]), tuple(round(c, 7) for c in uv[ub]), ua, ub))
    total, n = 0.0, 0
    for key, lst in edges.items():
        if len(lst) == 2 and (lst[0][0] != lst[1][0] or lst[0][1] != lst[1][1]):
            pa, pb = pos[lst[0][2]], pos[lst[0][3]]
            total += math.dist(pa, pb)
            n += 1
    return total, n

if __name__ == "__main__":
    total, n = seam_length(sys.argv[1])
    print(f"{total} {n}")
