#!/usr/bin/env python3
"""Fails when an include in core/ runs against the data flow.

The stages form floors, lowest first: common, particles, bricks, view, culling, render, composite,
finish, output, dump, pipeline. A file may include its own stage and the stages below it; config/,
camera/ and color/ are values that any stage may include, and they include only values and
common/. A subfolder belongs to its stage (core/output/png/ is output). Nothing in core/ includes
the public C header (adaptor/ translates). Usage:
check_layers.py [repository root]
"""
import pathlib
import re
import sys

FLOORS = ["common", "particles", "bricks", "view", "culling", "render", "composite", "finish",
          "output", "dump", "pipeline"]
VALUES = {"config", "camera", "color"}
INCLUDE = re.compile(r'#include "core/([a-z_]+)/')


def allowed(src, dst):
    if dst == src:
        return True
    if src in VALUES:
        return dst in VALUES or dst == "common"
    if dst in VALUES:
        return True
    return FLOORS.index(dst) < FLOORS.index(src)


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    bad = []
    files = sorted(p for p in (root / "core").rglob("*") if p.suffix in (".h", ".cpp"))
    for path in files:
        src = path.relative_to(root / "core").parts[0]
        if src not in FLOORS and src not in VALUES:
            bad.append(f"{path}: core/{src}/ is not a known stage (add it to the floors)")
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if "lantern/lantern.h" in line and line.startswith("#include"):
                bad.append(f"{path}:{number}: core/ includes the public header")
            m = INCLUDE.match(line)
            if m and (m.group(1) not in FLOORS and m.group(1) not in VALUES or
                      not allowed(src, m.group(1))):
                bad.append(f"{path}:{number}: {src}/ includes core/{m.group(1)}/")
    for b in bad:
        print(b)
    print(f"check_layers: {len(files)} files, {len(bad)} includes against the data flow")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
