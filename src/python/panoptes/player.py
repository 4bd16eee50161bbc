"""The playback engine, headless: scripted navigation and frames for notebooks and figures."""
import json
import os

from . import _panoptes


class Player:
    """The player's engine on a database (a panoptes.Database or a path), without a window; the start
    task is an index or a name.

    Time only moves when advance(seconds) is called (a virtual clock at the database's frame rate),
    so a script shows the same frames on every machine. Commands return False when they cannot apply
    (no such neighbour, end of an axis), as the keys of the window player do.
    """

    def __init__(self, db, camera=0, task=0, frame=0, prefetch=True, cache_mb=256):
        path = db.path if hasattr(db, "path") else db
        self._p = _panoptes.Player(os.fspath(path), camera, task, frame, prefetch, cache_mb)

    @property
    def selection(self):
        """{"camera", "task", "frame"} now shown."""
        return self._p.selection

    camera = property(lambda self: self._p.selection["camera"])
    task = property(lambda self: self._p.selection["task"])
    frame_index = property(lambda self: self._p.selection["frame"])
    frame_count = property(lambda self: self._p.frame_count)
    playing = property(lambda self: self._p.playing)
    fps = property(lambda self: self._p.fps)

    def key(self, name):
        """Press a key of the players' key table ("Up", "Shift+Tab", "3"), with the meaning it has in the
        window and headless runs (walks inside lattices, field of view in 360-degree streams)."""
        return self._p.key(name)

    def walk(self, direction):
        """Walk relative to the view: forward, back, left, right, up or down."""
        return self._p.walk(direction)

    mode = property(lambda self: self._p.mode, doc="view mode: sphere, panorama or lattice")
    active_axis = property(lambda self: self._p.active_axis, doc="the axis PageUp/PageDown step (A, Shift+A turn it); -1 without axes")
    look = property(lambda self: self._p.look, lambda self, v: setattr(self._p, "look", tuple(v)),
                    doc="(yaw, pitch, fov) in degrees inside 360-degree streams")

    def navigate(self, direction):
        """Moves along the navigation graph: "left", "right", "up", "down", "in" or "out"."""
        return self._p.navigate(direction)

    def jump_to_camera(self, camera):
        return self._p.jump_to_camera(camera)

    def set_task(self, task):
        """Switches to task `task`: its index or its name (e.g. "p+s"), as db.frame() takes it."""
        return self._p.set_task(task)

    def next_task(self):
        return self._p.next_task()

    def previous_task(self):
        return self._p.previous_task()

    def step_axis(self, axis, delta=1):
        """Moves to the task `delta` steps along parameter axis `axis` (name or index), keeping the others."""
        return self._p.step_axis(axis, delta)

    def seek(self, frame):
        self._p.seek(frame)

    def step_frame(self, delta=1):
        self._p.step_frame(delta)

    def nearest_camera(self, direction, shell=-1):
        return self._p.nearest_camera(tuple(direction), shell)

    def snap_to_direction(self, direction):
        """Switches to the camera nearest to `direction` (seen from the look-at point) on this shell."""
        return self._p.snap_to_direction(tuple(direction))

    def play(self):
        self._p.play()

    def pause(self):
        self._p.pause()

    def advance(self, seconds):
        """Moves the virtual clock; while playing, frames advance at fps x speed."""
        self._p.advance(seconds)

    speed = property(lambda self: self._p.speed, lambda self, v: setattr(self._p, "speed", v))
    loop = property(lambda self: self._p.loop, lambda self, v: setattr(self._p, "loop", v))

    def shown(self):
        """What is on screen: dict with camera, task, frame, time, status ("ok", "missing",
        "unreadable"), message, cache_hit and image (uint8 (H, W, 3))."""
        return self._p.shown()

    def image(self):
        """The frame on screen as uint8 (H, W, 3)."""
        return self._p.shown()["image"]

    def statistics(self):
        """Counters and switch latencies, as `panoptes play --stats` writes them."""
        return json.loads(self._p.statistics_json())

    def __repr__(self):
        s = self.selection
        return f"<panoptes.Player camera {s['camera']} task {s['task']} frame {s['frame']}>"
