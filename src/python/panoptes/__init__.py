"""Panoptes from Python: movie databases, the player engine and in-situ visualization.

    import panoptes
    db = panoptes.open("out/demo")            # manifest only; no movie is opened yet
    db.cameras.position                       # (N, 3) NumPy array; also look_at, up, fov, latitude, ...
    img = db.frame(camera=3, task=1, frame=10)  # uint8 (H, W, 3), decoded as the player shows it
    for img in db.stream(3, 1): ...           # every frame of one (camera, task) movie

    p = panoptes.Player(db)                   # the playback engine, headless, on a virtual clock
    p.navigate("right"); p.step_axis("isovalue", +1); p.seek(5); p.image()

    s = panoptes.Session("viz.toml", comm=MPI.COMM_WORLD)   # in situ, from a simulation
    s.set_grid(dims, origin, spacing); s.set_block(offset, extent, ghost_lo, ghost_hi)
    s.set_field("T", T)                       # float32/float64 (nz, ny, nx) incl. ghosts, not copied
    s.process(step, time); s.finalize()

Errors raise panoptes.Error (panoptes.FileError for files) with the messages the command line prints.
"""
from ._panoptes import Error, FileError, __version__  # CMake project(VERSION), one place
from .database import Cameras, Database, open
from .player import Player
from .session import Session

__all__ = ["open", "Database", "Cameras", "Player", "Session", "Error", "FileError"]
