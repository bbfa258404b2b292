"""The machine context of a run: CPU model and vector width, the measured
FMA ceiling and streaming bandwidth (bench/calibration_bench.cpp), the
Vulkan device and driver, and what bench/run_suite recorded about the run
(commands, start, duration, git commit) in run.json beside the results."""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Machine:
    cpu_model: str = "unknown CPU"
    cores: int = 0
    vector_bits: int = 0  # widest float vector the CPU offers: 512, 256, 128
    # The ceilings are per CPU-second (the rate while the thread runs: the
    # hardware's limit on a shared machine); the *_wall figures are per
    # second of wall clock, as the search cells are measured.
    fma_gflops_per_core: dict = field(default_factory=dict)  # "avx2"/"avx512" -> GFLOP per CPU-second
    fma_gflops_wall: dict = field(default_factory=dict)
    stream_gbs: dict = field(default_factory=dict)  # threads -> GB per CPU-second of each thread, summed
    stream_gbs_wall: dict = field(default_factory=dict)
    vulkan: str | None = None  # "device | driver version", None when not measured
    vulkan_error: str | None = None
    load_avg: list = field(default_factory=list)
    date: str = ""
    run: dict = field(default_factory=dict)  # run.json of bench/run_suite

    @property
    def fma_ceiling_per_core(self):
        """GFLOP/s of one core at the widest measured FMA."""
        return max(self.fma_gflops_per_core.values(), default=None)

    @property
    def fma_ceiling(self):
        per_core = self.fma_ceiling_per_core
        return per_core * self.cores if per_core and self.cores else None

    @property
    def stream_ceiling(self):
        """GB/s of the best streaming read (every thread)."""
        return max(self.stream_gbs.values(), default=None)


def _cpuinfo():
    """(model, flags) from /proc/cpuinfo; empty where unreadable."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return "", set()
    model = re.search(r"^model name\s*:\s*(.+)$", text, re.M)
    flags = re.search(r"^flags\s*:\s*(.+)$", text, re.M)
    return (model.group(1).strip() if model else "", set(flags.group(1).split()) if flags else set())


def vector_bits(flags):
    if "avx512f" in flags:
        return 512
    if "avx2" in flags or "avx" in flags:
        return 256
    return 128 if flags else 0


def describe_live():
    """What run_suite records about the CPU, read here and now."""
    model, flags = _cpuinfo()
    return {"cpu_model": model, "cores": os.cpu_count() or 0, "vector_bits": vector_bits(flags),
            "avx512f": "avx512f" in flags, "fma": "fma" in flags}


def build(data, run_json: Path | None = None) -> Machine:
    machine = Machine()
    run = {}
    if run_json is not None and run_json.exists():
        run = json.loads(run_json.read_text())
    cpu = run.get("cpu") or describe_live()
    machine.run = run
    machine.cpu_model = cpu.get("cpu_model") or machine.cpu_model
    machine.vector_bits = int(cpu.get("vector_bits") or 0)
    context = data.contexts[0] if data.contexts else {}
    machine.cores = int(context.get("num_cpus") or cpu.get("cores") or 0)
    machine.load_avg = context.get("load_avg", [])
    machine.date = context.get("date", "")
    for name, calibration in data.calibrations.items():
        if calibration.error:
            if name.startswith("calibration/vulkan_device"):
                machine.vulkan_error = calibration.error
            continue
        counters = calibration.counters
        # Google Benchmark's cpu_time is per thread, like real_time.
        busy = float(counters.get("real_time", 1)) / float(counters.get("cpu_time") or counters.get("real_time", 1))
        if m := re.match(r"calibration/fma_peak/(\w+)", name):
            machine.fma_gflops_wall[m.group(1)] = float(counters["flops/s"]) / 1e9
            machine.fma_gflops_per_core[m.group(1)] = machine.fma_gflops_wall[m.group(1)] * busy
        elif name.startswith("calibration/stream_read"):
            found = re.search(r"threads:(\d+)", name)
            threads = int(found.group(1)) if found else 1
            machine.stream_gbs_wall[threads] = float(counters["bytes/s"]) / 1e9
            machine.stream_gbs[threads] = machine.stream_gbs_wall[threads] * busy
        elif name.startswith("calibration/vulkan_device"):
            machine.vulkan = calibration.label
    return machine
