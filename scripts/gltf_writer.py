"""glTF 2.0 files (.gltf + .bin, or .glb) for the scene scripts (make-mug, make-teapot,
make-scenes): meshes, materials with the Khronos glass extensions, a node tree. What
shrefract-bake reads from them: docs/bake.md "glTF input".

Positions are float32. `off_mesh` reads an OFF file the scripts wrote and rounds each number
straight from its text to the nearest float32, as the C library's strtof does when OpenMesh reads
that file: so a glTF made from an OFF holds bit for bit the positions the OFF loads as (through a
double first, a value near a float32 midpoint could round twice).

Only the Python standard library; deterministic output.
"""
import json
import math
import struct
from fractions import Fraction

GLASS_EXTENSIONS = ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"]


def _bits(x):
    return struct.unpack("<I", struct.pack("<f", x))[0]


def _from_bits(b):
    return struct.unpack("<f", struct.pack("<I", b))[0]


def float32(text):
    """The float32 nearest the decimal `text`, ties to even."""
    exact = Fraction(text)
    if exact == 0:
        return 0.0
    guess = _from_bits(_bits(float(text)))
    b = _bits(guess)
    # The answer is the guess or one of its neighbours (same sign: never 0 for these values).
    neighbours = [n for n in (b - 1, b + 1) if (n & 0x7FFFFFFF) < 0x7F800000 and (n >> 31) == (b >> 31)]
    candidates = [guess] + [_from_bits(n) for n in neighbours]
    return min(candidates, key=lambda c: (abs(Fraction(c) - exact), _bits(c) & 1))


def off_mesh(path):
    """Vertices (float32 values) and triangles of a triangle OFF file."""
    tokens = open(path).read().split()
    nv, nf = int(tokens[1]), int(tokens[2])
    v = [tuple(float32(t) for t in tokens[4 + 3 * i:7 + 3 * i]) for i in range(nv)]
    p, f = 4 + 3 * nv, []
    for _ in range(nf):
        assert tokens[p] == "3", "triangles only"
        f.append(tuple(int(t) for t in tokens[p + 1:p + 4]))
        p += 4
    return v, f


def vertex_normals(v, f):
    """Area-weighted vertex normals (unit), as a modeller exports smooth shading."""
    acc = [[0.0, 0.0, 0.0] for _ in v]
    for a, b, c in f:
        ab = [v[b][i] - v[a][i] for i in range(3)]
        ac = [v[c][i] - v[a][i] for i in range(3)]
        n = (ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0])
        for i in (a, b, c):
            for k in range(3):
                acc[i][k] += n[k]
    out = []
    for n in acc:
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        out.append(tuple(x / length for x in n))
    return out


class Gltf:
    def __init__(self, generator, extensions=GLASS_EXTENSIONS):
        self.doc = {"asset": {"generator": generator, "version": "2.0"}}
        if extensions:
            self.doc["extensionsUsed"] = list(extensions)
        self.bin = bytearray()

    def _add(self, key, item):
        self.doc.setdefault(key, []).append(item)
        return len(self.doc[key]) - 1

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin += b"\0"
        view = {"buffer": 0, "byteLength": len(data), "byteOffset": len(self.bin), "target": target}
        self.bin += data
        return self._add("bufferViews", view)

    def _vec3(self, values, with_bounds):
        data = b"".join(struct.pack("<3f", *p) for p in values)
        acc = {"bufferView": self._view(data, 34962), "componentType": 5126, "count": len(values),
               "type": "VEC3"}
        if with_bounds:  # required for POSITION; float32 values print exactly as doubles
            acc["max"] = [max(_from_bits(_bits(p[k])) for p in values) for k in range(3)]
            acc["min"] = [min(_from_bits(_bits(p[k])) for p in values) for k in range(3)]
        return self._add("accessors", acc)

    def glass(self, name, ior=None, kappa=None, color=(1.0, 1.0, 1.0), extras=None):
        """A transmissive material. kappa: absorption per unit length per RGB channel, written as
        attenuationDistance 1 and attenuationColor exp(-kappa) (the reader takes -ln(c) / d)."""
        ext = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}
        if ior is not None:
            ext["KHR_materials_ior"] = {"ior": ior}
        if kappa is not None:
            ext["KHR_materials_volume"] = {"thicknessFactor": 1.0, "attenuationDistance": 1.0,
                                           "attenuationColor": [math.exp(-k) for k in kappa]}
        mat = {"doubleSided": False, "extensions": ext, "name": name,
               "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0],
                                        "metallicFactor": 0.0, "roughnessFactor": 0.0}}
        if extras:
            mat["extras"] = extras
        return self._add("materials", mat)

    def opaque(self, name, color, metallic, roughness):
        return self._add("materials", {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(color) + [1.0], "metallicFactor": metallic,
            "roughnessFactor": roughness}})

    def mesh(self, name, v, f, material, normals=None, uvs=None):
        """One TRIANGLES primitive; indices as unsigned short when they fit, as exporters do."""
        attributes = {"POSITION": self._vec3(v, True)}
        if normals is not None:
            attributes["NORMAL"] = self._vec3(normals, False)
        if uvs is not None:
            data = b"".join(struct.pack("<2f", *t) for t in uvs)
            attributes["TEXCOORD_0"] = self._add("accessors", {
                "bufferView": self._view(data, 34962), "componentType": 5126, "count": len(uvs),
                "type": "VEC2"})
        short = len(v) <= 65536
        flat = [i for t in f for i in t]
        data = struct.pack("<%d%s" % (len(flat), "H" if short else "I"), *flat)
        indices = self._add("accessors", {"bufferView": self._view(data, 34963),
                                          "componentType": 5123 if short else 5125,
                                          "count": len(flat), "type": "SCALAR"})
        return self._add("meshes", {"name": name, "primitives": [
            {"attributes": attributes, "indices": indices, "material": material}]})

    def node(self, name, mesh=None, children=(), translation=None, rotation=None, scale=None,
             extras=None):
        node = {}
        if children:
            node["children"] = list(children)
        if extras:
            node["extras"] = extras
        if mesh is not None:
            node["mesh"] = mesh
        node["name"] = name
        for key, value in (("rotation", rotation), ("scale", scale), ("translation", translation)):
            if value is not None:
                node[key] = list(value)
        return self._add("nodes", node)

    def scene(self, roots, name="Scene"):
        self.doc["scene"] = 0
        self.doc["scenes"] = [{"name": name, "nodes": list(roots)}]

    def _finish(self, uri):
        while len(self.bin) % 4:
            self.bin += b"\0"
        buffer = {"byteLength": len(self.bin)}
        if uri:
            buffer["uri"] = uri
        self.doc["buffers"] = [buffer]

    def write_gltf(self, path, bin_path):
        """JSON beside an external .bin (Blender's "glTF Separate")."""
        import os
        self._finish(os.path.basename(bin_path))
        with open(path, "w", newline="\n") as out:
            json.dump(self.doc, out, indent=2)
            out.write("\n")
        with open(bin_path, "wb") as out:
            out.write(bytes(self.bin))

    def write_glb(self, path):
        """One binary file: header, JSON chunk (space-padded), BIN chunk (zero-padded)."""
        self._finish(None)
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        total = 12 + 8 + len(text) + 8 + len(self.bin)
        with open(path, "wb") as out:
            out.write(struct.pack("<4sII", b"glTF", 2, total))
            out.write(struct.pack("<I4s", len(text), b"JSON") + text)
            out.write(struct.pack("<I4s", len(self.bin), b"BIN\0") + bytes(self.bin))
