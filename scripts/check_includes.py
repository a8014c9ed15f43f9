#!/usr/bin/env python3
"""Checks the include directions of core/ (docs/design.md, "Code layers").

Every folder of core/ is a layer; LAYERS lists them from the bottom up. A file of core/<dir>/
may include headers of its own layer and of the layers below it, never of a layer above it.
No file of core/ may include app/ or render/ headers, or OpenGL, windowing or GUI headers.
A folder of core/ missing from LAYERS is an error too, so a new folder gets its place.

Usage: scripts/check_includes.py [--root REPO]. Prints one line per violation,
"core/<dir>/<file>:<line>: <include> (<why>)", and exits with 1 when there is any, else 0.
The CTest test `include_directions` runs it on the source tree.
"""
import argparse
import os
import re
import sys

# Bottom to top. engine is the top layer: it may include everything in core/.
LAYERS = ["base", "mesh", "layout", "field", "param", "extract", "pipeline", "nodeopt",
          "import", "engine"]

# Include prefixes no core file may use (quoted or angle-bracketed).
FORBIDDEN_PREFIXES = {
    "app/": "core must not include the application",
    "render/": "core must not include the renderer",
    "GL/": "core must not use OpenGL",
    "GLES2/": "core must not use OpenGL",
    "GLES3/": "core must not use OpenGL",
    "OpenGL/": "core must not use OpenGL",
    "EGL/": "core must not use OpenGL",
    "KHR/": "core must not use OpenGL",
    "glad/": "core must not use OpenGL",
    "epoxy/": "core must not use OpenGL",
    "GLFW/": "core must not use a windowing library",
    "imgui": "core must not use the GUI library",
}

SOURCE_SUFFIXES = (".h", ".hpp", ".hh", ".inl", ".cpp", ".cc", ".cxx")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')
CORE_RE = re.compile(r"^core/([^/]+)/")


def check_file(path, rel, layer_of):
    """Violations of one file: (line number, include text, reason)."""
    parts = rel.split("/")
    own = parts[1] if len(parts) > 2 else None
    out = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            m = INCLUDE_RE.match(line)
            if not m:
                continue
            target = m.group(2).strip()
            text = m.group(1) + target + ('"' if m.group(1) == '"' else ">")
            for prefix, why in FORBIDDEN_PREFIXES.items():
                if target.startswith(prefix):
                    out.append((number, text, why))
                    break
            else:
                c = CORE_RE.match(target)
                if not c or own is None:
                    continue
                dep = c.group(1)
                if dep not in layer_of:
                    out.append((number, text, "core/%s is not a layer of scripts/check_includes.py"
                                % dep))
                elif own in layer_of and layer_of[dep] > layer_of[own]:
                    out.append((number, text, "layer %s is above layer %s" % (dep, own)))
    return out


def check_tree(root):
    """All violations under root/core: list of (relative path, line, include, reason)."""
    layer_of = {name: k for k, name in enumerate(LAYERS)}
    core = os.path.join(root, "core")
    violations = []
    if not os.path.isdir(core):
        raise FileNotFoundError("no core/ folder under " + root)
    for entry in sorted(os.listdir(core)):
        if os.path.isdir(os.path.join(core, entry)) and entry not in layer_of:
            violations.append(("core/" + entry, 0, "", "folder missing from LAYERS"))
    for folder, dirs, files in os.walk(core):
        dirs.sort()
        for name in sorted(files):
            if not name.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, root).replace(os.sep, "/")
            for number, text, why in check_file(path, rel, layer_of):
                violations.append((rel, number, text, why))
    return violations


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default_root = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--root", default=default_root, help="repository root (default: %(default)s)")
    args = parser.parse_args(argv)
    violations = check_tree(args.root)
    for rel, number, text, why in violations:
        if number:
            print("%s:%d: %s (%s)" % (rel, number, text, why))
        else:
            print("%s: %s" % (rel, why))
    if violations:
        print("%d include direction violation(s); layers bottom to top: %s"
              % (len(violations), " < ".join(LAYERS)))
        return 1
    print("include directions ok (%s)" % " < ".join(LAYERS))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
