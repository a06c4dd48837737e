#!/usr/bin/python3
"""Levels, measured (issue 16): generated game levels of about 10k, 100k and 300k triangles baked at every preset,
and the path tracer at several sample counts on the same texels, all scored against one converged path-traced
reference per level. Writes the speed table into docs/performance.md and the error-against-time table and plot
into docs/tradeoff.md (between `<!-- bench/levels.py -->` markers; the rest of those files is left alone).

    /usr/bin/python3 bench/levels.py                          # everything below (hours on 2 cores)
    /usr/bin/python3 bench/levels.py --levels clean:10000     # one level
    /usr/bin/python3 bench/levels.py --levels clean:10000 --presets medium --spp 16 64 256
    /usr/bin/python3 bench/levels.py --levels clean:10000 --variant "medium, R 32=--preset medium --hemicube-res 32"
    /usr/bin/python3 bench/levels.py --speed-only --levels overlapping:10000 overlapping:100000 overlapping:300000 \
        --presets medium --texels-per-unit 4 --work build/levels-speed   # time and memory per texel only

Levels come from examples/generate_level.py (seed 1): `clean:N` builds the layout whose parts meet without
overlapping, `overlapping:N` the one whose walls stand in the slabs as artists build them, `uniform:N` that one with
the same detail per square metre at every size (generate_level.py --uniform: rooms in proportion to N; the default
gives bigger levels more detail per room, so their time per texel grows with the level, not the baker), `tiled:N`
N/10,000 copies of the uniform 10k level side by side, 10 m apart (generate_level.py --tiles): exactly the same
content per square metre, so what its time per texel does is the baker's scaling alone. Every bake of a level
uses the same --texels-per-unit, so the unwrap is identical and `hemibake compare` scores texel for texel.
Per texel, the headline: compare's `relativeRmseAgainstTruth`, the RMS error against the noise-free answer relative
to each primitive's mean, with the reference's own noise taken out through the standard error it carries (a 4,096-spp
reference is itself some % off per texel, more than a good bake; scored plainly, every row would sit on that floor).
The path tracer's rows keep their own noise: it is their error. Where the bake is better than every path-tracer row,
the path tracer's time to reach it is extrapolated along error ∝ 1/√spp and time linear in spp (both fitted to its
two highest-spp rows), and marked so. Also reported: compare's plain mean relative error. Per object: per glTF node,
the texel-weighted mean of the bake over the reference's, minus one (what a user sees as "this room is 3 % dark").
Re-runs resume: finished rows are kept in WORK/levels.json (keyed by level, method and setting) and skipped.
--speed-only bakes and nothing else (no layout, reference or path tracer): time, memory and texels per level, for
sizes whose reference would take hours; it writes the speed table and levels_scaling.png (time and memory per texel
against texels; time per texel by stage and the cost of a ray, from each bake's bake.json), and leaves
docs/tradeoff.md alone.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tradeoff import ROOT, compare_json, label_axes, pyplot, run, time_to_reach  # noqa: E402  (one timing and interpolation for both benchmarks)

MARK_BEGIN = "<!-- bench/levels.py: generated, do not edit by hand -->"
MARK_END = "<!-- end bench/levels.py -->"


def per_object(comparison):
    """Per node: texel-weighted mean of A over B, minus one (channel means averaged)."""
    sums = {}
    for p in comparison["primitives"]:
        e = p["errors"]
        if not e.get("texels"):
            continue
        node = p.get("node", "")
        a = sum(e["meanA"]) / 3.0 * e["texels"]
        b = sum(e["meanB"]) / 3.0 * e["texels"]
        sa, sb = sums.get(node, (0.0, 0.0))
        sums[node] = (sa + a, sb + b)
    errors = {n: sa / sb - 1.0 for n, (sa, sb) in sums.items() if sb > 0.0}
    if not errors:
        return {}
    magnitudes = sorted(abs(v) for v in errors.values())
    return {"objects": len(errors), "objectMedianError": statistics.median(magnitudes),
            "objectWorstError": magnitudes[-1], "objectMeanSignedError": sum(errors.values()) / len(errors)}


def scores(binary, out_dir, reference):
    c = compare_json(binary, out_dir, reference)
    g = c["global"]
    return {"errorAgainstTruth": g.get("relativeRmseAgainstTruth"), "referenceNoise": g.get("referenceNoiseRelativeRms"),
            "meanRelativeError": g["meanRelativeError"], "meanSignedRelativeError": g["meanSignedRelativeError"],
            "p95RelativeError": g["p95RelativeError"], **per_object(c)}


TILE_TRIANGLES = 10000


def tiles_for(triangles):
    """Copies of the uniform 10k level that make a tiled level of about `triangles`."""
    return max(1, round(triangles / TILE_TRIANGLES))


def sweep_level(a, results, kind, triangles):
    name = f"{kind}-{triangles}"
    base = os.path.join(a.work, name)
    os.makedirs(base, exist_ok=True)
    gltf = os.path.join(base, name + ".gltf")
    if not os.path.exists(gltf):
        # tiled:N is N / TILE_TRIANGLES copies of the uniform TILE_TRIANGLES level side by side.
        size = TILE_TRIANGLES if kind == "tiled" else triangles
        subprocess.run([sys.executable, os.path.join(ROOT, "examples", "generate_level.py"), "--seed", "1", "--triangles",
                        str(size), "-o", gltf] + {"clean": ["--clean"], "uniform": ["--uniform"],
                                                 "tiled": ["--uniform", "--tiles", str(tiles_for(triangles))]}.get(kind, []),
                       check=True)
    density = ["--texels-per-unit", str(a.texels_per_unit)]
    level = results.setdefault(name, {"level": name, "kind": kind, "targetTriangles": triangles,
                                      "texelsPerUnit": a.texels_per_unit, "rows": {}})
    save = lambda: json.dump(results, open(os.path.join(a.work, "levels.json"), "w"), indent=1)
    if a.speed_only:
        bake_rows(a, level, name, gltf, density, None, save)
        return

    # The layout is the draft bake: its row is recorded like every other bake's (bake_row), so it is not baked twice.
    layout = os.path.join(base, "layout")
    if not os.path.exists(os.path.join(layout, "bake.json")):
        print(f"[{name}] layout (draft bake) ...", flush=True)
        wall, mem, _ = run([a.binary, "bake", gltf, "-o", layout, "--preset", "draft", "--no-preview"] + density)
        level["layoutRun"] = {"seconds": wall, "peakMiB": mem}
        save()
    reference = os.path.join(base, "reference")
    if level.get("referenceSpp") != a.reference_spp or not os.path.exists(os.path.join(reference, "reference.json")):
        print(f"[{name}] converged reference at {a.reference_spp} spp ...", flush=True)
        wall, mem, out = run([a.binary, "reference", "--texels", layout, "-o", reference, "--spp", str(a.reference_spp), "--json"])
        ref = json.loads(out)
        level.update({"referenceSpp": a.reference_spp, "referenceSeconds": wall, "texels": ref.get("texels")})
        level["rows"] = {}  # every score was against the old reference
        save()

    # Rows scored before compare knew the reference's noise: scored again where their output was kept.
    for key, row in level["rows"].items():
        if row.get("errorAgainstTruth") is None and row.get("outDir") and os.path.exists(row["outDir"]):
            row.update(scores(a.binary, row["outDir"], reference))
            save()

    bake_rows(a, level, name, gltf, density, reference, save)
    path_tracer_rows(a, level, name, layout, reference, save)


# The stages a bake's time per texel is split into on the scaling plot: the two that trace rays through the whole
# level's BVH, their direct-light passes, and the rest (loading, preparing the solve, the local bound, unwrap, output).
STAGES = (("shooting", "shooting rows"), ("finalGather", "final gather"), ("direct", "direct light (elements, texels)"),
          ("rest", "the rest"))
# The two ray stages: the stage, the row's count of the rays it traced, and its label.
RAY_STAGES = (("shooting", "rowRaysTraced", "shooting rows"), ("finalGather", "gatherRays", "final gather"))


def stage_seconds(report):
    """Wall seconds per stage of STAGES from a bake.json."""
    conv, light = report.get("convergence", {}).get("seconds", {}), report.get("lightmap", {}).get("seconds", {})
    total = (report.get("timings") or {}).get("total", 0.0)
    stages = {"shooting": conv.get("shoot", 0.0), "finalGather": light.get("gather", 0.0),
              "direct": conv.get("direct", 0.0) + light.get("direct", 0.0)}
    stages["rest"] = max(total - sum(stages.values()), 0.0)
    return stages


def row_stages(r):
    """A row's stage seconds: recorded with it, or read from its kept bake.json (rows recorded before they were)."""
    if r.get("stages"):
        return r["stages"]
    path = os.path.join(r["outDir"], "bake.json") if r.get("outDir") else None
    return stage_seconds(json.load(open(path))) if path and os.path.exists(path) else None


def ns_per_ray(stages, r, key, rays):
    """Wall ns a ray of ray stage `key`, whose rays row `r` counts under `rays`; None if it traced none."""
    return 1e9 * stages[key] / r[rays] if r.get(rays) else None


def bake_rows(a, level, name, gltf, density, reference, save):
    """A row per preset and variant: time, memory, what was drawn and traced; scored against `reference` if given."""
    base = os.path.dirname(gltf)
    layout = os.path.join(base, "layout")
    bakes = [(preset, ["--preset", preset] + a.bake_args.split()) for preset in a.presets]
    for variant in a.variant:
        label, _, args = variant.partition("=")
        bakes.append((label, args.split() + a.bake_args.split()))
    for preset, args in bakes:
        key = f"bake {preset}"
        if key in level["rows"]:
            continue
        out_dir = os.path.join(base, "bake-" + preset)
        if args == ["--preset", "draft"] and "layoutRun" in level:
            out_dir, wall, mem = layout, level["layoutRun"]["seconds"], level["layoutRun"]["peakMiB"]
        else:
            print(f"[{name}] bake {' '.join(args)} ...", flush=True)
            wall, mem, _ = run([a.binary, "bake", gltf, "-o", out_dir, "--no-preview"] + args + density)
        report = json.load(open(os.path.join(out_dir, "bake.json")))
        draws = report.get("hemicubeDraws", {})
        row = {"method": "bake", "setting": preset, "args": " ".join(args), "seconds": wall, "peakMiB": mem,
               "sceneTriangles": draws.get("sceneTriangles"),
               "solveHemicubes": draws.get("solve", {}).get("hemicubes"),
               "solveDrawnFraction": draws.get("solve", {}).get("meanFractionOfScene"),
               "gatherHemicubes": draws.get("finalGather", {}).get("hemicubes"),
               "gatherDrawnFraction": draws.get("finalGather", {}).get("meanFractionOfScene"),
               "gatherRays": report.get("lightmap", {}).get("finalGatherRays", {}).get("traced"),
               "gatherRaysPerTexel": report.get("lightmap", {}).get("finalGatherRays", {}).get("perTexel"),
               "gatherRaysEscaped": report.get("lightmap", {}).get("finalGatherRays", {}).get("escaped"),
               "timings": report.get("timings"), "outDir": out_dir,
               "texels": report.get("lightmap", {}).get("texels"),
               "rowRaysTraced": report.get("convergence", {}).get("rowRaysTraced"),
               "stages": stage_seconds(report),
               "emittersByRays": report.get("convergence", {}).get("emittersByRays"),
               "warnings": report.get("warnings"),
               **(scores(a.binary, out_dir, reference) if reference else {})}
        level["rows"][key] = row
        if not level.get("texels"):
            level["texels"] = row["texels"]
        save()
        error = f", per texel {100 * row['errorAgainstTruth']:.2f} % RMS" if row.get("errorAgainstTruth") else ""
        print(f"[{name}] bake {preset}: {wall:.0f} s, {mem:.0f} MiB{error}", flush=True)
        if not a.keep and out_dir != layout:
            shutil.rmtree(out_dir, ignore_errors=True)


def path_tracer_rows(a, level, name, layout, reference, save):
    """A row per sample count: the path tracer on the layout's texels, scored against the reference."""
    base = os.path.dirname(layout)
    for spp in a.spp:
        key = f"path tracer {spp}"
        if key in level["rows"]:
            continue
        out_dir = os.path.join(base, f"pt-{spp}")
        # A different seed from the reference's, so the two estimates are independent.
        wall, mem, _ = run([a.binary, "reference", "--texels", layout, "-o", out_dir, "--spp", str(spp), "--seed", "7"])
        row = {"method": "path tracer", "setting": f"{spp} spp", "seconds": wall, "peakMiB": mem,
               "outDir": out_dir, **scores(a.binary, out_dir, reference)}
        level["rows"][key] = row
        save()
        print(f"[{name}] path tracer {spp} spp: {wall:.0f} s, per texel {100 * row['errorAgainstTruth']:.2f} % RMS", flush=True)
        if not a.keep:
            shutil.rmtree(out_dir, ignore_errors=True)


def path_tracer_fit(level):
    """(a, t0, c) with error² = a/spp and seconds = t0 + c·spp, fitted to the two highest-spp path-tracer rows."""
    pts = sorted((int(r["setting"].split()[0]), r["seconds"], r["errorAgainstTruth"]) for r in level["rows"].values()
                 if r["method"] == "path tracer" and r.get("errorAgainstTruth"))
    if len(pts) < 2:
        return None
    (s0, t0, e0), (s1, t1, e1) = pts[-2], pts[-1]
    a = 0.5 * (e0 * e0 * s0 + e1 * e1 * s1)
    c = (t1 - t0) / (s1 - s0)
    return a, t1 - c * s1, c


def speedup(level, preset="medium"):
    """(path-tracer time to reach the preset's per-texel error over the preset's bake time, that time, extrapolated?)."""
    bake = level["rows"].get(f"bake {preset}")
    pt = [(r["seconds"], r["errorAgainstTruth"]) for r in level["rows"].values()
          if r["method"] == "path tracer" and r.get("errorAgainstTruth")]
    if not bake or not bake.get("errorAgainstTruth") or len(pt) < 2:
        return None, None, False
    target = bake["errorAgainstTruth"]
    if target < min(e for _, e in pt):
        fit = path_tracer_fit(level)
        if not fit:
            return None, None, False
        a, t0, c = fit
        t = t0 + c * a / (target * target)
        return t / bake["seconds"], t, True
    t = time_to_reach(pt, target)
    return (t / bake["seconds"] if t else None), t, False


def plot(results, path):
    plt = pyplot()
    if plt is None:
        return False
    levels = list(results.values())
    fig, axes = plt.subplots(1, len(levels), figsize=(6 * len(levels), 4.8), squeeze=False)
    for ax, level in zip(axes[0], levels):
        for method, style in (("path tracer", "k-o"), ("bake", "-s")):
            rows = sorted((r for r in level["rows"].values() if r["method"] == method and r.get("errorAgainstTruth")),
                          key=lambda r: r["seconds"])
            if not rows:
                continue
            ax.loglog([r["seconds"] for r in rows], [100 * r["errorAgainstTruth"] for r in rows], style,
                      label="path tracer (spp)" if method == "path tracer" else "bake presets")
            for r in rows:
                ax.annotate(r["setting"], (r["seconds"], 100 * r["errorAgainstTruth"]), fontsize=7,
                            textcoords="offset points", xytext=(3, 3))
        fit = path_tracer_fit(level)
        if fit:  # the path tracer's fitted line, on to the bakes' errors
            a_fit, t0, c = fit
            lows = [r["errorAgainstTruth"] for r in level["rows"].values() if r.get("errorAgainstTruth")]
            spps = [a_fit / (e * e) for e in (max(lows), 0.8 * min(lows))]
            ax.loglog([t0 + c * n for n in spps], [100 * (a_fit / n) ** 0.5 for n in spps], "k:", lw=0.8,
                      label="path tracer, error ∝ 1/√spp")
        label_axes(ax, "per-texel RMS error against the truth, %",
                   f"{level['level']} at {level['texelsPerUnit']}/m: {level.get('texels')} texels")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


def plot_scaling(results, path, preset="medium"):
    """Time and peak memory per texel, and time per element triangle, of the preset's bake against the level's texels
    (log–log), one line per kind of level: flat lines are linear."""
    plt = pyplot()
    if plt is None:
        return False
    points = sorted(({"kind": level.get("kind", "?"), "texels": r.get("texels") or level.get("texels"),
                      "seconds": r["seconds"], "peakMiB": r["peakMiB"], "elements": r.get("sceneTriangles") or 0,
                      "label": level["level"], "stages": row_stages(r), "row": r}
                     for level in results.values() for r in level["rows"].values()
                     if r["method"] == "bake" and r["setting"] == preset and (r.get("texels") or level.get("texels"))),
                    key=lambda p: (p["kind"], p["texels"]))
    if not points:
        return False
    staged = [p for p in points if p["stages"]]
    fig, grid = plt.subplots(2 if staged else 1, 3, figsize=(15, 8.4 if staged else 4.2), squeeze=False)
    axes = list(grid.flat)
    if staged:
        axes[5].axis("off")
    panels = ((lambda p: 1e6 * p["seconds"] / p["texels"], "wall time per texel, µs"),
              (lambda p: 1024.0 * 1024.0 * p["peakMiB"] / p["texels"], "peak memory per texel, bytes"),
              (lambda p: 1e6 * p["seconds"] / p["elements"] if p["elements"] else float("nan"),
               "wall time per element triangle, µs"))
    def finish(ax, ylabel, title):
        ax.set_xlabel("lightmap texels")
        ax.set_ylabel(ylabel)
        ax.set_title(f"{preset} preset{title}", fontsize=9)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)

    if staged:
        # Which stage grows: each stage's wall time per texel; and the two ray stages' wall time per ray traced
        # (the same rays per texel at every size, so any growth there is the cost of a ray, not the amount of work).
        kinds = sorted({p["kind"] for p in staged})
        name = lambda kind, label: label if len(kinds) == 1 else f"{kind}: {label}"
        for key, label in STAGES:
            for kind in kinds:
                mine = [p for p in staged if p["kind"] == kind]
                axes[3].loglog([p["texels"] for p in mine], [1e6 * p["stages"][key] / p["texels"] for p in mine], "-o",
                               label=name(kind, label))
        finish(axes[3], "wall time per texel by stage, µs", ", by stage")
        for key, rays, label in RAY_STAGES:
            for kind in kinds:
                mine = [(p["texels"], ns_per_ray(p["stages"], p["row"], key, rays)) for p in staged if p["kind"] == kind]
                mine = [(x, y) for x, y in mine if y is not None]
                axes[4].semilogx([x for x, _ in mine], [y for _, y in mine], "-o", label=name(kind, label))
                for x, y in mine:
                    axes[4].annotate(f"{y:.0f}", (x, y), fontsize=7, textcoords="offset points", xytext=(3, 3))
        axes[4].set_ylim(bottom=0)
        finish(axes[4], "wall time per ray (2 cores), ns", ", the cost of a ray")
    for ax, (value, ylabel) in zip(axes, panels):
        for kind in sorted({p["kind"] for p in points}):
            mine = [p for p in points if p["kind"] == kind]
            ax.loglog([p["texels"] for p in mine], [value(p) for p in mine], "-s", label=kind)
            for p in mine:
                ax.annotate(p["label"], (p["texels"], value(p)), fontsize=7, textcoords="offset points", xytext=(3, 3))
        finish(ax, ylabel, " (flat or falling = no worse than linear)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


def replace_section(path, body):
    text = open(path).read() if os.path.exists(path) else ""
    section = MARK_BEGIN + "\n" + body.rstrip() + "\n" + MARK_END
    if MARK_BEGIN in text and MARK_END in text:
        head, rest = text.split(MARK_BEGIN, 1)
        text = head + section + rest.split(MARK_END, 1)[1]
    else:
        text = text.rstrip() + "\n\n" + section + "\n"
    with open(path, "w") as f:
        f.write(text)


def pct(v, signed=False):
    return "—" if v is None else (f"{100 * v:+.2f} %" if signed else f"{100 * v:.2f} %")


def write_docs(results, docs, png, scaling_png=None, speed_only=False):
    command = "`/usr/bin/python3 bench/levels.py " + " ".join(sys.argv[1:]) + "`"
    perf = ["## Levels: time, memory and triangles drawn", "",
            f"Written by {command}. One process per row on this 2-core machine; peak memory from GNU time; "
            "triangles drawn per hemicube are bake.json `hemicubeDraws` (summed over the five faces, occluder pass "
            "included) over the level's triangles.", "",
            "| level | texels | preset | time (s) | peak MiB | µs / texel | KiB / texel | solve hemicubes | drawn (solve) | final-gather hemicubes | drawn (gather) | final-gather rays (per texel) |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    if scaling_png:
        perf[4:4] = [f"![levels: time and memory per texel against texels]({scaling_png})", ""]
    trade = ["## Levels: error against time", "",
             f"Written by {command}. Per texel, the headline: RMS error against the noise-free answer, relative to "
             "each primitive's mean (compare's `relativeRmseAgainstTruth`: the reference's own noise, known from the "
             "standard error it carries, is taken out; the path tracer's rows keep theirs, it is their error). Also "
             "the plain mean relative error against the reference (|a−b|/max(|b|, 1 % of the mean), which carries the "
             "reference's noise). Per object: per glTF node, texel-weighted bake mean over reference mean − 1 (median "
             "of |·|, worst, mean signed). All against one converged path-traced reference per level on the same "
             "texels; the path tracer's rows use a different seed.", ""]
    if png:
        trade += [f"![levels: error against time]({png})", ""]
    for level in results.values():
        texels = level.get("texels") or 0
        for key, r in sorted(level["rows"].items(), key=lambda kv: kv[1]["seconds"]):
            if r["method"] != "bake":
                continue
            texels = r.get("texels") or level.get("texels") or 0
            per_texel_us = 1e6 * r["seconds"] / texels if texels else float("nan")
            per_texel_kib = 1024.0 * r["peakMiB"] / texels if texels else float("nan")
            frac = lambda v: "—" if v is None else f"{100 * v:.1f} %"
            # A level whose emitters went back to shooting (over the ray-traced emitters' limit) is another baker.
            setting = r["setting"] + (", emitters through rows" if r.get("emittersByRays") is False else "")
            perf.append(f"| {level['level']} ({r.get('sceneTriangles')} element triangles) | {texels} | {setting} | "
                        f"{r['seconds']:.0f} | {r['peakMiB']:.0f} | {per_texel_us:.0f} | {per_texel_kib:.2f} | "
                        f"{r.get('solveHemicubes')} | {frac(r.get('solveDrawnFraction'))} | {r.get('gatherHemicubes')} | "
                        f"{frac(r.get('gatherDrawnFraction'))} | "
                        f"{'—' if not r.get('gatherRays') else '{:.3g} ({})'.format(r['gatherRays'], r.get('gatherRaysPerTexel'))} |")
        texels = level.get("texels") or 0
        ratio, t_pt, extrapolated = speedup(level)
        trade += [f"### {level['level']} at {level['texelsPerUnit']} texels/m", "",
                  f"{texels} texels; reference {level.get('referenceSpp')} spp ({level.get('referenceSeconds', 0):.0f} s).", "",
                  "| method | setting | time (s) | peak MiB | per texel: RMS against truth | mean rel (vs reference) | mean signed | p95 | per object: median | worst | mean signed |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for key, r in sorted(level["rows"].items(), key=lambda kv: (kv[1]["method"], kv[1]["seconds"])):
            trade.append(f"| {r['method']} | {r['setting']} | {r['seconds']:.0f} | {r['peakMiB']:.0f} | "
                         f"{pct(r.get('errorAgainstTruth'))} | {pct(r.get('meanRelativeError'))} | "
                         f"{pct(r.get('meanSignedRelativeError'), True)} | "
                         f"{pct(r.get('p95RelativeError'))} | {pct(r.get('objectMedianError'))} | "
                         f"{pct(r.get('objectWorstError'))} | {pct(r.get('objectMeanSignedError'), True)} |")
        noise = [r.get("referenceNoise") for r in level["rows"].values() if r.get("referenceNoise")]
        if noise:
            trade += ["", f"The reference's own noise on the same scale: {pct(noise[0])} RMS per texel."]
        fit = path_tracer_fit(level)
        if fit:
            trade += ["", f"The path tracer's rows: error ≈ {100 * fit[0] ** 0.5:.0f} % / √spp, "
                          f"time ≈ {fit[1]:.0f} s + {1000 * fit[2]:.0f} ms × spp."]
        if ratio:
            how = "would reach (extrapolated along that fit)" if extrapolated else "reaches"
            trade += ["", f"The path tracer {how} the medium preset's per-texel error in {t_pt:.0f} s: "
                          f"**{ratio:.1f}×** the bake's time (issue 16 asks ≥ 10× on the clean ~10k level)."]
        trade.append("")
    staged = [(level, r, st) for level in results.values() for r in level["rows"].values() if r["method"] == "bake"
              and (r.get("texels") or level.get("texels")) and (st := row_stages(r))]
    if staged:
        perf += ["", "Where the time per texel goes: each stage's wall time per texel (µs), and the two stages that trace "
                     "rays through the whole level, per ray traced (wall ns on 2 cores; the same rays per texel at "
                     "every size, so a growth there is the cost of a ray, not more work).", "",
                 "| level | preset | " + " | ".join(label for _, label in STAGES) + " | shooting, ns / row ray | final gather, ns / ray |",
                 "|---|---|" + "---|" * len(STAGES) + "---|---|"]
        for level, r, st in sorted(staged, key=lambda x: (x[0]["level"], x[1]["setting"])):
            texels = r.get("texels") or level.get("texels")
            per_ray = [ns_per_ray(st, r, key, rays) for key, rays, _ in RAY_STAGES]
            perf.append(f"| {level['level']} | {r['setting']} | " + " | ".join(f"{1e6 * st[key] / texels:.0f}" for key, _ in STAGES) +
                        "".join(" | —" if v is None else f" | {v:.0f}" for v in per_ray) + " |")
    replace_section(os.path.join(docs, "performance.md"), "\n".join(perf))
    if not speed_only:
        replace_section(os.path.join(docs, "tradeoff.md"), "\n".join(trade))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "hemibake"))
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "levels"))
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs"))
    ap.add_argument("--levels", nargs="+", default=["clean:10000", "overlapping:100000", "overlapping:300000"],
                    help="KIND:TRIANGLES, KIND clean, overlapping, uniform or tiled")
    ap.add_argument("--presets", nargs="+", default=["draft", "medium", "high", "ultra"])
    ap.add_argument("--variant", action="append", default=[], metavar="LABEL=ARGS",
                    help="an extra bake row, e.g. 'medium, interpolate=--preset medium --texel-mode interpolate'")
    ap.add_argument("--bake-args", default="", metavar="ARGS",
                    help="added to every bake, e.g. '--max-ray-traced-emitters 8192' for a level with more emitter "
                         "triangles near one receiver than the default limit (its emitters would shoot through rows "
                         "and warn; the table marks such rows)")
    ap.add_argument("--spp", nargs="+", type=int, default=[16, 64, 256, 1024])
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--texels-per-unit", type=float, default=16.0)
    ap.add_argument("--keep", action="store_true", help="keep the bake outputs (for inspection)")
    ap.add_argument("--speed-only", action="store_true",
                    help="bakes only (no reference, no path tracer): time, memory and texels; docs/tradeoff.md untouched")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    store = os.path.join(a.work, "levels.json")
    results = json.load(open(store)) if os.path.exists(store) else {}
    for spec in a.levels:
        kind, _, triangles = spec.partition(":")
        if kind not in ("clean", "overlapping", "uniform", "tiled") or not triangles.isdigit():
            sys.exit(f"--levels {spec}: expected clean:N, overlapping:N, uniform:N or tiled:N")
        sweep_level(a, results, kind, int(triangles))
    chosen = {k: v for k, v in results.items() if k in {s.replace(":", "-") for s in a.levels}}
    png = None if a.speed_only else ("levels.png" if plot(chosen, os.path.join(a.docs, "levels.png")) else None)
    scaling = "levels_scaling.png" if plot_scaling(chosen, os.path.join(a.docs, "levels_scaling.png")) else None
    write_docs(chosen, a.docs, png, scaling, a.speed_only)
    print("wrote", os.path.join(a.docs, "performance.md") + ("" if a.speed_only else " and " + os.path.join(a.docs, "tradeoff.md")))


if __name__ == "__main__":
    main()
