#!/usr/bin/env python3
"""Checks the layering of docs/architecture.md on the includes of the source tree.

Every library may include only its own headers and those of the libraries below it; Ceres only
in graph/ceres_*; benchmarks never include a command file (apps/*_command.h); the top level holds
only the design's folders. The CMake link lists enforce the same order at link time; this check
also catches a header-only include that would slip past the linker.

Usage: check_layers.py [REPO_ROOT]   (prints each violation as path:line and exits 1 if any)
"""
import pathlib
import re
import sys

# Library folder -> the folders it may include from (itself included), lowest layer first.
LAYERS = {
    "core": ["core"],
    "graph": ["core", "graph"],
    "factors": ["core", "graph", "factors"],
    "frontend/image": ["core", "frontend/image"],
    "sim": ["core", "graph", "factors", "sim"],
    "frontend/mapping": ["core", "graph", "factors", "frontend/image", "frontend/mapping"],
    "apps/cli": ["core", "graph", "factors", "frontend/image", "frontend/mapping", "sim",
                 "apps/cli"],
    "apps": ["core", "graph", "factors", "frontend/image", "frontend/mapping", "sim", "apps/cli",
             "apps"],
    "benchmarks": ["core", "graph", "factors", "frontend/image", "frontend/mapping", "sim",
                   "apps/cli", "benchmarks"],
}
TOP_LEVEL = {"CMakeLists.txt", "README.md", "core", "graph", "factors", "frontend", "apps", "test",
             "benchmarks", "sim", "scripts", "docs", "cmake", ".ci", ".clang-format",
             ".gitignore", ".git", "build"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')


def library_of(relative):
    """The most specific LAYERS folder holding `relative` (a path inside the repo)."""
    best = None
    for folder in LAYERS:
        if relative == folder or relative.startswith(folder + "/"):
            if best is None or len(folder) > len(best):
                best = folder
    return best


def header_folder(include):
    """The LAYERS folder of a repo-rooted include, or None for a system header."""
    return library_of(include) if include.split("/")[0] in {p.split("/")[0] for p in LAYERS} \
        else None


def violations(root):
    for entry in sorted(root.iterdir()):
        if entry.name not in TOP_LEVEL:
            yield f"{entry.name}: not one of the design's top-level folders"
    for path in sorted(root.rglob("*")):
        if path.suffix not in {".h", ".cpp"} or "build" in path.relative_to(root).parts[:1]:
            continue
        relative = path.relative_to(root).as_posix()
        library = library_of(relative)
        if library is None:
            continue  # test/ may include anything
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            include = match.group(1)
            if include.startswith("ceres/") and not (
                    relative.startswith("graph/ceres_") or library == "benchmarks"):
                yield f"{relative}:{number}: includes Ceres outside graph/ceres_*"
            folder = header_folder(include)
            if folder is None:
                continue
            if folder not in LAYERS[library]:
                yield f"{relative}:{number}: {library} includes {include} from {folder}, a layer " \
                      f"above or beside it"
            if library == "benchmarks" and re.fullmatch(r"apps/[a-z_]+_command\.h", include):
                yield f"{relative}:{number}: a benchmark includes the command file {include}"


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    if not (root / "CMakeLists.txt").is_file():
        print(f"check_layers: {root}: no CMakeLists.txt, not the repository root", file=sys.stderr)
        return 2
    found = list(violations(root))
    for line in found:
        print(line)
    print(f"check_layers: {len(found)} violation(s) in {root}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
