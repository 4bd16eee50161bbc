"""The misuse suite through Python and mpi4py (issue 42), 2 ranks: each case is a mistake a code makes
on one of its ranks; every rank must get a panoptes.Error naming the cause within 10 s, nothing may
hang (ctest's timeout is the hang detector) and the database stays readable.
    mpiexec -n 2 /usr/bin/python3 mpi_misuse.py OUT_DIR"""
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

import panoptes

NX, NY, NZ = 12, 10, 8
TOML = """
[output]
dir = "{dir}"
mode = "overwrite"
[image]
width = 32
height = 32
[rig]
spec = "fibonacci:3"
[schedule]
every_steps = 1
[resources]
mpi_timeout = 3
[[task]]
name = "T"
type = "volume"
field = "T"
"""
comm = MPI.COMM_WORLD
rank = comm.Get_rank()
failures = []


def expect_error(call, want, what, started):
    try:
        call()
    except panoptes.Error as e:
        waited = time.monotonic() - started
        if want not in str(e) or waited > 10:
            failures.append(f"{what}: after {waited:.1f} s: {e} (expected {want!r})")
        else:
            print(f"mpi_misuse: rank {rank}: {what}: error after {waited:.2f} s: {e}")
        return
    failures.append(f"{what}: no error")


def session(out):
    k0, k1 = NZ * rank // 2, NZ * (rank + 1) // 2
    s = panoptes.Session(TOML.format(dir=out), comm=comm)
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, k0), (NX, NY, k1 - k0))
    T = np.random.default_rng(rank).random((k1 - k0, NY, NX)).astype(np.float32)
    s.set_field("T", T)
    assert s.process(0, 0.0)
    return s, T


def short_array(out):
    """Rank 1's array is one plane short; its code catches the error and goes on."""
    started = time.monotonic()
    s, T = session(out)
    if rank == 1:
        try:
            s.set_field("T", T[1:])
        except panoptes.Error:
            pass
    expect_error(lambda: s.process(1, 0.1), 'field "T" is not bound' if rank == 1 else "rank 1 refused", "step 1", started)
    s.set_field("T", T)
    assert s.process(2, 0.2)
    s.finalize()


def skipped_step(out):
    """Rank 1 skips step 1's process()."""
    started = time.monotonic()
    s, T = session(out)
    if rank == 0:
        expect_error(lambda: s.process(1, 0.1), "out of step", "rank 0 at step 1", started)
    expect_error(lambda: s.process(2, 0.2), "out of step", "step 2", started)


def bad_config(out):
    """Rank 1's configuration is refused: every rank's Session() raises."""
    started = time.monotonic()
    text = "[image]\nwidth = -3\n" if rank == 1 else TOML.format(dir=out)
    expect_error(lambda: panoptes.Session(text, comm=comm), "image.width" if rank == 1 else "rank 1 failed", "Session()",
                 started)


def main():
    out = Path(sys.argv[1])
    for case in (short_array, skipped_step, bad_config):
        case(out / case.__name__)
        comm.Barrier()
    if rank == 0:
        for name in ("short_array", "skipped_step"):
            db = panoptes.open(out / name)
            print(f"mpi_misuse: {name}: database {db.status}, {db.frame_count} snapshots")
    bad = comm.allgather(failures)
    if rank == 0:
        for r, f in enumerate(bad):
            for line in f:
                print(f"mpi_misuse: rank {r}: FAIL: {line}", file=sys.stderr)
    if any(bad):
        sys.exit(1)
    if rank == 0:
        print("mpi_misuse: every rank got its error in time")


if __name__ == "__main__":
    main()
