#!/usr/bin/env python3
"""Checks the include directions of runtime/README.md's layer map.

Fails (exit 1, one line per include) on:
  - an include that goes up a layer: runtime/src/<layer>/ or a public header
    of that layer including a header of a layer listed after it;
  - an include of another target's private headers: runtime/src/ from
    anywhere but runtime/src/, runtime/vulkan/src/ from anywhere but
    runtime/vulkan/ (the white-box tests below are the declared exceptions);
  - an include by a relative path that climbs out of its folder ("../").

Each public header lives in its layer's folder, runtime/include/mmvk/<layer>/,
as the sources do in runtime/src/<layer>/, so its layer is where it is. The
one header above the layers is mmvk/mmvk.hpp, the start-here header that
includes them all: hosts, benchmarks and tests may include it, the runtime
may not. A public header elsewhere is an error.

usage: tools/check_layers.py [--root DIR]   (default: the repository holding this script)
"""

import argparse
import re
import sys
from pathlib import Path

# runtime/src/ folders, lowest first: each may include its own and earlier ones.
LAYERS = ["common", "import", "features", "database", "clusters", "search", "query", "animation"]
# mmvk::vulkan (runtime/vulkan/) is a target of its own above this layer.
VULKAN_USES_UP_TO = "search"

# The header above the layers (runtime/include/mmvk/mmvk.hpp).
UMBRELLA = "mmvk/mmvk.hpp"

# Tests that read a target's private headers on purpose, through an include
# directory their CMake target declares (tests/CMakeLists.txt).
WHITE_BOX = {
    "tests/cpu/cluster_table_test.cpp": "runtime/src",
    "tests/cpu/half_tile_store_test.cpp": "runtime/src",
    "tests/vulkan/vulkan_setup_test.cpp": "runtime/vulkan/src",
}

SOURCE_SUFFIXES = {".cpp", ".hpp", ".h", ".cc"}
SCANNED = ["runtime", "host", "bench", "tests"]
INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]+"([^"]+)"', re.MULTILINE)


def public_header_errors(root):
    """Public headers outside a layer folder, as error lines."""
    errors = []
    base = root / "runtime/include/mmvk"
    for header in sorted(base.rglob("*.hpp")) if base.is_dir() else []:
        rel = header.relative_to(base)
        if rel.as_posix() == "mmvk.hpp" or (len(rel.parts) == 2 and rel.parts[0] in LAYERS):
            continue
        errors.append(f"runtime/include/mmvk/{rel.as_posix()}: not in a layer folder: public headers live in"
                      f" runtime/include/mmvk/<layer>/ ({', '.join(LAYERS)})")
    return errors


def rank(layer):
    return LAYERS.index(layer)


class Checker:
    def __init__(self, root):
        self.root = root
        self.errors = public_header_errors(root)

    def fail(self, path, line, include, why):
        self.errors.append(f"{path}:{line}: #include \"{include}\": {why}")

    def own_layer(self, rel):
        """The layer whose rules `rel` follows, "vulkan", or None (a host, bench or test file)."""
        parts = rel.parts
        if parts[:2] == ("runtime", "src") and len(parts) > 3 and parts[2] in LAYERS:
            return parts[2]
        if parts[:3] == ("runtime", "include", "mmvk") and len(parts) == 5 and parts[3] in LAYERS:
            return parts[3]
        if parts[:3] == ("runtime", "include", "mmvk") and len(parts) == 4:
            return "umbrella"
        if parts[:2] == ("runtime", "vulkan"):
            return "vulkan"
        return None

    def target_of(self, include, rel):
        """Where an include lands: ("public", layer), ("umbrella",), ("vulkan-public",), ("private", layer),
        ("vulkan-private",), or None (this folder's own header, a generated or system one)."""
        if include.startswith("mmvk/vulkan/"):
            return ("vulkan-public",)
        if include == UMBRELLA:
            return ("umbrella",)
        parts = include.split("/")
        if len(parts) == 3 and parts[0] == "mmvk" and parts[1] in LAYERS:
            return ("public", parts[1])
        if (self.root / rel.parent / include).is_file():
            return None  # next to the including file
        first = include.split("/")[0]
        if first in LAYERS and (self.root / "runtime/src" / include).is_file():
            # From a host or test folder this may also be a folder of its own.
            top = self.root / rel.parts[0]
            if rel.parts[0] != "runtime" and any(p.is_file() for p in top.rglob(include)):
                return None
            return ("private", first)
        if rel.parts[0] != "runtime" and (self.root / "runtime/vulkan/src" / include).is_file():
            top = self.root / rel.parts[0]
            if not any(p.is_file() for p in top.rglob(include)):
                return ("vulkan-private",)
        return None

    def check_file(self, path):
        rel = path.relative_to(self.root)
        text = path.read_text(encoding="utf-8", errors="replace")
        own = self.own_layer(rel)
        white_box = WHITE_BOX.get(rel.as_posix())
        for match in INCLUDE.finditer(text):
            include = match.group(1)
            line = text.count("\n", 0, match.start()) + 1
            if ".." in Path(include).parts:
                self.fail(rel, line, include, "a relative path out of the folder; include a public header"
                          " (or, for a white-box test, a declared include directory)")
                continue
            target = self.target_of(include, rel)
            if target is None:
                continue
            kind = target[0]
            if own is None:  # host/, bench/, tests/
                if kind == "private" and white_box != "runtime/src":
                    self.fail(rel, line, include, f"a private header of mmvk::runtime (runtime/src/{target[1]}/);"
                              " what a host needs is public")
                elif kind == "vulkan-private" and white_box != "runtime/vulkan/src":
                    self.fail(rel, line, include, "a private header of mmvk::vulkan (runtime/vulkan/src/);"
                              " what a host needs is public")
            elif own == "umbrella":
                if kind in ("private", "vulkan-private"):
                    self.fail(rel, line, include, "mmvk/mmvk.hpp includes only public headers")
            elif kind == "umbrella":
                self.fail(rel, line, include, "the runtime includes the headers it needs, not mmvk/mmvk.hpp")
            elif own == "vulkan":
                if kind == "private":
                    self.fail(rel, line, include, "mmvk::vulkan includes a private header of mmvk::runtime")
                elif kind == "public" and rank(target[1]) > rank(VULKAN_USES_UP_TO):
                    self.fail(rel, line, include, f"mmvk::vulkan uses layers up to {VULKAN_USES_UP_TO},"
                              f" this header is in {target[1]}")
            else:
                if kind in ("vulkan-public", "vulkan-private"):
                    self.fail(rel, line, include, f"layer {own} of mmvk::runtime includes mmvk::vulkan")
                elif rank(target[1]) > rank(own):
                    self.fail(rel, line, include, f"goes up a layer: {own} includes {target[1]}"
                              " (runtime/README.md: each layer uses only the layers before it)")

    def run(self):
        for top in SCANNED:
            base = self.root / top
            if not base.is_dir():
                continue
            for path in sorted(base.rglob("*")):
                if path.suffix in SOURCE_SUFFIXES and path.is_file() and "corpus" not in path.parts:
                    self.check_file(path)
        return self.errors


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    args = parser.parse_args()
    errors = Checker(args.root.resolve()).run()
    for error in errors:
        print(error, file=sys.stderr)
    if errors:
        print(f"check_layers: {len(errors)} include(s) against runtime/README.md's layer map", file=sys.stderr)
        return 1
    print("check_layers: every include follows runtime/README.md's layer map")
    return 0


if __name__ == "__main__":
    sys.exit(main())
