#!/usr/bin/python3
"""The speed/accuracy trade, measured: radiosity bakes at a sweep of settings and the path tracer at a sweep of
samples per texel, all scored against one converged path-traced reference on the same texels.

    /usr/bin/python3 bench/tradeoff.py        # full sweep, writes docs/tradeoff.md + .png
    /usr/bin/python3 bench/tradeoff.py --quick  # a smaller sweep (same converged references)

Converged references are computed once per scene and density and reused (16,384 spp on the Cornell box at
64 texels/m: ≈ 4.5 min; 8,192 spp at 133 texels/m: ≈ 10 min; the generated level at 4 texels/m, 4,096 spp).

Every bake of one scene uses the same lightmap layout (same --texels-per-unit, so the unwrap is identical), so
`hemibake compare` scores it texel for texel against the reference computed once on that layout. Wall time and
peak memory come from GNU time around each process. Needs python3-matplotlib for the plot (the table is written
without it).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd, quiet=True):
    """Runs cmd under GNU time; returns (wall seconds, peak RSS MiB, stdout)."""
    start = time.monotonic()
    proc = subprocess.run(["/usr/bin/time", "-f", "%M"] + cmd, capture_output=True, text=True)
    wall = time.monotonic() - start
    if proc.returncode != 0:
        sys.exit("failed: " + " ".join(cmd) + "\n" + proc.stderr[-2000:])
    peak_kib = int(proc.stderr.strip().splitlines()[-1])
    return wall, peak_kib / 1024.0, proc.stdout


def compare_json(binary, a, b):
    """`hemibake compare A B --json` (B the reference), parsed."""
    _, _, out = run([binary, "compare", a, b, "--json"])
    return json.loads(out)


def compare(binary, a, b):
    g = compare_json(binary, a, b)["global"]
    return {k: g[k] for k in ("meanRelativeError", "meanSignedRelativeError", "p95RelativeError", "rmse")}


def time_to_reach(points, target):
    """Log-log interpolation of the first crossing of `target` along (time, error) points sorted by time."""
    pts = sorted(points)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 > target >= e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return pts[0][0] if pts and pts[0][1] <= target else None


def sweep_scene(binary, work, scene, texels_per_unit, reference_spp, bakes, spps):
    name = os.path.splitext(os.path.basename(scene))[0]
    base = os.path.join(work, name if texels_per_unit == 64 else f"{name}-{texels_per_unit}")
    os.makedirs(base, exist_ok=True)
    density = ["--texels-per-unit", str(texels_per_unit)]
    rows = []

    # The layout (any bake at this density) and the converged reference on its texels.
    layout = os.path.join(base, "layout")
    if not os.path.exists(os.path.join(layout, "bake.json")):
        run([binary, "bake", scene, "-o", layout, "--preset", "draft"] + density)
    reference = os.path.join(base, "reference")
    previous = os.path.join(reference, "reference.json")
    if os.path.exists(previous) and json.load(open(previous)).get("spp") == reference_spp:
        # Re-runs reuse the converged reference (it is the expensive part); delete the folder to recompute it.
        ref_json = json.load(open(previous))
        ref_wall = ref_json.get("seconds", float("nan"))
    else:
        print(f"[{name}] reference at {reference_spp} spp ...", flush=True)
        ref_wall, _, out = run([binary, "reference", "--texels", layout, "-o", reference, "--spp", str(reference_spp), "--json"])
        ref_json = json.loads(out)
    texel_count = ref_json.get("texels", None)

    for label, family, args in bakes:
        out_dir = os.path.join(base, "bake-" + label)
        # No preview render: the path tracer's texel mode renders no picture either (≈ 0.3 s at 640 px).
        wall, mem, _ = run([binary, "bake", scene, "-o", out_dir, "--no-preview"] + density + args)
        report = json.load(open(os.path.join(out_dir, "bake.json")))
        err = compare(binary, out_dir, reference)
        rows.append({"method": "radiosity", "family": family, "label": label, "args": " ".join(args), "seconds": wall,
                     "peakMiB": mem, "shots": report.get("convergence", {}).get("shots"),
                     "patches": report.get("counts", {}).get("patches"), **err})
        print(f"[{name}] bake {label:24s} {wall:7.1f} s {100 * err['meanRelativeError']:6.2f} %", flush=True)
        shutil.rmtree(out_dir, ignore_errors=True)

    for spp in spps:
        out_dir = os.path.join(base, f"pt-{spp}")
        # A different seed from the reference's, so the two estimates are independent.
        wall, mem, _ = run([binary, "reference", "--texels", layout, "-o", out_dir, "--spp", str(spp), "--seed", "7"])
        err = compare(binary, out_dir, reference)
        rows.append({"method": "path tracer", "family": "path tracer", "label": f"{spp} spp", "args": f"--spp {spp}",
                     "seconds": wall, "peakMiB": mem, **err})
        print(f"[{name}] path tracer {spp:6d} spp {wall:7.1f} s {100 * err['meanRelativeError']:6.2f} %", flush=True)
        shutil.rmtree(out_dir, ignore_errors=True)
    return {"scene": name, "texelsPerUnit": texels_per_unit, "texels": texel_count, "referenceSpp": reference_spp,
            "referenceSeconds": ref_wall, "rows": rows}


def pyplot():
    """matplotlib.pyplot on the file-only backend, or None (with a note) when python3-matplotlib is missing."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError:
        print("python3-matplotlib not installed: no plot", file=sys.stderr)
        return None


def label_axes(ax, ylabel, title):
    """The error-against-time axes both benchmarks draw: wall time on x, a log grid, a small legend."""
    ax.set_xlabel("wall time, s (2 cores)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)


def plot(results, path):
    plt = pyplot()
    if plt is None:
        return False
    fig, axes = plt.subplots(1, len(results), figsize=(6.5 * len(results), 5), squeeze=False)
    for ax, res in zip(axes[0], results):
        families = {}
        for r in res["rows"]:
            families.setdefault(r["family"], []).append(r)
        for family, rows in families.items():
            rows.sort(key=lambda r: r["seconds"])
            style = "k-o" if family == "path tracer" else "-s"
            ax.loglog([r["seconds"] for r in rows], [100 * r["meanRelativeError"] for r in rows], style, label=family)
            for r in rows:
                ax.annotate(r["label"], (r["seconds"], 100 * r["meanRelativeError"]), fontsize=6,
                            textcoords="offset points", xytext=(3, 3))
        ax.axhline(2.0, color="grey", lw=0.8, ls="--")
        label_axes(ax, "mean relative error vs reference, %",
                   f"{res['scene']}, {res['texelsPerUnit']}/m: {res['texels']} texels, ref {res['referenceSpp']} spp")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


def write_markdown(results, path, png_name, quick):
    lines = ["# Speed vs accuracy, measured", "",
             "Written by `/usr/bin/python3 bench/tradeoff.py" + (" --quick" if quick else "") + "` (do not edit by hand). Every "
             "row is one process on this 2-core machine (llvmpipe, Embree), scored by `hemibake compare` against a "
             "path-traced reference on exactly the same texels (E/π, CONVENTIONS.md). Mean relative error is "
             "|a−b|/max(|b|, 1 % of the mean) averaged over texels and channels; the reference's own noise is part "
             "of every number (it is the floor the curves flatten towards).", ""]
    if os.path.exists(os.path.join(os.path.dirname(path), png_name)):
        lines += [f"![error vs time]({png_name})", ""]
    for res in results:
        pt = [(r["seconds"], r["meanRelativeError"]) for r in res["rows"] if r["method"] == "path tracer"]
        bakes = [r for r in res["rows"] if r["method"] == "radiosity"]
        lines += [f"## {res['scene']} at {res['texelsPerUnit']} texels/m", "",
                  f"{res['texels']} texels at {res['texelsPerUnit']} texels/m; reference {res['referenceSpp']} spp "
                  f"({res['referenceSeconds']:.0f} s).", "",
                  "| method | setting | time (s) | peak MiB | mean rel | mean signed | p95 rel |", "|---|---|---|---|---|---|---|"]
        for r in res["rows"]:
            lines.append(f"| {r['method']} ({r['family']}) | {r['label']} `{r['args']}` | {r['seconds']:.1f} | {r['peakMiB']:.0f} | "
                         f"{100 * r['meanRelativeError']:.2f} % | {100 * r['meanSignedRelativeError']:+.2f} % | "
                         f"{100 * r['p95RelativeError']:.1f} % |")
        lines.append("")
        for target in (0.05, 0.03, 0.02, 0.01):
            t_pt = time_to_reach(pt, target)
            ok = [r for r in bakes if r["meanRelativeError"] <= target]
            best = min(ok, key=lambda r: r["seconds"]) if ok else None
            pt_text = f"{t_pt:.1f} s" if t_pt else "not reached"
            bake_text = f"{best['seconds']:.1f} s ({best['label']})" if best else "not reached"
            ratio = f", path tracer / bake = {t_pt / best['seconds']:.2f}×" if (t_pt and best) else ""
            lines.append(f"- {100 * target:.0f} % mean relative error: path tracer {pt_text}, fastest bake {bake_text}{ratio}.")
        lines.append("")
    notes = os.path.join(ROOT, "bench", "tradeoff_notes.md")  # hand-written reading of the numbers
    if os.path.exists(notes):
        lines += [open(notes).read().rstrip()]
    # bench/levels.py keeps its own section in this file: carry it over.
    old = open(path).read() if os.path.exists(path) else ""
    begin = old.find("<!-- bench/levels.py")
    if begin >= 0:
        lines += ["", old[begin:].rstrip()]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "hemibake"))
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "tradeoff"))
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--skip-level", action="store_true", help="no generated level")
    ap.add_argument("--skip-default-density", action="store_true", help="Cornell box at 64 texels/m only")
    a = ap.parse_args()

    cornell = os.path.join(ROOT, "examples", "cornell_box.gltf")
    level = os.path.join(ROOT, "examples", "level_small.gltf")
    presets = [(p, "presets", ["--preset", p]) for p in (["draft", "medium"] if a.quick else ["draft", "medium", "high", "ultra"])]
    medium = lambda family, label, args: (label, "medium, " + family, ["--preset", "medium"] + args)
    knobs = [medium("hemicube R", f"R={r}", ["--hemicube-res", str(r)]) for r in ([32, 128] if a.quick else [32, 128, 256])]
    knobs += [medium("unshot bound", f"eps={e}", ["--epsilon", e]) for e in (["3e-2"] if a.quick else ["3e-2", "1e-3"])]
    knobs += [medium("patch size", f"patch x{f}", ["--patch-size", s]) for f, s in ([("2", "0.24")] if a.quick else [("2", "0.24"), ("0.5", "0.06")])]
    knobs += [medium("shadow rays", f"{n} rays", ["--emitter-samples", str(n)]) for n in ([64] if a.quick else [64, 1024])]
    knobs += [medium("texels", "lattice 8", ["--lattice", "8"]), medium("texels", "lattice 1", ["--lattice", "1"]),
              medium("texels", "interpolate", ["--texel-mode", "interpolate"])]
    # Emitters shooting through hemicubes like every other patch (every preset before rays did the direct light).
    knobs += [medium("emitters", "emitters by hemicube", ["--emitters", "hemicube"]),
              medium("emitters", "hemicube, R=128, eps 1e-3, near field", ["--emitters", "hemicube", "--hemicube-res", "128",
                                                                            "--epsilon", "1e-3", "--proximity", "2"])]
    spps = [16, 64, 256, 1024] if a.quick else [16, 64, 256, 1024, 4096]

    os.makedirs(a.work, exist_ok=True)
    # The benchmark density (64 texels/m) keeps the converged reference affordable; the medium preset's own
    # density (128 texels along the diagonal, ≈ 133/m here) is where users bake, and the path tracer's cost
    # grows with the texel count while the bake's hardly does.
    results = [sweep_scene(a.binary, a.work, cornell, 64, 16384, presets + knobs, spps)]
    if not a.skip_default_density:
        results.append(sweep_scene(a.binary, a.work, cornell, 133, 8192, [(p, "presets", ["--preset", p]) for p in ["draft", "medium"]],
                                   [64, 256, 1024] if a.quick else [64, 256, 1024, 4096]))
    if not a.skip_level and os.path.exists(level):
        level_bakes = [(p, "presets", ["--preset", p]) for p in ["draft", "medium"]]
        results.append(sweep_scene(a.binary, a.work, level, 4, 1024 if a.quick else 4096, level_bakes,
                                   [16, 64, 256] if a.quick else [16, 64, 256, 1024]))
    json.dump(results, open(os.path.join(a.work, "tradeoff.json"), "w"), indent=1)
    png = "tradeoff.png"
    plot(results, os.path.join(a.docs, png))
    write_markdown(results, os.path.join(a.docs, "tradeoff.md"), png, a.quick)
    print("wrote", os.path.join(a.docs, "tradeoff.md"))


if __name__ == "__main__":
    main()
