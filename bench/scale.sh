#!/usr/bin/env bash
# Scale benchmark: bake time and peak memory of generated game levels (examples/generate_level.py) at ~10k,
# ~100k and ~300k triangles and each preset, through `hemibake batch` (one child process per bake, so the peak
# memory is each bake's own, from wait4). Prints a Markdown table for docs/performance.md.
#
#   bash bench/scale.sh [WORKDIR]          # default WORKDIR: build-scale/ (levels, bakes, summaries)
#   SIZES="10000 100000" PRESETS="draft medium" MAX_TIME=600 bash bench/scale.sh
#
# The manifest also holds a deliberately broken level (a truncated copy of the smallest), so every run is also the
# batch acceptance check: the good levels bake, the broken one is reported, the batch exits 1. Re-running resumes:
# finished bakes are skipped (their numbers come from results.jsonl, appended by every run), so the table can be
# built up over several sessions. MAX_TIME (seconds, optional) caps the shooting stage of each bake (--max-time).
set -uo pipefail
cd "$(dirname "$0")/.."
work="${1:-build-scale}"
sizes="${SIZES:-10000 100000 300000}"
presets="${PRESETS:-draft medium high ultra}"
hemibake="${HEMIBAKE:-build/hemibake}"
mkdir -p "$work/levels"

for t in $sizes; do
  [ -f "$work/levels/level_$t.gltf" ] || python3 examples/generate_level.py --seed 1 --triangles "$t" -o "$work/levels/level_$t.gltf"
done
first="$(echo $sizes | cut -d' ' -f1)"
head -c 2000 "$work/levels/level_$first.gltf" > "$work/levels/broken.gltf"

python3 - "$work" "$sizes" "$presets" "${MAX_TIME:-}" <<'PY'
import json, sys
work, sizes, presets, max_time = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), sys.argv[4]
scenes = []
for p in presets:
    for t in sizes:
        s = {"name": "level_%s_%s" % (t, p), "scene": "levels/level_%s.gltf" % t, "output": "bakes/level_%s_%s" % (t, p),
             "settings": {"preset": p}}
        if max_time:
            s["settings"]["max-time"] = float(max_time)
        scenes.append(s)
scenes.append({"name": "broken", "scene": "levels/broken.gltf", "output": "bakes/broken", "settings": {"preset": "draft"}})
json.dump({"scenes": scenes}, open(work + "/manifest.json", "w"), indent=1)
PY

"$hemibake" batch "$work/manifest.json" --progress
echo "batch exit code: $? (1 expected: the broken level)" >&2

python3 - "$work" <<'PY'
import json, os, sys
work = sys.argv[1]
summary = json.load(open(work + "/batch.json"))
with open(work + "/results.jsonl", "a") as log:
    for s in summary["scenes"]:
        if s["status"] != "ok":
            continue
        bake = json.load(open(os.path.join(s["output"], "bake.json")))
        row = {"name": s["name"], "seconds": s["seconds"], "peakMemoryMiB": s["peakMemoryMiB"],
               "triangles": bake["counts"]["triangles"], "texels": bake["lightmap"]["texels"],
               "patches": bake["counts"]["patches"], "elements": bake["counts"]["elements"],
               "shots": bake["convergence"].get("shots"), "stop": bake["convergence"].get("stopReason"),
               "texelsPerUnit": bake["lightmap"]["texelsPerUnit"],
               "rendered": bake["lightmap"].get("renderedFraction"), "load": os.getloadavg()[0]}
        log.write(json.dumps(row) + "\n")
latest = {}
for line in open(work + "/results.jsonl"):
    r = json.loads(line)
    latest[r["name"]] = r
print("| level | preset | triangles | texels (per m) | patches / elements | stop | time | peak RSS |")
print("|---|---|---|---|---|---|---|---|")
for s in summary["scenes"]:
    if s["name"] == "broken":
        print("| broken (truncated) | draft | | | | %s: %s | | |" % (s["status"], s.get("error") or ""))
        continue
    _, t, p = s["name"].split("_")
    r = latest.get(s["name"])
    if not r:
        print("| %s | %s | | | | %s | | |" % (t, p, s["status"] + (": " + s["error"] if s.get("error") else "")))
        continue
    print("| %s | %s | %s | %s (%g) | %s / %s | %s, %s shots | %.0f s | %.0f MiB |" % (
        t, p, format(r["triangles"], ","), format(r["texels"], ","), r["texelsPerUnit"], format(r["patches"], ","),
        format(r["elements"], ","), r["stop"], r["shots"], r["seconds"], r["peakMemoryMiB"]))
PY
