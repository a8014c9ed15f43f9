#!/usr/bin/env python3
"""bench/make_report.py regenerates only the generated part of docs/benchmarks.md: the notes
below its marker (and, in a page from before the marker, from the first notes heading on)
survive a run, and a page it cannot split is left alone with an error."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(ROOT, "bench", "make_report.py")
sys.path.insert(0, os.path.join(ROOT, "bench"))
import make_report  # noqa: E402

MACHINE = {"nproc": "2", "cpu": "test cpu", "memory": "1Gi", "load": "0.0", "date": "today",
           "commit": "abc1234", "command": "scripts/bench.sh", "runtime_s": 1}
NOTES = "## A note\n\nNumbers nobody can regenerate: 1.234 s.\n"


def write_run(runs, name, report):
    """One run folder as scripts/bench.sh leaves it."""
    folder = os.path.join(runs, name)
    os.makedirs(folder)
    with open(os.path.join(folder, "run.json"), "w") as f:
        json.dump({"name": name, "status": "ok", "exit_code": 0, "wall_s": 0.5,
                   "command": "quadsketch-cli optimize"}, f)
    with open(os.path.join(folder, "log.txt"), "w") as f:
        f.write("node optimization [descent] step 1: E = 0.5 (accepted), alpha = 0.75, "
                "moved nodes = 3, fold-overs = 0, 0.01 s\n")
    with open(os.path.join(folder, "report.json"), "w") as f:
        json.dump(report, f)


class MakeReportTest(unittest.TestCase):
    def run_report(self, page):
        with tempfile.TemporaryDirectory() as tmp:
            runs = os.path.join(tmp, "runs")
            os.makedirs(runs)
            write_run(runs, "ellipsoid.opt",
                      {"E_init": 2.5, "E_final": 0.5, "metrics": {"foldovers": 0},
                       "node_optimization": {"steps": 1, "foldovers_init": 1}})
            path = os.path.join(tmp, "benchmarks.md")
            if page is not None:
                with open(path, "w") as f:
                    f.write(page)
            proc = subprocess.run(
                [sys.executable, SCRIPT, "--runs", runs, "--machine", json.dumps(MACHINE),
                 "--json", os.path.join(tmp, "results.json"), "--markdown", path,
                 "--svg-dir", os.path.join(tmp, "svg")], capture_output=True, text=True)
            with open(path) as f:
                return proc, f.read()

    def assert_generated(self, text):
        self.assertTrue(text.startswith("# Benchmarks\n"))
        self.assertIn("- Git commit: abc1234", text)
        self.assertIn("## Table 1 analogue", text)

    def test_notes_below_the_marker_are_kept(self):
        old = ("# Benchmarks\n\n- Git commit: old0000\n\n## Table 1 analogue\n\nstale\n\n" +
               make_report.NOTES_MARKER + "\n\n" + NOTES)
        proc, text = self.run_report(old)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assert_generated(text)
        self.assertNotIn("old0000", text)
        self.assertNotIn("stale", text)
        self.assertTrue(text.endswith(make_report.NOTES_MARKER + "\n\n" + NOTES), text[-300:])
        self.assertEqual(text.count(make_report.NOTES_MARKER), 1)
        # A second run keeps them again (and adds no second marker).
        proc, again = self.run_report(text)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(again, text)

    def test_a_page_from_before_the_marker_keeps_its_notes(self):
        old = ("# Benchmarks\n\n- Git commit: old0000\n\n" + make_report.FIRST_NOTES_HEADING +
               "\n\nfield notes\n\n" + NOTES)
        proc, text = self.run_report(old)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assert_generated(text)
        self.assertNotIn("old0000", text)
        self.assertIn(make_report.NOTES_MARKER + "\n\n" + make_report.FIRST_NOTES_HEADING +
                      "\n\nfield notes\n\n" + NOTES, text)

    def test_a_new_page_has_the_marker_and_no_notes(self):
        proc, text = self.run_report(None)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assert_generated(text)
        self.assertTrue(text.endswith(make_report.NOTES_MARKER + "\n"), text[-200:])

    def test_a_page_it_cannot_split_is_left_alone(self):
        old = "# Someone's page\n\nwithout marker or notes heading\n"
        proc, text = self.run_report(old)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("no notes marker", proc.stderr)
        self.assertEqual(text, old)


if __name__ == "__main__":
    unittest.main()
