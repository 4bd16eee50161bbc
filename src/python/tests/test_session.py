"""panoptes.Session in one process: zero-copy fields, schedule, database written, errors."""
import numpy as np
import pytest

import panoptes
from conftest import HEAT_TOML

NX, NY, NZ = 24, 20, 16


def blob(shape, centre):
    z, y, x = np.indices(shape)
    return np.exp(-((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2) / 20.0)


def test_session_writes_a_database_from_numpy_fields(tmp_path):
    out = tmp_path / "heat_db"
    s = panoptes.Session(HEAT_TOML.format(dir=out))
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    T = np.zeros((NZ, NY, NX), dtype=np.float32)
    s.set_field("T", T)
    taken = []
    for step in range(5):
        # Written in place after set_field: the session must see the new values (no copy was made).
        T[...] = blob(T.shape, (4 + 4 * step, 10, 8))
        taken.append(s.process(step, 0.5 * step))
    s.finalize()
    assert taken == [True, False, True, False, True]
    db = panoptes.open(out)
    assert db.status == "complete" and db.frame_count == 3 and db.camera_count == 6
    np.testing.assert_allclose(db.times, [0.0, 1.0, 2.0])
    f0, f2 = db.frame(0, 0, 0), db.frame(0, 0, 2)
    assert f0.max() > 60  # the blob is visible
    assert np.abs(f0.astype(int) - f2.astype(int)).mean() > 1  # and it moved: the in-place writes were seen


def test_float64_with_ghosts_and_strided_views(tmp_path):
    # Whole grid in one process, with one ghost layer in z stored (ignored at the domain edge).
    a = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "a"))
    a.set_grid((NX, NY, NZ))
    a.set_block((0, 0, 0), (NX, NY, NZ), (0, 0, 0), (0, 0, 1))
    T = np.zeros((NZ + 1, NY, NX), dtype=np.float64)
    T[:NZ] = blob((NZ, NY, NX), (12, 10, 8))
    a.set_field("T", T)
    a.snapshot(0.0)
    a.finalize()
    # The same field as a strided float32 view (every other element of a wider array).
    b = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "b"))
    b.set_grid((NX, NY, NZ))
    b.set_block((0, 0, 0), (NX, NY, NZ))
    wide = np.zeros((NZ, NY, 2 * NX), dtype=np.float32)
    wide[:, :, ::2] = blob((NZ, NY, NX), (12, 10, 8))
    b.set_field("T", wide[:, :, ::2])
    b.snapshot(0.0)
    b.finalize()
    fa, fb = panoptes.open(tmp_path / "a").frame(1, 0, 0), panoptes.open(tmp_path / "b").frame(1, 0, 0)
    assert np.abs(fa.astype(int) - fb.astype(int)).max() <= 2


def test_session_errors(tmp_path):
    with pytest.raises(panoptes.Error, match="set_block first"):
        panoptes.Session(HEAT_TOML.format(dir=tmp_path / "x")).set_field("T", np.zeros((1, 1, 1)))
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "x"))
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    with pytest.raises(panoptes.Error, match=r"shape \(16, 20\); expected \(16, 20, 24\)"):
        s.set_field("T", np.zeros((NZ, NY)))
    with pytest.raises(panoptes.Error, match="dtype int64; expected float32 or float64"):
        s.set_field("T", np.zeros((NZ, NY, NX), dtype=np.int64))
    # The failed binding is named at the next collective call (on every rank, issue 42); after that
    # the field is simply missing.
    with pytest.raises(panoptes.Error, match='field "T" is not bound: its binding failed \\(set_field: field "T" has dtype int64'):
        s.snapshot(0.0)
    with pytest.raises(panoptes.Error, match='field "T" \\(read by a task\\) was not given'):
        s.snapshot(0.0)
    with pytest.raises(panoptes.Error):
        panoptes.Session("[image]\nwidth = -3\n")
    with pytest.raises(panoptes.FileError):
        panoptes.Session(str(tmp_path / "missing.toml"))


def test_rank_and_counts_answer_before_set_grid(tmp_path):
    # A simulation needs its rank to compute its block: nothing may require set_grid/set_block first.
    sweep = '[[task]]\nname = "iso"\ntype = "isosurface"\nfield = "T"\nisovalues = [0.2, 0.5]\n'
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "c") + sweep)
    assert (s.rank, s.ranks, s.snapshots) == (0, 1, 0)
    early = (s.camera_count, s.task_count)
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    s.set_field("T", np.zeros((NZ, NY, NX), dtype=np.float32))
    s.snapshot(0.0)  # the session exists from here: its own counts must be the ones announced
    assert early == (s.camera_count, s.task_count) == (6, 3)  # the sweep is 2 tasks
    s.finalize()


def test_due_and_forced_snapshot(tmp_path):
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "d"))  # every_steps = 2
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    T = blob((NZ, NY, NX), (12, 10, 8)).astype(np.float32)
    s.set_field("T", T)
    assert [s.due(step, 0.1 * step) for step in range(5)] == [True, False, True, False, True]
    assert s.snapshots == 0  # due() renders nothing
    s.snapshot(0.15)  # forced, between scheduled steps
    assert s.process(2, 0.2) and not s.process(3, 0.3)
    s.finalize()
    np.testing.assert_allclose(panoptes.open(tmp_path / "d").times, [0.15, 0.2])


def test_set_halo_is_checked_against_the_stored_ghosts(tmp_path):
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "h"))
    s.set_grid((NX, NY, NZ))
    with pytest.raises(panoptes.Error, match="set_halo: call set_block first"):
        s.set_halo((0, 0, 0), (0, 0, 0))
    s.set_block((0, 0, 0), (NX, NY, NZ), (0, 0, 2), (0, 0, 2))
    with pytest.raises(panoptes.Error, match=r"set_halo: valid ghost layers 3 below / 1 above on axis z; expected -1"):
        s.set_halo((0, 0, 3), (0, 0, 1))
    s.set_halo((0, 0, 1), (-1, -1, 1), edges_valid=False)


def test_times_must_be_finite_and_increasing(tmp_path):
    """Issue 42, point 5: NaN / inf times used to return normally and leave null in the manifest (no
    reader opened the database); times going back were stored. Now panoptes.Error, nothing written."""
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "d"))  # every_steps = 2
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    s.set_field("T", blob((NZ, NY, NX), (12, 10, 8)).astype(np.float32))
    for bad in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(panoptes.Error, match="expected a finite simulation time"):
            s.process(0, bad)
    assert s.process(0, 1.0)
    with pytest.raises(panoptes.Error, match="time 0.5 is not after the previous snapshot's time 1"):
        s.process(2, 0.5)
    with pytest.raises(panoptes.Error, match="time 1 is not after"):
        s.snapshot(1.0)
    assert s.process(4, 2.0)
    s.finalize()
    np.testing.assert_allclose(panoptes.open(tmp_path / "d").times, [1.0, 2.0])


def test_strides_that_overflow_are_refused(tmp_path):
    """Issue 42, point 6: a view whose strides reach past 64-bit offsets (numpy's as_strided allows any)
    was bound and read at wrapped addresses; now set_field refuses it."""
    s = panoptes.Session(HEAT_TOML.format(dir=tmp_path / "d"))
    s.set_grid((NX, NY, NZ))
    s.set_block((0, 0, 0), (NX, NY, NZ))
    T = blob((NZ, NY, NX), (12, 10, 8)).astype(np.float32)
    huge = np.lib.stride_tricks.as_strided(T, shape=T.shape, strides=(2**62, T.strides[1], T.strides[2]))
    with pytest.raises(panoptes.Error, match="reach further than 64-bit offsets can address"):
        s.set_field("T", huge)
    s.set_field("T", T)
    assert s.process(0, 0.0)
    s.finalize()
