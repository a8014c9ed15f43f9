# Manual check (not run by CI or CTest): reads the quad mesh exports of `quadsketch-cli optimize
# --quad-size Q` with both of Blender's OBJ importers and prints what each one imported next to
# what the files contain, so a reader can compare them (issue #44).
#
#   blender -b --python scripts/check_exports_blender.py -- DIR
#
# DIR holds layout_curves.obj and quads.obj. Each file is imported four ways: the default
# importer of Blender 3.4 (File > Import > Wavefront (.obj), bpy.ops.wm.obj_import) and the
# legacy add-on (bpy.ops.import_scene.obj), each with its default settings and with the groups
# kept (the default importer: `import_vertex_groups`, vertex groups from `g`, which it assigns to
# faces only; the legacy one: `use_split_groups`, one object per `g`). For layout_curves.obj it
# prints the imported objects, vertices, edges, connected pieces of the imported meshes (vertices
# joined by edges, as Blender holds them: no merging by position) and vertex groups, against the
# file's `l` segments and the pieces its shared vertices make. For quads.obj: objects, vertices,
# faces, the UV range and how many pairs of faces overlap in UV space. Exits non-zero when an
# importer reads fewer edges or faces than the file has.
import os
import sys

import bpy


def parse_obj(path):
    """Counts from the file itself: vertices, line segments, faces; the segments as index pairs."""
    nv, faces, segs = 0, 0, []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                nv += 1
            elif t[0] == "f":
                faces += 1
            elif t[0] == "l":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                idx = [i if i > 0 else nv + 1 + i for i in idx]
                segs += list(zip(idx, idx[1:]))
    return nv, faces, segs


def pieces(edges):
    """Connected pieces of a graph given as edges between hashable vertex keys."""
    parent = {}

    def find(x):
        parent.setdefault(x, x)
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in edges:
        parent[find(a)] = find(b)
    return len({find(x) for x in list(parent)})


def clear_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)
    for m in list(bpy.data.meshes):
        bpy.data.meshes.remove(m)


IMPORTERS = ("new", "new, vertex groups", "legacy", "legacy, split by group")


def import_obj(importer, path):
    clear_scene()
    groups = "," in importer
    if importer.startswith("new"):  # Blender 3.4's default (File > Import > Wavefront (.obj))
        bpy.ops.wm.obj_import(filepath=path, import_vertex_groups=groups)
    else:  # the legacy Python add-on
        if not hasattr(bpy.ops.import_scene, "obj"):
            return None
        bpy.ops.import_scene.obj(filepath=path, use_split_groups=groups)
    return [o for o in bpy.data.objects if o.type == "MESH"]


def check_curves(path):
    nv, _, segs = parse_obj(path)
    print(f"layout_curves.obj file: {nv} vertices, {len(segs)} line segments, "
          f"{pieces(segs)} connected pieces")
    ok = True
    for importer in IMPORTERS:
        objs = import_obj(importer, path)
        if objs is None:
            print(f"  {importer:22}: not available")
            continue
        verts = sum(len(o.data.vertices) for o in objs)
        edges = sum(len(o.data.edges) for o in objs)
        keyed = []
        for o in objs:
            keyed += [((o.name, e.vertices[0]), (o.name, e.vertices[1])) for e in o.data.edges]
        vgroups = sum(len(o.vertex_groups) for o in objs)
        print(f"  {importer:22}: {len(objs)} objects, {verts} vertices, {edges} edges, "
              f"{pieces(keyed)} connected pieces, {vgroups} vertex groups")
        ok &= edges == len(segs)
    return ok


def overlapping_uv_faces(objs, eps=1e-9):
    """Pairs of faces (over all objects) whose UV bounding boxes overlap with positive area.
    The exported UV quads are axis-aligned rectangles, so this is their true overlap."""
    boxes = []
    for o in objs:
        if not o.data.uv_layers:
            continue
        uv = o.data.uv_layers[0].data
        for poly in o.data.polygons:
            us = [uv[i].uv[0] for i in poly.loop_indices]
            vs = [uv[i].uv[1] for i in poly.loop_indices]
            boxes.append((min(us), min(vs), max(us), max(vs)))
    if not boxes:
        return None, None, 0
    cell = max(max(b[2] - b[0], b[3] - b[1]) for b in boxes) or 1.0
    buckets = {}
    pairs = set()
    for k, b in enumerate(boxes):
        for gx in range(int(b[0] // cell), int(b[2] // cell) + 1):
            for gy in range(int(b[1] // cell), int(b[3] // cell) + 1):
                for j in buckets.get((gx, gy), ()):
                    c = boxes[j]
                    if min(b[2], c[2]) - max(b[0], c[0]) > eps and \
                            min(b[3], c[3]) - max(b[1], c[1]) > eps:
                        pairs.add((j, k))
                buckets.setdefault((gx, gy), []).append(k)
    lo = min(min(b[0], b[1]) for b in boxes)
    hi = max(max(b[2], b[3]) for b in boxes)
    return lo, hi, len(pairs)


def check_quads(path):
    nv, nf, _ = parse_obj(path)
    print(f"quads.obj file: {nv} vertices, {nf} faces")
    ok = True
    for importer in IMPORTERS:
        objs = import_obj(importer, path)
        if objs is None:
            print(f"  {importer:22}: not available")
            continue
        verts = sum(len(o.data.vertices) for o in objs)
        faces = sum(len(o.data.polygons) for o in objs)
        line = (f"  {importer:22}: {len(objs)} objects, {verts} vertices, "
                f"{faces} faces")
        lo, hi, overlaps = overlapping_uv_faces(objs)
        if lo is not None:
            line += f", UVs in [{lo:.6g}, {hi:.6g}], {overlaps} face pairs with overlapping UVs"
        print(line)
        ok &= faces == nf
    return ok


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) != 1:
        print("usage: blender -b --python scripts/check_exports_blender.py -- DIR")
        sys.exit(2)
    folder = argv[0]
    print("Blender", bpy.app.version_string)
    ok = check_curves(os.path.join(folder, "layout_curves.obj"))
    ok &= check_quads(os.path.join(folder, "quads.obj"))
    print("OK" if ok else "FAILED: an importer read fewer elements than the file has")
    sys.exit(0 if ok else 1)


main()
