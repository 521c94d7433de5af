#!/usr/bin/env python3
"""Writes the hand-made seeds of fuzz/corpus/gltf_load/ (files named seed-*): small valid .gltf
(embedded base64 buffers) and .glb files covering what the loader reads, and a few broken ones.
The other corpus files are the fuzzer's own discoveries (cmin-minimised). Re-run after changing
this script: python3 fuzz/make_seeds.py (from the repository root)."""

import base64
import json
import math
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "gltf_load")

FLOAT, U8, U16, U32, I8, I16 = 5126, 5121, 5123, 5125, 5120, 5122
FMT = {FLOAT: "f", U8: "B", U16: "H", U32: "I", I8: "b", I16: "h"}
TRIANGLES, STRIP, FAN, POINTS, LINES = 4, 5, 6, 0, 1

TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
QUAD = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
CUBE = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
CUBE_TRIS = [0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
             2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5]


def png(width, height, rgba):
    """A PNG of 8-bit RGBA texels (rows from the top), written by hand (no imaging library)."""
    import zlib

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    rows = b"".join(b"\0" + bytes(rgba[4 * width * y:4 * width * (y + 1)]) for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows))
            + chunk(b"IEND", b""))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


CHECKER = png(2, 2, [255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255])


class Doc:
    """A glTF document under construction with one buffer."""

    def __init__(self):
        self.j = {"asset": {"version": "2.0", "generator": "fovea make_seeds.py"}}
        self.bin = bytearray()

    def _list(self, key):
        return self.j.setdefault(key, [])

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        self.bin += data
        self._list("bufferViews").append(view)
        return len(self.j["bufferViews"]) - 1

    def accessor(self, values, ctype, kind, normalized=False, minmax=False):
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[kind]
        flat = [c for v in values for c in (v if width > 1 else (v,))]
        data = struct.pack("<%d%s" % (len(flat), FMT[ctype]), *flat)
        acc = {"bufferView": self.view(data), "componentType": ctype,
               "count": len(values), "type": kind}
        if normalized:
            acc["normalized"] = True
        if minmax or kind == "VEC3":
            acc["min"] = [min(v[k] for v in values) for k in range(3)]
            acc["max"] = [max(v[k] for v in values) for k in range(3)]
        self._list("accessors").append(acc)
        return len(self.j["accessors"]) - 1

    def positions(self, points):
        return self.accessor(points, FLOAT, "VEC3")

    def indices(self, idx, ctype=U32):
        return self.accessor(idx, ctype, "SCALAR")

    def mesh(self, primitives, name=None):
        mesh = {"primitives": primitives}
        if name:
            mesh["name"] = name
        self._list("meshes").append(mesh)
        return len(self.j["meshes"]) - 1

    def prim(self, pos, idx=None, mode=TRIANGLES, material=None):
        p = {"attributes": {"POSITION": pos}, "mode": mode}
        if idx is not None:
            p["indices"] = idx
        if material is not None:
            p["material"] = material
        return p

    def node(self, **fields):
        self._list("nodes").append(fields)
        return len(self.j["nodes"]) - 1

    def scene(self, roots):
        self.j["scenes"] = [{"nodes": roots}]
        self.j["scene"] = 0

    def material(self, **pbr_and_more):
        self._list("materials").append(pbr_and_more)
        return len(self.j["materials"]) - 1

    def gltf(self):
        j = dict(self.j)
        if self.bin:
            uri = "data:application/octet-stream;base64," + base64.b64encode(self.bin).decode()
            j["buffers"] = [{"byteLength": len(self.bin), "uri": uri}]
        return json.dumps(j, indent=1).encode()

    def glb(self):
        j = dict(self.j)
        if self.bin:
            j["buffers"] = [{"byteLength": len(self.bin)}]
        text = json.dumps(j, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
        if self.bin:
            data = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
            chunks += struct.pack("<II", len(data), 0x004E4942) + data
        return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def one_mesh(points, idx=None, mode=TRIANGLES, ctype=U32):
    d = Doc()
    pos = d.positions(points)
    i = d.indices(idx, ctype) if idx is not None else None
    d.mesh([d.prim(pos, i, mode)], name="thing")
    d.scene([d.node(mesh=0)])
    return d


def seeds():
    yield "triangle-indexed", one_mesh(TRI, [0, 1, 2])
    yield "triangle-nonindexed", one_mesh(TRI)
    yield "quad-u8-indices", one_mesh(QUAD, [0, 1, 2, 0, 2, 3], ctype=U8)
    yield "cube-u16-indices", one_mesh(CUBE, CUBE_TRIS, ctype=U16)
    yield "strip-indexed", one_mesh(QUAD, [0, 1, 3, 2], STRIP)
    yield "strip-restart", one_mesh(QUAD + QUAD, [0, 1, 3, 3, 4, 4, 5, 7, 6], STRIP)
    yield "fan-indexed", one_mesh(QUAD, [0, 1, 2, 3], FAN)
    yield "fan-nonindexed", one_mesh(QUAD, None, FAN)

    d = Doc()  # points, lines and triangles in one mesh
    pos = d.positions(QUAD)
    d.mesh([d.prim(pos, None, POINTS), d.prim(pos, d.indices([0, 1, 1, 2]), LINES),
            d.prim(pos, d.indices([0, 1, 2]), TRIANGLES)])
    d.scene([d.node(mesh=0)])
    yield "mixed-modes", d

    d = Doc()  # hierarchy: TRS, matrix, shared mesh, mirrored node, grandchildren
    pos = d.positions(TRI)
    d.mesh([d.prim(pos, d.indices([0, 1, 2]))], name="tri")
    leaf = d.node(mesh=0, scale=[-1, 1, 1], name="mirrored")
    mid = d.node(mesh=0, rotation=[0, 0.7071068, 0, 0.7071068], translation=[0, 2, 0],
                 children=[leaf], name="rotated")
    m = [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 5, 0, -1, 1]
    top = d.node(matrix=m, children=[mid], name="matrix")
    other = d.node(mesh=0, translation=[-3, 0, 0])
    d.scene([top, other])
    yield "hierarchy", d

    d = Doc()  # no scenes: every root node is walked
    pos = d.positions(TRI)
    d.mesh([d.prim(pos)])
    d.node(mesh=0, children=[1])
    d.node(mesh=0, translation=[0, 0, 1])
    d.node(mesh=0, translation=[0, 0, 2])
    yield "no-scene", d

    d = Doc()  # perspective camera on a rotated node, an orthographic one ignored
    pos = d.positions(CUBE)
    d.mesh([d.prim(pos, d.indices(CUBE_TRIS, U16))])
    d.j["cameras"] = [
        {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
        {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}},
    ]
    cams = d.node(children=[d.node(camera=0), d.node(camera=1, translation=[0.5, 0.5, 4])],
                  rotation=[0, 0.0998, 0, 0.995])
    d.scene([d.node(mesh=0), cams])
    yield "cameras", d

    d = Doc()  # camera only, no triangles
    d.j["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.01}}]
    d.scene([d.node(camera=0, translation=[0, 1, 3])])
    yield "camera-only", d

    d = Doc()  # materials: dielectric, metal, mirror, emissive with strength, default
    d.j["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    pos = d.positions(QUAD)
    idx = d.indices([0, 1, 2, 0, 2, 3])
    mats = [
        d.material(pbrMetallicRoughness={"baseColorFactor": [0.8, 0.2, 0.1, 1],
                                         "metallicFactor": 0, "roughnessFactor": 0.5}),
        d.material(pbrMetallicRoughness={"baseColorFactor": [0.9, 0.9, 0.9, 1],
                                         "metallicFactor": 1, "roughnessFactor": 0.2}),
        d.material(pbrMetallicRoughness={"metallicFactor": 1, "roughnessFactor": 0}, name="mirror"),
        d.material(emissiveFactor=[1, 0.9, 0.8],
                   extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 12}}),
        d.material(pbrMetallicRoughness={"baseColorFactor": [1, 1, 1, 0.5]}, alphaMode="BLEND"),
    ]
    d.mesh([d.prim(pos, idx, material=m) for m in mats] + [d.prim(pos, idx)])
    d.scene([d.node(mesh=0)])
    yield "materials", d

    d = Doc()  # KHR_mesh_quantization: normalized i16 positions, u8 positions
    d.j["extensionsUsed"] = d.j["extensionsRequired"] = ["KHR_mesh_quantization"]
    q = d.accessor([(0, 0, 0), (32767, 0, 0), (0, -32767, 100)], I16, "VEC3", normalized=True)
    b = d.accessor([(0, 0, 0), (255, 0, 0), (0, 255, 9)], U8, "VEC3")
    d.mesh([d.prim(q), d.prim(b, d.indices([0, 2, 1], U8))])
    d.scene([d.node(mesh=0, scale=[1, 1, 0.01])])
    yield "quantized", d

    d = Doc()  # sparse accessors: over a buffer view, and over implicit zeros
    base = d.positions(QUAD)
    sparse_idx = d.view(struct.pack("<2H", 1, 3))
    sparse_val = d.view(struct.pack("<6f", 2, 0, 0, 0, 2, 0))
    acc = dict(d.j["accessors"][base])
    acc["sparse"] = {"count": 2, "indices": {"bufferView": sparse_idx, "componentType": U16},
                     "values": {"bufferView": sparse_val}}
    d.j["accessors"].append(acc)
    zeros = {"componentType": FLOAT, "count": 4, "type": "VEC3", "min": [0, 0, 0],
             "max": [2, 2, 0], "sparse": acc["sparse"]}
    d.j["accessors"].append(zeros)
    idx = d.indices([0, 1, 2, 0, 2, 3], U8)
    d.mesh([d.prim(len(d.j["accessors"]) - 3, idx), d.prim(len(d.j["accessors"]) - 2, idx)])
    d.scene([d.node(mesh=0)])
    yield "sparse", d

    d = Doc()  # interleaved vertices: a 24-byte stride with a second attribute
    inter = b"".join(struct.pack("<6f", *p, 0, 0, 1) for p in QUAD)
    v = d.view(inter, stride=24)
    d.j["accessors"] = [
        {"bufferView": v, "componentType": FLOAT, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": v, "byteOffset": 12, "componentType": FLOAT, "count": 4, "type": "VEC3"},
    ]
    p = d.prim(0, d.indices([0, 1, 2, 2, 3, 0], U16))
    p["attributes"]["NORMAL"] = 1
    d.mesh([p])
    d.scene([d.node(mesh=0)])
    yield "interleaved", d

    d = Doc()  # a texture (data: URI PNG) and ignored content: animation, unknown extension
    d.j["extensionsUsed"] = ["EXT_example"]
    pos = d.positions(TRI)
    d.mesh([d.prim(pos, d.indices([0, 1, 2]), material=0)])
    d.j["images"] = [{"uri": data_uri("image/png", CHECKER)}]
    d.j["samplers"] = [{}]
    d.j["textures"] = [{"source": 0, "sampler": 0}]
    d.material(pbrMetallicRoughness={"baseColorTexture": {"index": 0}})
    times = d.accessor([0.0, 1.0], FLOAT, "SCALAR", minmax=False)
    d.j["accessors"][times].update({"min": [0.0], "max": [1.0]})
    moves = d.accessor([(0, 0, 0), (1, 0, 0)], FLOAT, "VEC3")
    d.j["animations"] = [{"samplers": [{"input": times, "output": moves}],
                          "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}]
    d.scene([d.node(mesh=0)])
    yield "ignored-features", d

    d = Doc()  # textures in the binary buffer, texture coordinates, every slot, a transform
    d.j["extensionsUsed"] = ["KHR_texture_transform"]
    pos = d.positions(QUAD)
    prim = d.prim(pos, d.indices([0, 1, 2, 2, 3, 0], U16), material=0)
    prim["attributes"]["TEXCOORD_0"] = d.accessor([(0, 0), (1, 0), (1, 1), (0, 1)], FLOAT, "VEC2",
                                                  minmax=False)
    prim["attributes"]["NORMAL"] = d.accessor([(0, 0, 1)] * 4, FLOAT, "VEC3")
    d.mesh([prim])
    d.j["images"] = [{"bufferView": d.view(CHECKER), "mimeType": "image/png"}]
    d.j["samplers"] = [{"magFilter": 9728, "minFilter": 9729, "wrapS": 33071, "wrapT": 33648}]
    d.j["textures"] = [{"source": 0, "sampler": 0}]
    d.material(pbrMetallicRoughness={
        "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
            "offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2]}}},
        "metallicRoughnessTexture": {"index": 0}},
        emissiveTexture={"index": 0}, emissiveFactor=[1, 1, 1],
        normalTexture={"index": 0, "scale": 0.5})
    d.scene([d.node(mesh=0)])
    yield "textures", d

    d = Doc()  # a grid: more vertices, two primitives sharing one vertex array
    grid = [(x, y, math.sin(x + y) * 0.2) for y in range(6) for x in range(6)]
    tris = []
    for y in range(5):
        for x in range(5):
            a = y * 6 + x
            tris += [a, a + 1, a + 7, a, a + 7, a + 6]
    pos = d.positions(grid)
    d.mesh([d.prim(pos, d.indices(tris[:60], U16)), d.prim(pos, d.indices(tris[60:], U16))])
    d.scene([d.node(mesh=0), d.node(mesh=0, translation=[0, 0, -2])])
    yield "grid", d


def broken():
    """Inputs the loader must refuse (with a message)."""
    d = one_mesh([(0, 0, 0), (math.nan, 0, 0), (0, 1, 0)], [0, 1, 2])
    d.j["accessors"][0].update({"min": [0, 0, 0], "max": [0, 1, 0]})
    yield "bad-nan-vertex.gltf", d.gltf()
    d = one_mesh(TRI, [0, 1, 5])
    yield "bad-index-out-of-range.gltf", d.gltf()
    d = one_mesh(TRI, [0, 1, 2])
    d.j["nodes"][0]["children"] = [0]
    yield "bad-node-cycle.gltf", d.gltf()
    d = one_mesh(TRI, [0, 1, 2])
    yield "bad-truncated.glb", d.glb()[:-7]
    text = one_mesh(TRI, [0, 1, 2]).gltf()
    yield "bad-external-buffer.gltf", text.replace(
        text[text.index(b'"data:'):text.index(b'"', text.index(b'"data:') + 1) + 1],
        b'"triangle.bin"')
    yield "bad-gltf-1.gltf", b'{"asset": {"version": "1.0"}, "meshes": {"m": {}}}'
    yield "bad-empty.gltf", b""
    d = one_mesh(TRI, [0, 1, 2])
    d.j["accessors"][0]["count"] = 1 << 30
    yield "bad-huge-accessor.glb", d.glb()
    d = one_mesh(TRI, [0, 1, 2])
    d.j["extensionsRequired"] = d.j["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    yield "bad-draco-required.gltf", d.gltf()
    d = one_mesh(TRI, [0, 1, 2])
    d.j["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    d.j["meshes"][0]["primitives"][0]["material"] = 0
    d.material(emissiveFactor=[1e30, 1, 1],
               extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 1e30}})
    yield "bad-emission-overflow.gltf", d.gltf()
    d = one_mesh([(0, 0, 0), (3e38, 0, 0), (-3e38, 1, 0)], [0, 1, 2])
    yield "bad-coordinates-near-f32-max.glb", d.glb()
    for name, uri in [
        ("bad-truncated-image.gltf", "data:image/png;base64,iVBORw0KGgo="),  # the magic alone
        ("bad-image-type.gltf", data_uri("image/gif", b"GIF89a\x01\x00\x01\x00\x00\x00\x00;")),
        ("bad-missing-image.gltf", "missing.png"),
    ]:
        d = one_mesh(TRI, [0, 1, 2])
        d.j["meshes"][0]["primitives"][0]["material"] = 0
        d.j["images"] = [{"uri": uri}]
        d.j["textures"] = [{"source": 0}]
        d.material(pbrMetallicRoughness={"baseColorTexture": {"index": 0}})
        yield name, d.gltf()
    d = one_mesh(TRI, [0, 1, 2])
    d.j["nodes"][0]["scale"] = [1e30, 1e30, 1e30]
    yield "bad-node-scale-overflow.gltf", d.gltf()


def main():
    os.makedirs(OUT, exist_ok=True)
    for name in os.listdir(OUT):
        if name.startswith("seed-"):
            os.remove(os.path.join(OUT, name))
    written = 0
    for name, doc in seeds():
        for ext, data in (("gltf", doc.gltf()), ("glb", doc.glb())):
            with open(os.path.join(OUT, "seed-%s.%s" % (name, ext)), "wb") as f:
                f.write(data)
            written += 1
    for name, data in broken():
        with open(os.path.join(OUT, "seed-" + name), "wb") as f:
            f.write(data)
        written += 1
    # The bundled low-resolution bunny: a real exporter's .glb.
    bunny = os.path.join(os.path.dirname(OUT), "..", "..", "assets", "bunny-low.glb")
    with open(bunny, "rb") as src, open(os.path.join(OUT, "seed-bunny-low.glb"), "wb") as dst:
        dst.write(src.read())
    written += 1
    print("wrote %d seeds to %s" % (written, OUT))


if __name__ == "__main__":
    main()
