"""panoptes.Player: the engine, headless, on a virtual clock."""
import numpy as np
import pytest

import panoptes


def test_navigate_step_seek_and_read(synth_db):
    db = panoptes.open(synth_db)
    p = panoptes.Player(db)
    assert p.selection == {"camera": 0, "task": 0, "frame": 0}
    assert np.array_equal(p.image(), db.frame(0, 0, 0))
    assert p.navigate("right") and p.camera == 1
    assert p.navigate("left") and p.camera == 0
    assert p.step_axis("isovalue", +1) and p.task == 1
    assert not p.step_axis("isovalue", -2)  # off the end of the axis: refused, nothing changes
    assert p.task == 1
    p.seek(3)
    shown = p.shown()
    assert (shown["camera"], shown["task"], shown["frame"], shown["status"]) == (0, 1, 3, "ok")
    assert shown["time"] == pytest.approx(0.3)
    assert np.array_equal(shown["image"], db.frame(0, 1, 3))
    assert p.next_task() and p.task == 2
    assert p.jump_to_camera(3) and p.camera == 3


def test_virtual_clock_plays_at_the_database_rate(synth_db):
    p = panoptes.Player(synth_db, prefetch=False)
    assert not p.playing
    p.play()
    p.advance(2.5 / p.fps)  # two and a half frame periods
    assert p.frame_index == 2
    p.pause()
    p.advance(1.0)
    assert p.frame_index == 2
    stats = p.statistics()
    assert "frames_shown" in stats or "counters" in stats


def test_bad_commands(synth_db):
    p = panoptes.Player(synth_db)
    with pytest.raises(panoptes.Error, match='direction "sideways"; expected left, right, up, down, in or out'):
        p.navigate("sideways")
    with pytest.raises(panoptes.Error, match='no parameter axis "speed"'):
        p.step_axis("speed")


def test_tasks_by_name(synth_db):
    db = panoptes.open(synth_db)
    names = [t["name"] for t in db.tasks]
    p = panoptes.Player(db, task=names[2])
    assert p.task == 2
    assert p.set_task(names[1]) and p.task == 1
    assert np.array_equal(p.image(), db.frame(0, names[1], 0))
    assert p.set_task(0) and p.task == 0
    with pytest.raises(panoptes.Error, match=r'set_task: the database has no task "phi_s"; its tasks are "'):
        p.set_task("phi_s")
    with pytest.raises(panoptes.Error, match=r"expected a task index \(int\) or name \(str\)"):
        p.set_task(1.5)
    with pytest.raises(panoptes.Error, match=r'Player: the database has no task "nope"'):
        panoptes.Player(db, task="nope")


def test_keys_give_the_headless_trace_on_a_lattice(tmp_path):
    """Issue 30: Player.key() follows the same dispatch as `play --headless` (trace per script line)."""
    import json
    import subprocess
    from conftest import panoptes_binary
    db = tmp_path / "lattice"
    subprocess.run([panoptes_binary(), "synth-db", str(db), "--lattice", "3x3x3", "--tasks", "3", "--frames", "4",
                    "--size", "64x32"], check=True, stdout=subprocess.DEVNULL)
    keys = ["Up", "Right", "Up", "Period", "2", "Tab", "End", "Left", "Z", "Comma"]
    script = tmp_path / "s.txt"
    script.write_text("".join(f"t={i / 10} key={k}\n" for i, k in enumerate(keys)))
    trace = tmp_path / "trace.jsonl"
    subprocess.run([panoptes_binary(), "play", str(db), "--headless", "--paused", "--camera", "13", "--script",
                    str(script), "--trace", str(trace)], check=True, stdout=subprocess.DEVNULL)
    expected = [(r["step"], r["camera"], r["task"], r["frame"]) for r in map(json.loads, trace.read_text().splitlines())]
    p = panoptes.Player(db, camera=13)
    got = []
    for i, k in enumerate(keys):
        p.key(k)
        got.append((i, p.camera, p.task, p.frame_index))
    assert got == expected
    assert got[0][1] == 22  # Up from the centre camera goes up the graph, as in the window
    with pytest.raises(Exception, match="unknown key"):
        p.key("Nope")
