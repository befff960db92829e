# Used by bench/results/transfer_fidelity_masked.txt: python3 bench/transfer_mask_below.py SOURCE.obj SOURCE.png MASK.png 0.5
# Mask of the known-answer source texture: white texels for triangles whose centroid's
# normalised height (y) is below H (an incomplete source, paper B Fig. 8).
import struct, zlib, sys
obj, png, out, H = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
with open(png, 'rb') as f:
    head = f.read(24)
w, h = struct.unpack('>II', head[16:24])
V, T, F = [], [], []
for line in open(obj):
    p = line.split()
    if not p: continue
    if p[0] == 'v': V.append(tuple(map(float, p[1:4])))
    elif p[0] == 'vt': T.append(tuple(map(float, p[1:3])))
    elif p[0] == 'f':
        F.append([tuple(int(x) for x in c.split('/')[:2]) for c in p[1:4]])
ys = [v[1] for v in V]; lo, hi = min(ys), max(ys)
mask = bytearray(w * h)
n = 0
for f in F:
    cy = sum(V[c[0]-1][1] for c in f) / 3
    if (cy - lo) / (hi - lo) < H:
        u, v = T[f[0][1]-1]
        x = min(int(u * w), w - 1); y = min(int((1 - v) * h), h - 1)
        mask[y * w + x] = 255; n += 1
raw = b''.join(b'\x00' + bytes(mask[r*w:(r+1)*w]) for r in range(h))
def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
with open(out, 'wb') as f:
    f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 0, 0, 0, 0)) + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
print(f'{w}x{h} mask, {n} of {len(F)} triangles masked')
