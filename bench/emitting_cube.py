#!/usr/bin/python3
"""The emitting cube against the Cornell box (issue 16): a closed 2 m cube of 12 triangles, every face emitting
L_e = 1 W·m⁻²·sr⁻¹ inwards with ρ = 0.9 (an emitter-heavy scene: every element emits, and light bounces ~10 times
before it is absorbed), baked at a preset next to examples/cornell_box.gltf. Inside a closed furnace every texel's
E/π is L_e/(1 − ρ) = 10 exactly, so the script also reports the cube's worst texel against that.

    /usr/bin/python3 bench/emitting_cube.py                  # default preset, both scenes, one run each
    /usr/bin/python3 bench/emitting_cube.py --preset high --runs 3

Time is the `hemibake bake` child's wall clock (best of --runs), peak memory its maximum resident set.
"""
import argparse
import base64
import json
import os
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tradeoff import ROOT, run  # noqa: E402  (one way of timing a child for every benchmark)

REFLECTANCE = 0.9
EMITTED_RADIANCE = 1.0


def write_cube(path, half_m=1.0):
    """A closed cube, faces wound and normalled inwards, one emissive material."""
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = -sign
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(positions)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign * half_m, a * half_m, b * half_m
                positions.append(p)
                normals.append(n)
            # (u, v, axis) is right-handed, so the quad's winding faces +axis; flip it where inwards is −axis.
            indices += [base, base + 1, base + 2, base, base + 2, base + 3] if sign < 0 else \
                [base, base + 2, base + 1, base, base + 3, base + 2]
    pb = b"".join(struct.pack("<3f", *p) for p in positions)
    nb = b"".join(struct.pack("<3f", *n) for n in normals)
    ib = b"".join(struct.pack("<H", i) for i in indices)
    data = pb + nb + ib
    gltf = {
        "asset": {"version": "2.0", "generator": "hemibake bench/emitting_cube.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "emitting_cube"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"name": "furnace", "emissiveFactor": [EMITTED_RADIANCE] * 3,
                       "pbrMetallicRoughness": {"baseColorFactor": [REFLECTANCE] * 3 + [1.0], "metallicFactor": 0.0}}],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pb)},
                        {"buffer": 0, "byteOffset": len(pb), "byteLength": len(nb)},
                        {"buffer": 0, "byteOffset": len(pb) + len(nb), "byteLength": len(ib)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
                       "min": [-half_m] * 3, "max": [half_m] * 3},
                      {"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5123, "count": len(indices), "type": "SCALAR"}],
    }
    with open(path, "w") as f:
        json.dump(gltf, f)


def worst_texel_error(binary, out_dir, expected):
    """Largest |E/π − expected| / expected over the covered texels (oiiotool reads the EXR; empty texels are 0)."""
    report = json.load(open(os.path.join(out_dir, "bake.json")))
    worst = 0.0
    for atlas in sorted({p["lightmap"] for p in report["primitives"]}):
        out = subprocess.run(["oiiotool", "--dumpdata:empty=0", os.path.join(out_dir, atlas)], capture_output=True,
                             text=True, check=True).stdout
        for line in out.splitlines():
            if ":" not in line or "Pixel" not in line:
                continue
            values = [float(v) for v in line.split(":", 1)[1].split()]
            if values and max(values) > 0.0:  # covered (uncovered texels hold 0)
                worst = max(worst, max(abs(v - expected) / expected for v in values))
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "hemibake"))
    ap.add_argument("--preset", default="medium")
    ap.add_argument("--runs", type=int, default=1)
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="hemibake-emitting-cube-")
    cube = os.path.join(work, "emitting_cube.gltf")
    write_cube(cube)
    rows = []
    for name, scene in (("emitting cube", cube), ("Cornell box", os.path.join(ROOT, "examples", "cornell_box.gltf"))):
        out_dir = os.path.join(work, name.replace(" ", "_"))
        best = None
        for _ in range(max(1, a.runs)):
            wall, mem, _ = run([a.binary, "bake", scene, "-o", out_dir, "--preset", a.preset, "--no-preview"])
            best = (wall, mem) if best is None or wall < best[0] else best
        report = json.load(open(os.path.join(out_dir, "bake.json")))
        conv = report.get("convergence", {})
        rows.append((name, best[0], best[1], conv.get("shots"), conv.get("hemicubes"), conv.get("emittersByRays"),
                     out_dir))
    print(f"preset {a.preset}, best of {a.runs}; work in {work}")
    print("| scene | time (s) | peak MiB | shots | solve hemicubes | emitters by rays |")
    print("|---|---|---|---|---|---|")
    for name, wall, mem, shots, hemicubes, rays, _ in rows:
        print(f"| {name} | {wall:.1f} | {mem:.0f} | {shots} | {hemicubes} | {rays} |")
    expected = EMITTED_RADIANCE / (1.0 - REFLECTANCE)
    print(f"emitting cube: worst texel E/π off L_e/(1 − ρ) = {expected:g} by "
          f"{100 * worst_texel_error(a.binary, rows[0][6], expected):.2f} %")
    ratio = rows[0][1] / rows[1][1]
    print(f"emitting cube / Cornell box time: {ratio:.2f} (issue 16 asks ≤ 1)")


if __name__ == "__main__":
    main()
