"""panoptes.open: manifest, cameras as NumPy arrays, frames decoded as the player shows them."""
import json
import subprocess

import numpy as np
import pytest

import panoptes
from conftest import panoptes_binary


def test_summary(synth_db):
    db = panoptes.open(synth_db)
    assert db.title == "synthetic database"
    assert db.status == "complete"
    assert db.frame_count == 5
    assert db.image_size == (64, 48)
    np.testing.assert_allclose(db.times, [0.0, 0.1, 0.2, 0.3, 0.4])
    assert db.camera_count == 4 and db.task_count == 3
    assert [t["name"] for t in db.tasks] == [t["name"] for t in db.manifest["tasks"]]
    assert list(db.axes) == ["isovalue"] and db.axes["isovalue"].shape == (3,)
    assert "synthetic" in repr(db)
    assert db.projection == "perspective" and "360" not in repr(db)


def test_360_degree_databases_say_so(tmp_path):
    """Issue 14: a lattice of equirectangular cameras; its frames are panoramas, not views."""
    out = tmp_path / "lattice"
    subprocess.run([panoptes_binary(), "synth-db", str(out), "--lattice", "2x2x1", "--projection", "equirectangular",
                    "--tasks", "1", "--frames", "1", "--size", "64x32"], check=True, stdout=subprocess.DEVNULL)
    db = panoptes.open(out)
    assert db.projection == "equirectangular"
    assert "360-degree equirectangular panoramas" in repr(db)
    assert db.frame(0, 0, 0).shape == (32, 64, 3)


def test_cameras_match_panoptes_info(synth_db):
    db = panoptes.open(synth_db)
    cams = db.cameras
    assert len(cams) == 4
    assert cams.position.shape == (4, 3) and cams.position.dtype == np.float64
    assert cams.neighbours.shape == (4, 6) and cams.neighbours.dtype == np.int32
    assert cams.fov.shape == cams.latitude.shape == cams.longitude.shape == cams.shell.shape == (4,)
    # The synthetic rig's ring graph: right of camera c is c + 1.
    assert [cams.neighbour(c, "right") for c in range(4)] == [1, 2, 3, 0]
    # Latitude/longitude labels are those of the direction from the look-at point.
    d = cams.direction()
    np.testing.assert_allclose(np.degrees(np.arcsin(d[:, 2])), cams.latitude, atol=1e-9)
    # Same numbers as the command line reports.
    info = json.loads(subprocess.run([panoptes_binary(), "info", "--json", "--no-check", str(synth_db)],
                                     check=True, capture_output=True, text=True).stdout)
    assert info["cameras"] == 4
    with pytest.raises(ValueError):
        cams.position[0, 0] = 1.0  # read-only views of the table


def test_frames_are_the_stamped_frames(synth_db):
    db = panoptes.open(synth_db)
    img = db.frame(2, 1, 3)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8 and img.flags.c_contiguous
    # The stamp: 10 x 8 blocks of 4 px in the top-left corner, black or white.
    blocks = img[:32:4, :40:4].astype(int).mean(axis=2)
    assert ((blocks < 60) | (blocks > 195)).mean() > 0.9
    # Decoding is exact: the same frame twice, and a stream iterates frame after frame.
    assert np.array_equal(img, db.frame(2, 1, 3))
    frames = list(db.stream(2, 1))
    assert len(frames) == 5 and np.array_equal(frames[3], img)
    assert not np.array_equal(frames[0], frames[1])
    assert np.array_equal(db.frame(2, db.tasks[1]["name"], 3), img)


def test_frames_equal_headless_player_pngs(synth_db, tmp_path):
    """db.frame gives exactly the pixels `panoptes play --headless --frames-out` writes."""
    script = tmp_path / "path.txt"
    script.write_text("t=0 key=Right\n")
    subprocess.run([panoptes_binary(), "play", str(synth_db), "--headless", "--paused", "--frame", "2",
                    "--script", str(script), "--frames-out", str(tmp_path / "frames"), "--duration", "0.05"],
                   check=True, capture_output=True)
    pngs = sorted((tmp_path / "frames").glob("*.png"))
    assert pngs, "headless player wrote no frames"
    import zlib
    import struct

    def read_png_rgb(path):  # minimal PNG reader for 8-bit RGB(A), no filters beyond the standard ones
        data = path.read_bytes()
        pos, idat, w = 8, b"", 0
        while pos < len(data):
            n, kind = struct.unpack(">I4s", data[pos:pos + 8])
            chunk = data[pos + 8:pos + 8 + n]
            if kind == b"IHDR":
                w, h, depth, ctype = struct.unpack(">IIBB", chunk[:10])
                ch = {2: 3, 6: 4}[ctype]
            elif kind == b"IDAT":
                idat += chunk
            pos += 12 + n
        raw = zlib.decompress(idat)
        out = np.zeros((h, w * ch), np.uint8)
        stride, prev = w * ch, np.zeros(w * ch, np.int32)
        for y in range(h):
            f, line = raw[y * (stride + 1)], np.frombuffer(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)], np.uint8).astype(np.int32)
            cur = np.zeros(stride, np.int32)
            for x in range(stride):
                a = cur[x - ch] if x >= ch else 0
                b = prev[x]
                c = prev[x - ch] if x >= ch else 0
                if f == 0: v = line[x]
                elif f == 1: v = line[x] + a
                elif f == 2: v = line[x] + b
                elif f == 3: v = line[x] + (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    v = line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)
                cur[x] = v & 255
            out[y] = cur
            prev = cur
        return out.reshape(h, w, ch)[:, :, :3]

    db = panoptes.open(synth_db)
    shown = read_png_rgb(pngs[-1])
    # After "Right" the player shows camera 1, task 0, frame 2 (paused).
    assert np.array_equal(shown, db.frame(1, 0, 2))


def test_errors_are_exceptions_with_the_cli_messages(synth_db, tmp_path):
    with pytest.raises(panoptes.FileError) as e:
        panoptes.open(tmp_path / "nothing")
    cli = subprocess.run([panoptes_binary(), "info", str(tmp_path / "nothing")], capture_output=True, text=True)
    assert cli.returncode != 0
    assert cli.stderr.strip() == "panoptes: error: " + str(e.value)
    db = panoptes.open(synth_db)
    with pytest.raises(panoptes.Error, match="frame 5 out of range; the database has 5 complete frames"):
        db.frame(0, 0, 5)
    with pytest.raises(panoptes.Error, match="camera 9 out of range"):
        db.frame(9, 0, 0)
    with pytest.raises(panoptes.Error, match="no task named 'nope'"):
        db.frame(0, "nope", 0)
    assert issubclass(panoptes.FileError, panoptes.Error) and issubclass(panoptes.Error, RuntimeError)


def test_packed_databases_read_like_files(tmp_path, synth_db):
    """Issue 46: `panoptes pack` output reads frame for frame as its source, and a stream cut out of the
    packs by its byte ranges alone is a movie of its own."""
    packed = tmp_path / "packed"
    subprocess.run([panoptes_binary(), "synth-db", str(tmp_path / "src"), "--cameras", "4", "--tasks", "3",
                    "--frames", "5", "--size", "64x48", "--gop", "1"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([panoptes_binary(), "pack", str(tmp_path / "src"), str(packed)], check=True,
                   stdout=subprocess.DEVNULL)
    a, b = panoptes.open(tmp_path / "src"), panoptes.open(packed)
    assert not a.packed and b.packed
    for c, t, f in [(0, 0, 0), (3, 2, 4), (1, 1, 2)]:
        np.testing.assert_array_equal(a.frame(c, t, f), b.frame(c, t, f))
    pieces = b.packed_stream(2, 1)
    assert pieces[0]["frames"] == 0 and sum(p["frames"] for p in pieces) == 5
    cut = tmp_path / "cut.mp4"
    with open(cut, "wb") as out:
        for p in pieces:
            with open(p["file"], "rb") as f:
                f.seek(p["offset"])
                out.write(f.read(p["size"]))
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-show_entries", "stream=nb_read_frames",
                            "-of", "csv=p=0", str(cut)], capture_output=True, text=True, check=True)
    assert probe.stdout.strip() == "5"
