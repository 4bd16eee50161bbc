"""Two MPI ranks (mpi4py) write one database through panoptes.Session; rank 0 then writes the same
field alone (COMM_SELF) and checks that both databases hold the same frames.
    mpiexec -n 2 /usr/bin/python3 mpi_session.py OUT_DIR"""
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

import panoptes

NX, NY, NZ = 24, 20, 16
TOML = """
[output]
dir = "{dir}"
overwrite = true
[image]
width = 48
height = 40
[rig]
spec = "fibonacci:5"
[schedule]
every_steps = 1
[[task]]
name = "temperature"
type = "volume"
field = "T"
preset = "hot"
relative = false
window = [0.0, 1.0]
[[task]]
name = "isotherm"
type = "isosurface"
field = "T"
isovalues = [0.4]
"""


def field(k0, k1, step):
    z, y, x = np.mgrid[k0:k1, 0:NY, 0:NX]
    return np.exp(-((x - 6 - 4 * step) ** 2 + (y - 10) ** 2 + (z - 8) ** 2) / 20.0).astype(np.float32)


def run(comm, out):
    rank, size = comm.Get_rank(), comm.Get_size()
    k0, k1 = NZ * rank // size, NZ * (rank + 1) // size
    s = panoptes.Session(TOML.format(dir=out), comm=comm)
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, k0), (NX, NY, k1 - k0))
    for step in range(3):
        T = field(k0, k1, step)
        s.set_field("T", T)
        assert s.process(step, float(step))
    assert s.ranks == size
    s.finalize()


def main():
    out = Path(sys.argv[1])
    world = MPI.COMM_WORLD
    assert world.Get_size() == 2, "run with 2 ranks"
    run(world, out / "two_ranks")
    world.Barrier()
    if world.Get_rank() == 0:
        run(MPI.COMM_SELF, out / "one_rank")
        a, b = panoptes.open(out / "two_ranks"), panoptes.open(out / "one_rank")
        assert a.status == "complete" and a.frame_count == 3 and a.camera_count == 5 and a.task_count == 2
        assert a.provenance["extra"]["mpi_ranks"] == "2"
        worst = 0
        for c in range(5):
            for t in range(2):
                for f in range(3):
                    worst = max(worst, int(np.abs(a.frame(c, t, f).astype(int) - b.frame(c, t, f).astype(int)).max()))
        print(f"mpi_session: 2 ranks vs 1 rank, 30 frames, max pixel difference {worst}")
        assert worst <= 3, worst
    world.Barrier()


if __name__ == "__main__":
    main()
