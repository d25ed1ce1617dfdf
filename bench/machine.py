"""The machine a benchmark ran on, for its table: the CPU's model (with AMD's core generation,
which its model name leaves out: "AMD EPYC" covers Zen 1 to Zen 5), threads and vector ISA."""

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
    field = lambda name: next((l.split(":", 1)[1].strip() for l in info.splitlines()
                               if l.split(":", 1)[0].strip() == name), "")
    family, number = field("cpu family"), field("model")
    core = ""
    if family.isdigit() and number.isdigit():
        core = f" (family {family}, model {number}"
        generation = amd_core(int(family), int(number)) if "AMD" in model else None
        core += f", {generation})" if generation else ")"
    return f"{model}{core}, {os.cpu_count()} threads, {isa}"


def amd_core(family, model):
    """AMD's core generation from the CPU's family and model numbers (AMD's processor
    programming references), or None for families before Zen."""
    if family == 0x17:
        return "Zen 2" if model >= 0x30 else "Zen or Zen+"
    if family == 0x19:
        return "Zen 4" if 0x10 <= model <= 0x1F or 0x60 <= model <= 0x7F or 0xA0 <= model <= 0xAF else "Zen 3"
    if family == 0x1A:
        return "Zen 5"
    return None


def pathlab_build(pathlab):
    """`pathlab --version`: its version and which build runs (the baseline, or the variant for
    this CPU that deploy/build-variants.sh put beside it)."""
    import subprocess
    return subprocess.run([pathlab, "--version"], capture_output=True, text=True).stdout.strip()
