"""Reading movie databases: manifest, cameras as NumPy arrays, decoded frames."""
import json
import os

import numpy as np

from . import _panoptes

__all__ = ["open", "Database", "Cameras"]

#: Columns of Cameras.neighbours, in order.
NEIGHBOUR_COLUMNS = ("left", "right", "up", "down", "in", "out")


class Cameras:
    """Every camera of a database, one NumPy array per field (row i = camera i).

    position, look_at, up: (N, 3) float64; fov: (N,) vertical field of view in degrees;
    latitude, longitude: (N,) degrees, of the direction from the look-at point to the camera;
    shell: (N,) int32 (0 = outermost); neighbours: (N, 6) int32 camera ids in the columns
    NEIGHBOUR_COLUMNS (left, right, up, down, in, out), -1 = none; patch: list of str.
    """

    def __init__(self, columns):
        self.position = columns["position"]
        self.look_at = columns["look_at"]
        self.up = columns["up"]
        self.fov = columns["fov"]
        self.latitude = columns["latitude"]
        self.longitude = columns["longitude"]
        self.shell = columns["shell"]
        self.neighbours = columns["neighbours"]
        self.patch = columns["patch"]
        self.has_navigation = columns["has_navigation"]
        for a in (self.position, self.look_at, self.up, self.fov, self.latitude, self.longitude, self.shell,
                  self.neighbours):
            a.flags.writeable = False

    def __len__(self):
        return len(self.fov)

    def direction(self):
        """Unit vectors from each camera's look-at point to the camera, (N, 3)."""
        d = self.position - self.look_at
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def neighbour(self, camera, direction):
        """The neighbour of `camera` in `direction` ("left", ..., "out"), or -1."""
        return int(self.neighbours[camera, NEIGHBOUR_COLUMNS.index(direction)])

    def __repr__(self):
        return f"<panoptes.Cameras: {len(self)} cameras>"


class Database:
    """An opened movie database (see panoptes.open)."""

    def __init__(self, path):
        self._db = _panoptes.Database(os.fspath(path))
        self._manifest = json.loads(self._db.manifest_json())
        self._cameras = None

    # ---- summary ----------------------------------------------------------------------------------
    @property
    def path(self):
        return self._db.path

    @property
    def title(self):
        return self._manifest.get("title", "")

    @property
    def status(self):
        """"complete", "running" (a live writer holds the lock) or "interrupted"."""
        return self._db.status

    @property
    def frame_count(self):
        """Complete frames: every stream holds at least this many."""
        return self._db.frame_count

    @property
    def times(self):
        """Simulation time of each frame, (frame_count,) float64."""
        return self._db.times

    @property
    def image_size(self):
        """(width, height) of every frame."""
        image = self._manifest["image"]
        return image["width"], image["height"]

    @property
    def fps(self):
        return self._manifest.get("video", {}).get("fps", 30)

    @property
    def domain(self):
        """dims, origin, spacing, units of the simulation grid (dims 0 = unknown)."""
        return self._manifest.get("domain", {})

    @property
    def rig(self):
        return self._manifest.get("rig", {})

    @property
    def projection(self):
        """"perspective", or "equirectangular": every frame is a whole 360 x 180 degree panorama around a
        camera inside the volume (longitude along the width, latitude along the height), not a view. Shown
        as an image it looks distorted; `panoptes play` looks around in it and `panoptes export-path
        --view-size WxH` cuts perspective views out of it."""
        return self.rig.get("parameters", {}).get("projection", "perspective")

    @property
    def provenance(self):
        return self._manifest.get("provenance", {})

    @property
    def manifest(self):
        """The manifest as a dict (without the per-camera rows; see cameras)."""
        return self._manifest

    # ---- cameras, tasks, axes ---------------------------------------------------------------------
    @property
    def cameras(self):
        if self._cameras is None:
            self._cameras = Cameras(self._db.cameras())
        return self._cameras

    @property
    def camera_count(self):
        return self._db.camera_count

    @property
    def tasks(self):
        """List of dicts: id, name, method, fields, parameters, axes ([{axis, index}])."""
        return self._manifest.get("tasks", [])

    @property
    def task_count(self):
        return self._db.task_count

    @property
    def axes(self):
        """Parameter axes: {name: numpy array of values}."""
        return {a["name"]: np.asarray(a["values"], dtype=float) for a in self._manifest.get("axes", [])}

    def task_index(self, name):
        """Index of the task called `name`."""
        for t in self.tasks:
            if t["name"] == name:
                return t["id"]
        raise Error(f"{self.path}: no task named {name!r}; tasks: {', '.join(t['name'] for t in self.tasks)}")

    # ---- frames -----------------------------------------------------------------------------------
    def frame(self, camera, task, frame):
        """Frame `frame` of stream (camera, task) as a new uint8 array (H, W, 3), RGB. `task` may be a
        name."""
        if isinstance(task, str):
            task = self.task_index(task)
        return self._db.frame(int(camera), int(task), int(frame))

    def stream(self, camera, task, start=0, stop=None):
        """Iterates over the frames start..stop-1 of stream (camera, task) (one decode per frame)."""
        if isinstance(task, str):
            task = self.task_index(task)
        stop = self.frame_count if stop is None else min(stop, self.frame_count)
        for f in range(start, stop):
            yield self._db.frame(int(camera), int(task), f)

    def stream_path(self, camera, task):
        """Path of the stream's MP4 movie (files layout; a packed database has none: see packed_stream)."""
        return self._db.stream_path(int(camera), int(task))

    @property
    def packed(self):
        """True when the movies live in packs (docs/formats.md, Packed layout)."""
        return self._db.packed

    def packed_stream(self, camera, task):
        """A packed stream as byte ranges: a list of dicts (file, offset, size, first_frame, frames), the
        init segment first; their bytes concatenated are a fragmented MP4 any player opens."""
        return self._db.packed_stream(int(camera), int(task))

    def __repr__(self):
        w, h = self.image_size
        return (f"<panoptes.Database {str(self.path)!r}: {self.title!r}, {self.status}, {self.camera_count} cameras x "
                f"{self.task_count} tasks, {self.frame_count} frames of {w}x{h}"
                f"{' (360-degree equirectangular panoramas)' if self.projection == 'equirectangular' else ''}>")


Error = _panoptes.Error


def open(path):
    """Opens the movie database in directory `path` (reads the manifest and camera table only)."""
    return Database(path)
