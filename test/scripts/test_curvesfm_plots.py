"""Unit tests of scripts/curvesfm_plots on small fixtures written here: the OBJ reader, messages
that name the bad file, the eval figure (PNG, PDF, refused extension), the bench figures and the
HTML report's figures and notes. Run with PYTHONPATH=<repo>/scripts python3 -m unittest."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

from curvesfm_plots import bench_figures, inputs, real_bench, report

OBJ = """# curvesfm: densely sampled poly-Bezier curves, one polyline per curve
o curve_0
v 0 0 0
v 0.1 0 0
v 0.2 0.05 0
l 1 2 3
o curve_1
v 0 0.3 0
v 0.1 0.3 0.01
l 4 5
"""


def write(folder, name, text):
    path = os.path.join(folder, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return path


def run_package(*args):
    """Runs `python3 -m curvesfm_plots ARGS`; returns (exit code, stderr)."""
    result = subprocess.run([sys.executable, "-m", "curvesfm_plots", *args],
                            capture_output=True, text=True)
    return result.returncode, result.stderr


def tum_line(t, x, y, z):
    return "%.3f %.6f %.6f %.6f 0 0 0 1\n" % (t, x, y, z)


def positions(count, scale=1.0):
    return [[0.01 * k * scale, 0.0, 0.002 * k * k * scale] for k in range(count)]


def write_run(folder, ground_truth=True):
    """A `curvesfm run` folder of 4 keyframes and 2 curves, as run_command.cpp writes it."""
    write(folder, "curves.obj", OBJ)
    write(folder, "trajectory.txt", "".join(tum_line(k, *p) for k, p in enumerate(positions(4))))
    write(folder, "trajectory_initial.txt",
          "".join(tum_line(k, *p) for k, p in enumerate(positions(4, 1.1))))
    matched = {"timestamp": [0, 1, 2, 3], "error_m": [0.001, 0.002, 0.001, 0.003],
               "aligned_position": positions(4), "ground_truth_position": positions(4, 1.01)}
    seconds = {s: 0.01 for s in report.STAGES + ("frontend",)}
    document = {
        "command": "run",
        "camera": {"width": 320, "height": 240, "fx": 300, "fy": 300, "cx": 160, "cy": 120},
        "counts": {"frames": 5, "keyframes": 4, "curves": 2, "segments": 3},
        "frames": [{"frame_index": k, "keyframe_index": k if k < 4 else -1, "seconds": seconds}
                   for k in range(5)],
        "global_ba_cost_by_type": {"initial": {"CurveReprojection": {"count": 10, "cost": 5.0}},
                                   "final": {"CurveReprojection": {"count": 10, "cost": 1.0}}},
        "ate": {"alignment": "sim3", "initial_m": {"rmse": 0.002}, "refined_m": {"rmse": 0.001},
                "per_pose": {"initial": matched, "refined": matched} if ground_truth else None,
                "problem": ""},
        "total_seconds": 1.5}
    write(folder, "report.json", json.dumps(document))
    return folder


class ObjTest(unittest.TestCase):
    def test_reads_curves_and_polylines(self):
        with tempfile.TemporaryDirectory() as d:
            curves = inputs.read_obj(write(d, "curves.obj", OBJ))
        self.assertEqual([name for name, _ in curves], ["curve_0", "curve_1"])
        self.assertEqual(len(curves[0][1][0]), 3)
        self.assertEqual(curves[1][1][0][1], (0.1, 0.3, 0.01))

    def test_bad_vertex_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            path = write(d, "curves.obj", "o curve_0\nv 0 0 0\nv 1 two 0\n")
            with self.assertRaisesRegex(inputs.InputError, r"curves\.obj:3: expected 'v x y z'"):
                inputs.read_obj(path)

    def test_index_out_of_range_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            path = write(d, "curves.obj", "o curve_0\nv 0 0 0\nv 1 0 0\nl 1 3\n")
            with self.assertRaisesRegex(inputs.InputError, r"curves\.obj:4: .*\[1, 2\]"):
                inputs.read_obj(path)


class ReportTest(unittest.TestCase):
    def test_figures_and_trace_counts_with_ground_truth(self):
        with tempfile.TemporaryDirectory() as d:
            path, traces = report.build(write_run(d))
            with open(path) as f:
                page = f.read()
        self.assertEqual(traces, {"map": 3, "trajectory": 3, "ate": 2, "timings": 7, "costs": 2})
        self.assertIn('id="report-status"', page)
        self.assertIn("No overlays/*.png", page)
        self.assertNotIn("<script src=", page)  # Self-contained: no script from the network.

    def test_without_ground_truth_leaves_the_ate_out_with_a_note(self):
        with tempfile.TemporaryDirectory() as d:
            path, traces = report.build(write_run(d, ground_truth=False),
                                        os.path.join(d, "other.html"))
            with open(path) as f:
                page = f.read()
        self.assertEqual(traces, {"map": 3, "trajectory": 2, "timings": 7, "costs": 2})
        self.assertIn("No ground truth", page)

    def test_overlays_become_thumbnails(self):
        import matplotlib.image
        import numpy
        with tempfile.TemporaryDirectory() as d:
            write_run(d)
            os.makedirs(os.path.join(d, "overlays"))
            matplotlib.image.imsave(os.path.join(d, "overlays", "000000.png"),
                                    numpy.zeros((480, 640, 3)))
            with open(report.build(d)[0]) as f:
                page = f.read()
        self.assertIn('<img src="data:image/png;base64,', page)

    def test_missing_report_json_names_it(self):
        with tempfile.TemporaryDirectory() as d:
            write(d, "curves.obj", OBJ)
            code, message = run_package("report", d)
        self.assertEqual(code, 1)
        self.assertIn(os.path.join(d, "report.json") + ": cannot read", message)

    def test_malformed_inputs_name_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            write_run(d)
            write(d, "curves.obj", "o curve_0\nv 0 0\n")
            code, message = run_package("report", d)
            self.assertEqual(code, 1)
            self.assertIn(os.path.join(d, "curves.obj") + ":2:", message)
            write(d, "report.json", '{"frames": [}')
            code, message = run_package("report", d)
            self.assertEqual(code, 1)
            self.assertIn(os.path.join(d, "report.json") + ": not valid JSON", message)
            write(d, "report.json", '{"frames": 3}')
            code, message = run_package("report", d)
        self.assertEqual(code, 1)
        self.assertIn('report.json: "frames" should be a list', message)
        self.assertEqual(len(message.strip().splitlines()), 1)


class EvalFigureTest(unittest.TestCase):
    def write_eval_json(self, folder):
        truth = positions(20)
        document = {"options": {"alignment": "sim3"}, "ate_m": {"rmse": 0.002},
                    "per_pose": {"ground_truth_timestamp": [0.1 * k for k in range(20)],
                                 "estimate_timestamp": [0.1 * k for k in range(20)],
                                 "ate_m": [0.002] * 20, "aligned_position": truth,
                                 "ground_truth_position": truth}}
        return write(folder, "eval.json", json.dumps(document))

    def test_writes_png_and_pdf(self):
        with tempfile.TemporaryDirectory() as d:
            source = self.write_eval_json(d)
            for name, magic in (("eval.png", b"\x89PNG"), ("eval.pdf", b"%PDF")):
                self.assertEqual(run_package("eval", source, os.path.join(d, name))[0], 0)
                with open(os.path.join(d, name), "rb") as f:
                    self.assertEqual(f.read(4), magic)

    def test_refuses_other_extensions(self):
        with tempfile.TemporaryDirectory() as d:
            code, message = run_package("eval", self.write_eval_json(d), os.path.join(d, "e.jpg"))
            self.assertFalse(os.path.exists(os.path.join(d, "e.jpg")))
        self.assertEqual(code, 2)
        self.assertIn("e.jpg': expected a file name ending in .png or .pdf", message)

    def test_missing_key_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            source = write(d, "eval.json", '{"per_pose": {}}')
            code, message = run_package("eval", source, os.path.join(d, "e.png"))
        self.assertEqual(code, 1)
        self.assertIn('eval.json: expected the key "per_pose.ground_truth_timestamp"', message)


class BenchFiguresTest(unittest.TestCase):
    def test_planar_bench_figures(self):
        header = ("photo,category,noise_percent,seed,frames,keyframes,global_curves,"
                  "initial_ate_mm,refined_ate_mm,ratio,improved,error\n")
        rows = "".join("p%d,%s,%d,1,10,5,20,2.0,%g,%g,1,\"\"\n" % (i, c, n, 0.5 + i, 0.25 + i / 2)
                       for i, c in enumerate(bench_figures.CATEGORIES) for n in (0, 10))
        with tempfile.TemporaryDirectory() as d:
            write(d, "runs.csv", header + rows + "bad,logo,0,1,10,0,0,nan,nan,nan,0,\"threw\"\n")
            write(d, "paper_table2.csv", "category,noise_percent,ate_mm\nlogo,0,0.4\nlogo,10,0.5\n")
            paths = bench_figures.planar(d)
            self.assertTrue(all(os.path.getsize(p) > 0 for p in paths))
        self.assertEqual(sorted(os.path.basename(p) for p in paths),
                         ["ate_ratio_vs_noise.pdf", "ate_ratio_vs_noise.png", "ate_vs_noise.pdf",
                          "ate_vs_noise.png"])

    def test_strategy_bench_figures(self):
        header = ("scene,strategy,linear_solver,kernel,lambda1,lambda2,edges,ate_after_mm,"
                  "curve_after_mm,seconds\n")
        rows = "".join("s,%s,sparse_schur,%s,%g,%g,subpixel,1.5,2.5,0.3\n" % (s, k, l1, l2)
                       for s in bench_figures.STRATEGIES for k in ("none", "huber", "cauchy")
                       for l1 in (0, 100, 10000) for l2 in (0, 1, 10))
        with tempfile.TemporaryDirectory() as d:
            write(d, "runs.csv", header + rows)
            self.assertEqual(len(bench_figures.strategy(d)), 8)

    def test_missing_column_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            write(d, "runs.csv", "scene,strategy\n")
            code, message = run_package("strategy-bench", d)
        self.assertEqual(code, 1)
        self.assertIn(os.path.join(d, "runs.csv") + ":1: expected the columns", message)


class RealBenchFiguresTest(unittest.TestCase):
    HEADER = "set,variant,status,frames,registered,evaluated,ate_rmse,ate_mean,ate_median,note\n"

    def write_bench(self, d):
        rows = ("a,init,ok,5,5,5,0.02,0.02,0.02,\"\"\n"
                "a,curves,ok,5,5,4,0.01,0.01,0.01,\"\"\n"
                "a,hybrid,skipped,5,0,0,,,,\"curvesfm run has no --ba-points\"\n"
                "b,init,failed,6,0,0,,,,\"exit code 1\"\n"
                "b,colmap,ok,6,6,6,1.5,1.2,1.1,\"\"\n")
        write(d, "real_bench.csv", self.HEADER + rows)
        for s, count in (("a", 5), ("b", 6)):
            write(d, os.path.join(s, "groundtruth.txt"),
                  "".join(tum_line(k, *p) for k, p in enumerate(positions(count))))
        for s, v, count in (("a", "init", 5), ("a", "curves", 4), ("b", "colmap", 6)):
            write(d, os.path.join(s, v, "aligned_trajectory.txt"),
                  "".join(tum_line(k, *p) for k, p in enumerate(positions(count, 1.05))))

    def test_writes_the_bar_chart_and_the_trajectories(self):
        with tempfile.TemporaryDirectory() as d:
            self.write_bench(d)
            paths = real_bench.draw(d)
            self.assertTrue(all(os.path.getsize(p) > 0 for p in paths))
        self.assertEqual([os.path.basename(p) for p in paths],
                         ["ate_by_set.png", "trajectories.png"])

    def test_draws_the_first_repetition_only(self):
        header = "set,variant,start,repetition,status,ate_rmse,note\n"
        rows = ("a,curves,truth,1,ok,0.01,\"\"\n"
                "a,colmap,,1,ok,0.02,\"\"\n"
                "a,curves,truth,2,ok,0.01,\"\"\n"
                "a,colmap,,2,ok,0.03,\"\"\n")
        with tempfile.TemporaryDirectory() as d:
            write(d, "real_bench.csv", header + rows)
            read = real_bench.read_rows(os.path.join(d, "real_bench.csv"))
        self.assertEqual([(r["variant"], r["ate_rmse"]) for r in read],
                         [("curves_truth", 0.01), ("colmap", 0.02)])

    def test_missing_trajectory_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            self.write_bench(d)
            os.remove(os.path.join(d, "b", "colmap", "aligned_trajectory.txt"))
            code, message = run_package("real-bench", d)
        self.assertEqual(code, 1)
        self.assertIn(os.path.join(d, "b", "colmap", "aligned_trajectory.txt") + ": cannot read",
                      message)


if __name__ == "__main__":
    unittest.main()
