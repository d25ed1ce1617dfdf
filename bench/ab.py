#!/usr/bin/env python3
"""Two pathlab builds on one scene, in turns: the ratio of their samples per second.

    python3 bench/ab.py OLD NEW N -- [render arguments...]

runs `OLD render ARGS --json -o ...` and `NEW render ...` N times each, alternating which goes
first, with PATHLAB_NO_VARIANT=1 (each binary as built, not a variant beside it). It prints
the mean of the log ratios with its standard error (pairs taken in turns), the ratio of the
medians, and the ratio of the best rates: on a machine whose neighbours take memory bandwidth
and cache at times, a run is only ever slowed, so the best of N is the steadier figure there.
It also says whether the last two images are the same to the bit (EXR files byte for byte).
"""

import filecmp
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile


def rate(binary, args, out):
    env = dict(os.environ, PATHLAB_NO_VARIANT="1")
    r = subprocess.run(
        [binary, "render", *args, "--json", "-o", out],
        capture_output=True,
        text=True,
        env=env,
    )
    if r.returncode:
        sys.exit(f"{binary} failed:\n{r.stderr}")
    return json.loads(r.stdout)["samples_per_second"]


def main():
    if len(sys.argv) < 5 or sys.argv[4] != "--":
        sys.exit(__doc__)
    old, new, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
    args = sys.argv[5:]
    if n < 2:
        sys.exit("ab.py: N must be at least 2")
    work = tempfile.mkdtemp(prefix="pathlab-ab-")
    out_old, out_new = os.path.join(work, "old.exr"), os.path.join(work, "new.exr")
    a, b = [], []
    for k in range(n):
        if k % 2 == 0:
            a.append(rate(old, args, out_old))
            b.append(rate(new, args, out_new))
        else:
            b.append(rate(new, args, out_new))
            a.append(rate(old, args, out_old))
    logs = [math.log(y / x) for x, y in zip(a, b)]
    m = sum(logs) / n
    se = math.sqrt(sum((v - m) ** 2 for v in logs) / (n - 1) / n)
    same = filecmp.cmp(out_old, out_new, shallow=False)
    print(
        f"{' '.join(args)}: x{math.exp(m):.3f} +- {se:.3f} (mean log ratio, {n} pairs); "
        f"medians x{statistics.median(b) / statistics.median(a):.3f}; "
        f"best x{max(b) / max(a):.3f} ({max(a) / 1e6:.3f} -> {max(b) / 1e6:.3f} M samples/s); "
        f"images {'the same' if same else 'DIFFERENT'}"
    )


if __name__ == "__main__":
    main()
