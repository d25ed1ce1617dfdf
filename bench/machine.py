"""The machine a benchmark ran on, for its table: the CPU's model, threads and vector ISA."""

import os
import platform


def cpu_line():
    try:
        info = open("/proc/cpuinfo").read()
    except OSError:
        return platform.processor()
    model = next((l.split(":", 1)[1].strip() for l in info.splitlines() if l.startswith("model name")), "?")
    flags = next((l.split(":", 1)[1].split() for l in info.splitlines() if l.startswith("flags")), [])
    isa = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE"
    return f"{model}, {os.cpu_count()} threads, {isa}"


def pathlab_build(pathlab):
    """`pathlab --version`: its version and which build runs (the baseline, or the variant for
    this CPU that deploy/build-variants.sh put beside it)."""
    import subprocess
    return subprocess.run([pathlab, "--version"], capture_output=True, text=True).stdout.strip()
