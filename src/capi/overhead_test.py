#!/usr/bin/env python3
"""capi.overhead_vs_os: the in-situ overhead line against the operating system's CPU count (issue 41, 7).

overhead_sim runs twice on R ranks: with every panoptes_* call skipped ("off") and with them ("on").
Each rank runs under this script's --wrap mode, which starts it as a child and takes the child's CPU
time (user + system, all its threads) from wait4's rusage, as `time` does. So

    true overhead = (CPU with Panoptes - CPU without) / CPU without      (summed over the ranks)

and the line panoptes_finalize printed (one rank: its ratio; several: "all ranks together") must be
within 10 % of it. CPU time of a fixed workload varies on a busy machine (the code's own CPU by 5-10 %
from run to run at load 8-10 on the shared 2-core VM, and in bursts up to 2x: the host's other work,
the other engineers' compilers, MPI start-up), which the ratio amplifies, while the line's own ratio
stays within a few % (it divides two CPU times of one run); so a pair that misses is run again, up to
four times, and each
time the pairs so far are also pooled (true overhead of the summed CPU times against the mean of the
lines), which averages the noise out where one pair alone would not.

One rank is measured but not asserted (RANKS entry "1:report"): there the code's own loop, timed by its
thread's CPU clock, ran 0.1-0.4 CPU-s slower in the run with Panoptes than in the run without it, in
some runs and not in others (1.62 s against 2.03 s, then 1.64 against 1.64; with OMP_NUM_THREADS=1 and
OMP_WAIT_POLICY=passive too; in one binary more often than in a byte-for-byte rebuild of it with other
addresses), so the OS's difference of two runs said 0.13x..0.57x where the line said 0.28x..0.35x. That
is a cost of sharing one core with Panoptes (caches, predictors, the OpenMP worker bound to the same
core) that no meter inside the code can see, plus the host's noise; it is written in docs/insitu.md.
Two ranks, the issue's setting, one core each, agree within a few % in every run seen.

    overhead_test.py OVERHEAD_SIM WORKDIR MPIEXEC RANKS[:report]...
    overhead_test.py --wrap OUTFILE CMD...     (per rank, under mpiexec)
"""
import os
import re
import subprocess
import sys
import time

TOLERANCE = 0.10
ATTEMPTS = 4
# Grid and steps: a grid whose two arrays (4 MB) stay in the cache, so the code's CPU time is
# compute-bound and repeats within ~2 % (a 128x128x96 grid, memory-bound, varied by 10-25 % at load 8
# on the shared 2-core machine); enough steps that it takes ~1.8 CPU-s (MPI start-up, ~0.25 CPU-s per rank
# and noisy, a small part of it), the visualization (11
# snapshots of 12 cameras x 2 tasks at 160x160 on 2 OpenMP threads) about as much.
GRID = (64, 64, 64)
STEPS = 4000
EVERY = 400
CONFIG = """[output]
dir = "{dir}"
overwrite = true
[image]
width = 160
height = 160
[rig]
spec = "fibonacci:12"
[schedule]
every_steps = {every}
[[task]]
name = "volume"
type = "volume"
field = "T"
preset = "hot"
relative = false
window = [0.0, 0.5]
[[task]]
name = "iso"
type = "isosurface"
field = "T"
isovalues = [0.05, 0.2]
"""


def wrap(out, cmd):
    """Runs cmd as a child and appends its CPU seconds (wait4 rusage: user + system) to out."""
    pid = os.fork()
    if pid == 0:
        try:
            os.execvp(cmd[0], cmd)
        finally:
            os._exit(127)
    _, status, usage = os.wait4(pid, 0)
    cpu = usage.ru_utime + usage.ru_stime
    with open(out, "a") as f:  # one short O_APPEND write per rank
        f.write(f"{cpu:.6f}\n")
    code = os.waitstatus_to_exitcode(status)
    sys.exit(code if code >= 0 else 128 - code)


def run(sim, workdir, mpiexec, ranks, mode):
    """One run; returns (OS CPU seconds summed over ranks, the program's stderr)."""
    cpu_file = os.path.join(workdir, f"cpu_{ranks}_{mode}.txt")
    if os.path.exists(cpu_file):
        os.remove(cpu_file)
    config = os.path.join(workdir, f"overhead_{ranks}.toml")
    with open(config, "w") as f:
        f.write(CONFIG.format(dir=os.path.join(workdir, f"db_{ranks}"), every=EVERY))
    cmd = [mpiexec, "--oversubscribe", "-np", str(ranks), sys.executable, os.path.abspath(__file__), "--wrap",
           cpu_file, sim, config, mode] + [str(n) for n in GRID] + [str(STEPS), str(EVERY)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited with {p.returncode}\n{p.stdout}\n{p.stderr}")
    with open(cpu_file) as f:
        values = [float(v) for v in f.read().split()]
    if len(values) != ranks:
        sys.exit(f"FAIL: {cpu_file} has {len(values)} CPU times for {ranks} ranks")
    return sum(values), p.stderr


def reported_ratio(stderr, ranks):
    """The ratio of Panoptes' overhead line (also the older wall-time wording, to show what it said)."""
    patterns = [r"visualization used ([0-9.]+)x the simulation's CPU time",
                r"all ranks together ([0-9.]+)x",
                # the wall-time line before issue 41 (one rank; several: the median)
                r"visualization took ([0-9.]+)x the simulation time",
                r"visualization time / simulation time per rank: min [0-9.]+x, median ([0-9.]+)x"]
    for p in patterns:
        m = re.search(p, stderr)
        if m:
            return float(m.group(1))
    sys.exit(f"FAIL: no in-situ overhead line for {ranks} rank(s) in:\n{stderr}")


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--wrap":
        wrap(sys.argv[2], sys.argv[3:])
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    sim, workdir, mpiexec = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(workdir, exist_ok=True)
    failed = False
    for spec in sys.argv[4:]:
        ranks, _, mode = spec.partition(":")
        ranks, report_only = int(ranks), mode == "report"
        sum_without = sum_with = sum_line = 0.0
        for attempt in range(1, ATTEMPTS + 1):
            t0 = time.monotonic()
            # Alternate the order, so that a machine getting busier or quieter during the test does
            # not favour one side of the pooled sums.
            if attempt % 2:
                without, _ = run(sim, workdir, mpiexec, ranks, "off")
                with_viz, stderr = run(sim, workdir, mpiexec, ranks, "on")
            else:
                with_viz, stderr = run(sim, workdir, mpiexec, ranks, "on")
                without, _ = run(sim, workdir, mpiexec, ranks, "off")
            line = reported_ratio(stderr, ranks)
            sum_without += without
            sum_with += with_viz
            sum_line += line
            true = (with_viz - without) / without
            error = abs(line - true) / true if true > 0 else float("inf")
            pooled_true = (sum_with - sum_without) / sum_without
            pooled_line = sum_line / attempt
            pooled_error = abs(pooled_line - pooled_true) / pooled_true if pooled_true > 0 else float("inf")
            print(f"{ranks} rank(s), attempt {attempt}: OS CPU without {without:.2f} s, with {with_viz:.2f} s "
                  f"-> overhead {true:.3f}x; the line says {line:.2f}x ({100 * error:.1f} % off"
                  + (f"; pooled over {attempt}: {pooled_true:.3f}x vs {pooled_line:.3f}x, "
                     f"{100 * pooled_error:.1f} % off" if attempt > 1 else "")
                  + f"; {time.monotonic() - t0:.1f} s wall)")
            print("  " + "\n  ".join(l for l in stderr.splitlines() if "overhead" in l or "rank " in l))
            sys.stdout.flush()
            if min(error, pooled_error) <= TOLERANCE:
                break
            if report_only and attempt >= 2:
                print(f"{ranks} rank(s): reported, not asserted (see the docstring)")
                break
        else:
            print(f"FAIL: {ranks} rank(s): the overhead line is more than {100 * TOLERANCE:.0f} % off the OS's "
                  f"count in {ATTEMPTS} attempts")
            failed = True
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
