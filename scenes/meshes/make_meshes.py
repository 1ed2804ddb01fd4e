"""Writes the example meshes in this folder: a pear-like body of revolution as OBJ and as
glTF (embedded base64 buffer). Units: metres, z up, centred on the origin. Run from here."""
import base64, json, math, struct

def pear(rings=24, around=32):
    verts, tris = [], []
    # Profile radius along z (height 0.09 m): a broad base and a narrower neck.
    def radius(t):
        return 0.032 * math.sin(math.pi * t) ** 0.8 * (1.0 - 0.35 * t)
    verts.append((0.0, 0.0, -0.045))
    for i in range(1, rings):
        t = i / rings
        r, z = radius(t), -0.045 + 0.09 * t
        for j in range(around):
            a = 2 * math.pi * j / around
            verts.append((r * math.cos(a), r * math.sin(a), z))
    verts.append((0.0, 0.0, 0.045))
    ring = lambda i, j: 1 + (i - 1) * around + j % around
    last = len(verts) - 1
    for j in range(around):
        tris.append((0, ring(1, j + 1), ring(1, j)))
        tris.append((last, ring(rings - 1, j), ring(rings - 1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(around):
            tris.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)))
            tris.append((ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)))
    return verts, tris

verts, tris = pear()
with open("pear.obj", "w") as f:
    f.write("# pear-like body of revolution, metres (make_meshes.py)\n")
    for v in verts:
        f.write("v %.6f %.6f %.6f\n" % v)
    for t in tris:
        f.write("f %d %d %d\n" % tuple(i + 1 for i in t))

pos = b"".join(struct.pack("<3f", *v) for v in verts)
idx = b"".join(struct.pack("<3I", *t) for t in tris)
lo = [min(v[k] for v in verts) for k in range(3)]
hi = [max(v[k] for v in verts) for k in range(3)]
doc = {
    "asset": {"version": "2.0", "generator": "tactex make_meshes.py"},
    "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": len(pos) + len(idx), "uri": "data:application/octet-stream;base64," + base64.b64encode(pos + idx).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                    {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx), "target": 34963}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi},
                  {"bufferView": 1, "componentType": 5125, "count": 3 * len(tris), "type": "SCALAR"}],
}
with open("pear.gltf", "w") as f:
    json.dump(doc, f)
