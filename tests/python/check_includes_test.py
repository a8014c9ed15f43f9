#!/usr/bin/env python3
"""scripts/check_includes.py accepts includes of the same or a lower layer and reports, with
file and line, includes of a higher layer, of app/ or render/, of OpenGL headers, and folders
of core/ that are not in its layer list."""
import os
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import check_includes  # noqa: E402


def write(root, rel, text):
    path = os.path.join(root, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


class CheckIncludesTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name

    def tearDown(self):
        self.dir.cleanup()

    def test_downward_and_same_layer_includes_pass(self):
        write(self.root, "core/field/a.h",
              '#include <vector>\n#include "core/base/b.h"\n#include "core/field/c.h"\n')
        write(self.root, "core/engine/e.cpp", '#include "core/import/x.h"\n')
        self.assertEqual(check_includes.check_tree(self.root), [])
        self.assertEqual(check_includes.main(["--root", self.root]), 0)

    def test_violations_are_reported_with_file_and_line(self):
        write(self.root, "core/layout/a.cpp",
              '#include "core/layout/a.h"\n'
              '#include "core/param/p.h"\n'
              '#  include "app/gui/editor.h"\n'
              '#include "render/layers.h"\n'
              '#include <GL/glcorearb.h>\n'
              '// #include "core/engine/e.h" in a comment is not an include\n')
        found = [(rel, line) for rel, line, _, _ in check_includes.check_tree(self.root)]
        self.assertEqual(found, [("core/layout/a.cpp", 2), ("core/layout/a.cpp", 3),
                                 ("core/layout/a.cpp", 4), ("core/layout/a.cpp", 5)])
        self.assertEqual(check_includes.main(["--root", self.root]), 1)

    def test_unknown_folders_are_reported(self):
        write(self.root, "core/newtopic/a.h", "")
        write(self.root, "core/mesh/m.h", '#include "core/newtopic/a.h"\n')
        reasons = [why for _, _, _, why in check_includes.check_tree(self.root)]
        self.assertEqual(len(reasons), 2)

    def test_layer_order_is_the_documented_one(self):
        with open(os.path.join(ROOT, "docs", "design.md")) as f:
            design = f.read()
        self.assertIn(" < ".join("`%s`" % name for name in check_includes.LAYERS), design)


if __name__ == "__main__":
    unittest.main()
