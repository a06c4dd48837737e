#!/usr/bin/env python3
"""Checks that every #include in mesh/, raster/, baker/<stage>/ and cli/ stays inside what its CMake target links.

The stage graph is read from baker/CMakeLists.txt (hemibake_baker_stage(NAME PUBLIC deps...)), so the build
files are the one statement of it: a stage may include its own headers and those of the stages it links,
directly or through them. Layers: mesh <- raster <- baker <- cli. Exit 1 with one line per violation."""
import pathlib
import re
import sys

root = pathlib.Path(__file__).resolve().parent.parent
cmake = (root / "baker" / "CMakeLists.txt").read_text()
links = {}
for m in re.finditer(r"hemibake_baker_stage\((\w+)\s+([^)]*)\)", cmake):
    stage, args = m.group(1), m.group(2).split()
    links[stage] = {a[len("hemibake_baker_"):] for a in args if a.startswith("hemibake_baker_")}
if not links:
    sys.exit("check-layers: no hemibake_baker_stage() calls found in baker/CMakeLists.txt")


def reach(stage, seen=None):
    seen = seen if seen is not None else set()
    for d in links.get(stage, ()):
        if d not in seen:
            seen.add(d)
            reach(d, seen)
    return seen


allowed_layers = {"mesh": {"mesh"}, "raster": {"mesh", "raster"}, "baker": {"mesh", "raster", "baker"},
                  "cli": {"mesh", "raster", "baker", "cli"}}
include = re.compile(r'^\s*#\s*include\s+"(\w+)/(?:(\w+)/)?[\w.]+"', re.M)
problems = []
for layer, ok in allowed_layers.items():
    for path in sorted((root / layer).rglob("*")):
        if path.suffix not in (".h", ".cpp"):
            continue
        rel = path.relative_to(root)
        own_stage = rel.parts[1] if layer == "baker" and len(rel.parts) > 2 else None
        if layer == "baker" and own_stage is None:
            problems.append(f"{rel}: baker sources belong in a stage folder")
            continue
        for m in include.finditer(path.read_text()):
            top, sub = m.group(1), m.group(2)
            if top not in allowed_layers:
                continue
            if top not in ok:
                problems.append(f"{rel}: includes {top}/ (a higher layer)")
            elif top == "baker" and own_stage is not None and sub != own_stage and sub not in reach(own_stage):
                problems.append(f"{rel}: includes baker/{sub}/, which baker/{own_stage} does not link")
for p in problems:
    print(p)
if problems:
    sys.exit(1)
print(f"check-layers: {len(links)} baker stages, every include inside its target's links")
