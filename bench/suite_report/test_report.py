"""Tests of bench/report and bench/run_suite's cell selection, on Google
Benchmark JSON made here (no benchmark runs). Run by ctest (bench_report,
label cpu) or:  /usr/bin/python3 -m unittest discover -s bench/suite_report
"""

import importlib.machinery
import importlib.util
import json
import re
import sys
import tempfile
import unittest
from pathlib import Path

sys.dont_write_bytecode = True
BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

from suite_report import cells, report  # noqa: E402


def load_run_suite():
    loader = importlib.machinery.SourceFileLoader("run_suite", str(BENCH / "run_suite"))
    spec = importlib.util.spec_from_loader("run_suite", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


N = {"locomotion": 21791, "volume104k": 104000, "volume": 416845, "volume-mirrored": 833690}
# µs/query at N = 22k and the growth exponent, per method (made-up, plausible).
COST = {"reference": (1400, 1.0), "fast-brute": (40, 1.0), "fast-box": (30, 0.9), "clusters": (8, 0.6),
        "nprobe4": (4, 0.6), "nprobe16": (6, 0.6), "vulkan-brute": (90, 1.0), "vulkan-nprobe16": (60, 0.8),
        "faiss-flat": (35, 1.0), "faiss-flat-1q": (60, 1.0), "faiss-ivf4": (5, 0.5), "faiss-ivf16": (9, 0.5),
        "pca-kdtree300": (20, 0.4), "box-scan": (50, 0.9)}
RECALL = {"nprobe4": 0.95, "nprobe16": 0.995, "vulkan-nprobe16": 0.995, "faiss-ivf4": 0.9, "faiss-ivf16": 0.99,
          "pca-kdtree300": 0.97, "faiss-flat": 0.999, "faiss-flat-1q": 0.999}


def suite_run(dataset, method, batch, stream="transition", schema="default27", error=None):
    us, exponent = COST[method]
    us *= (N[dataset] / N["locomotion"]) ** exponent
    run = {"name": f"suite/{dataset}/{schema}/{stream}/{method}/B:{batch}/real_time",
           "run_name": f"suite/{dataset}/{schema}/{stream}/{method}/B:{batch}/real_time",
           "run_type": "iteration", "iterations": 10, "real_time": us * batch, "cpu_time": us * batch,
           "time_unit": "us", "us_per_query": us, "queries_per_s": 1e6 / us, "rows_fraction": 0.01,
           "recall1": RECALL.get(method, 1.0), "recall10": RECALL.get(method, 1.0), "db_bytes": N[dataset] * 108,
           "index_bytes": 1000, "device_bytes": N[dataset] * 108 if method.startswith("vulkan") else 0,
           "build_s": 0.5, "kernel_us_per_query": us * 0.9 if method.startswith("vulkan") else 0,
           "N": N[dataset], "dims": 27, "near_ties": 1 if method.startswith("faiss-flat") else 0}
    if error:
        run = {"name": run["name"], "run_name": run["run_name"], "run_type": "iteration", "error_occurred": True,
               "error_message": error}
    return run


def calibration_runs(vulkan=True):
    runs = [{"name": "calibration/fma_peak/avx2/real_time", "run_type": "iteration", "real_time": 5.0,
             "cpu_time": 2.5, "time_unit": "ms", "flops/s": 30e9},
            {"name": "calibration/stream_read/real_time/threads:2", "run_type": "iteration", "real_time": 16.0,
             "cpu_time": 16.0, "time_unit": "ms", "bytes/s": 33e9}]
    if vulkan:
        runs.append({"name": "calibration/vulkan_device/iterations:1", "run_type": "iteration", "real_time": 1,
                     "cpu_time": 1, "time_unit": "ns", "label": "llvmpipe (LLVM 15.0.6, 256 bits) | llvmpipe Mesa 22.3.6"})
    else:
        runs.append({"name": "calibration/vulkan_device/iterations:1", "run_type": "iteration",
                     "error_occurred": True, "error_message": "no Vulkan device"})
    return runs


def document(runs):
    return {"context": {"date": "2026-11-23T16:00:00+00:00", "num_cpus": 2, "load_avg": [1.0, 1.5, 2.0]},
            "benchmarks": runs}


HAND_WRITTEN = "# Benchmark results\n\n## Someone else's section\n\nKeep me.\n"


class ReportTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        self.results = self.dir / "RESULTS.md"
        self.results.write_text(HAND_WRITTEN)

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, name, runs):
        path = self.dir / name
        path.write_text(json.dumps(document(runs)))
        return path

    def report(self, *paths, plots=True):
        # Plots take seconds each: only the tests about them draw them.
        extra = [] if plots else ["--no-plots"]
        self.assertEqual(report.main([str(p) for p in paths] + ["--results", str(self.results)] + extra), 0)
        return self.results.read_text()

    def full_runs(self, methods=COST, datasets=N):
        return [suite_run(d, m, b) for d in datasets for m in methods for b in (1, 64, 1024)]

    def test_full_input_gives_every_table_and_plot(self):
        text = self.report(self.write("cal.json", calibration_runs()), self.write("suite.json", self.full_runs()))
        self.assertIn("Keep me.", text)
        self.assertIn(report.BEGIN, text)
        self.assertIn(report.END, text)
        for name, _ in report.PLOTS:
            svg = self.dir / "plots" / name
            self.assertTrue(svg.exists(), name)
            self.assertIn("<svg", svg.read_text()[:2000])
            self.assertIn(f"(plots/{name})", text)
        self.assertIn("#### volume (N = 416,845), default27, transition", text)
        self.assertIn("### µs/query against N", text)
        self.assertIn("### Against the machine's limit", text)
        # The fixture: faiss-ivf16 is the cheapest IVF setting at recall 0.99; no KD-tree setting reaches it.
        self.assertRegex(text, r"\| faiss-ivf \| `faiss-ivf16` \|")
        self.assertRegex(text, r"\| pca-kdtree \| none \(best: `pca-kdtree300`\) \|")
        self.assertIn("llvmpipe", text)
        # FMA ceiling per CPU-second: 30 GFLOP/s of wall at half the CPU.
        self.assertIn("AVX2 60.0 GFLOP/s per core", text)
        self.assertNotIn("Not in this run", text)
        # The clusters row's growth exponent is the one the data was made with.
        scale = text[text.index("### µs/query against N"):]
        self.assertRegex(scale, r"\| `clusters` \|[^\n]*\| 0\.60 \|")
        self.assertRegex(text, r"\| `faiss-flat` \| 0\.9990 \| 1 \| 1 \|")

    def test_missing_peers_and_vulkan_are_said_not_fatal(self):
        cpu_only = [m for m in COST if cells.method_info(m)[2] == "mmvk"]
        text = self.report(self.write("cal.json", calibration_runs(vulkan=False)),
                           self.write("suite.json", self.full_runs(methods=cpu_only)))
        self.assertIn("Not in this run", text)
        self.assertIn("- FAISS: no cells", text)
        self.assertIn("- mmvk Vulkan backends: no cells", text)
        self.assertIn("Vulkan: none in this run (no Vulkan device)", text)
        for name, _ in report.PLOTS:
            self.assertTrue((self.dir / "plots" / name).exists(), name)

    def test_skipped_cells_are_listed(self):
        runs = self.full_runs(datasets=["locomotion"]) + [suite_run("locomotion", "box-scan", 8192, error="peer failed")]
        text = self.report(self.write("suite.json", runs), plots=False)
        self.assertIn("| skipped |", text)
        self.assertIn("`box-scan` B=8192: peer failed", text)

    def test_rerun_replaces_the_section_only(self):
        path = self.write("suite.json", self.full_runs(datasets=["locomotion", "volume"]))
        first = self.report(path, plots=False)
        self.results.write_text(first + "\n## Added later\n\nStays.\n")
        second = self.report(path, plots=False)
        self.assertEqual(second.count(report.BEGIN), 1)
        self.assertIn("Stays.", second)
        self.assertEqual(second.replace("\n## Added later\n\nStays.\n", ""), first)

    def test_no_cells_still_writes_a_section(self):
        text = self.report(self.write("cal.json", calibration_runs()))
        self.assertIn("No suite cells in the input.", text)
        self.assertIn("Keep me.", text)

    def test_mmvk_bench_cells_are_read_as_suite_cells(self):
        runs = [{"name": "real/volume/transition/clusters-nprobe16/B:1024/real_time", "run_type": "iteration",
                 "real_time": 102.0, "cpu_time": 20.0, "time_unit": "ms", "queries/s": 10039.0,
                 "recall@1": 0.97, "rows_fraction": 0.007, "frames": 416845}]
        data = cells.load([self.write("old.json", runs)])
        cell = data.cells[("volume", "default27", "transition", "nprobe16", 1024)]
        self.assertAlmostEqual(cell.us_per_query, 102000.0 / 1024)
        self.assertEqual(cell.get("recall1"), 0.97)
        self.assertEqual(cell.get("N"), 416845)

    def test_repetitions_use_the_median(self):
        runs = [dict(suite_run("locomotion", "clusters", 64), us_per_query=v) for v in (5.0, 9.0, 6.0)]
        data = cells.load([self.write("suite.json", runs)])
        self.assertEqual(data.cells[("locomotion", "default27", "transition", "clusters", 64)].us_per_query, 6.0)


class RunSuiteSelectionTest(unittest.TestCase):
    def setUp(self):
        self.run_suite = load_run_suite()

    def names(self):
        return [f"suite/{d}/{s}/{st}/{m}/B:{b}/real_time" for d in N for s in ("default27", "wide60")
                for st in ("continue", "transition", "uniform") for m in COST for b in (1, 64, 1024, 8192)]

    def test_filter_matches_exactly_the_selected_cells(self):
        for preset in ("quick", "full"):
            select, _ = self.run_suite.PRESETS[preset]
            chosen = {n for n in self.names() if select(*self.run_suite.parse(n)[1])[0]}
            self.assertTrue(chosen)
            pattern = re.compile(self.run_suite.filter_for([self.run_suite.parse(n)[0] for n in chosen]))
            matched = {n for n in self.names() if pattern.search(n)}
            self.assertEqual(matched, chosen, preset)

    def test_full_leaves_out_the_slow_cells_and_keeps_the_headline(self):
        select, _ = self.run_suite.PRESETS["full"]
        self.assertFalse(select("volume", "default27", "transition", "reference", 1024)[0])
        self.assertFalse(select("volume-mirrored", "default27", "transition", "vulkan-brute", 8192)[0])
        single_query = ("reference", "box-scan", "pca-kdtree300", "faiss-flat-1q")
        for method in COST:
            # The headline slice: every method at B = 1024 but the reference,
            # B = 8192 for the batched CPU methods and FAISS flat / IVF.
            self.assertEqual(select("volume", "default27", "transition", method, 1024)[0], method != "reference")
            batched = method not in single_query and not method.startswith("vulkan")
            self.assertEqual(select("volume", "default27", "transition", method, 8192)[0], batched, method)
        for dataset in N:
            self.assertTrue(select(dataset, "default27", "transition", "clusters", 1024)[0], dataset)

    def test_check_names_what_is_missing(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp)
            problems = self.run_suite.check(out / "calibration.json", out / "suite.json", out / "RESULTS.md",
                                            out / "plots")
            self.assertEqual(len(problems), 5, problems)
            (out / "suite.json").write_text(json.dumps(document([suite_run("locomotion", "clusters", 1)])))
            (out / "calibration.json").write_text(json.dumps(document(calibration_runs())))
            (out / "RESULTS.md").write_text(report.BEGIN + "\n" + report.END + "\n")
            (out / "plots").mkdir()
            for plot in ("qps_vs_batch.svg", "recall_vs_time.svg"):
                (out / "plots" / plot).write_text("<svg/>")
            self.assertEqual(self.run_suite.check(out / "calibration.json", out / "suite.json", out / "RESULTS.md",
                                                  out / "plots"), [])


if __name__ == "__main__":
    unittest.main()
