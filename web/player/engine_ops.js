// The browser's counterpart of player::Engine::apply and player::Controls (src/player/engine.cpp,
// controls.cpp): the clock and every operation keys.json names that is not the front end's own (issue
// 43). player.js's OPS keeps only what a browser page does itself (magnify the canvas, full screen,
// screenshot, help, HUD, C). An operation returns true when it changed something and false when it was
// refused, and the key handler then shows keys.json's `refusal` text — the window's words.
// test/engine_ops_test.mjs checks that the names here are exactly keys.json's engine and dispatch
// operations, so an engine key added to src/player/keys.cpp without its browser half fails there.

/// The operations named in keys.json that the front end does itself: an action marked front_end_only
/// whose operation is the action's own name (in 360° modes + / - / 0 become fov_* of the dispatch).
export const isFrontEndOperation = (binding, op) => binding.front_end_only === true && op === binding.action;

/// The player's clock over the state S (S.anchorFrame, S.anchorTime, S.playing, S.loop, S.dir,
/// S.speed, S.fps, S.db.frames), as player::Engine's: the position runs forward or backward (J) from
/// an anchor and wraps or stops at either end. `now` is a clock in ms (performance.now in the page).
export function makeClock(S, now = () => performance.now()) {
  function currentFrame(t = now()) {
    const n = S.db.frames;
    if (!S.playing) return S.anchorFrame;
    let f = S.anchorFrame + S.dir * Math.floor(((t - S.anchorTime) / 1000) * S.fps * S.speed + 1e-9);
    if (f >= n || f < 0) {
      if (S.loop) f = ((f % n) + n) % n;
      else { f = f < 0 ? 0 : n - 1; S.playing = false; S.anchorFrame = f; }
    }
    return f;
  }
  function setFrame(f) {
    S.anchorFrame = Math.max(0, Math.min(S.db.frames - 1, f));
    S.anchorTime = now();
  }
  function setPlaying(p) {
    const f = currentFrame();
    S.playing = p;
    setFrame(f);
  }
  return { currentFrame, setFrame, setPlaying };
}

/// The task at the same positions as `task` on every axis but `axisName`, moved by delta there; -1 if
/// none (Engine::step_axis).
export function stepTaskOnAxis(db, task, axisName, delta) {
  const pos = (t) => Object.fromEntries(db.tasks[t].axes.map((a) => [a.axis, a.index]));
  const from = pos(task);
  if (!(axisName in from)) return -1;
  for (let t = 0; t < db.tasks.length; t++) {
    const p = pos(t);
    if (p[axisName] !== from[axisName] + delta) continue;
    if (Object.keys(from).every((k) => k === axisName || p[k] === from[k]) && Object.keys(p).length === Object.keys(from).length)
      return t;
  }
  return -1;
}

/// The operations by keys.json name. p: { S, clock (makeClock), select(camera, task, command) → bool,
/// move(slot) → bool (the graph and its move trail), walk(w) → bool, setLook(look), notify(text) }.
/// Playback constants come from keys.json's `playback` and `look` (S.keys), with the C++ defaults.
export function engineOps(p) {
  const { S, clock, select, move, walk, setLook, notify } = p;
  const pb = (k, dflt) => (S.keys && S.keys.playback && S.keys.playback[k]) || dflt;
  const lk = (k, dflt) => (S.keys && S.keys.look && S.keys.look[k]) || dflt;
  const changed = (before, after) => before !== after;
  /// Speed factor, as Engine::set_speed (x1/4..x8), keeping the playhead; false at a limit.
  function setSpeed(v) {
    const f = clock.currentFrame(), before = S.speed;
    S.speed = Math.min(pb("speed_max", 8), Math.max(pb("speed_min", 0.25), v));
    clock.setFrame(f);
    if (S.speed === before) return false;
    notify(`speed x${S.speed.toFixed(2)} (${(S.speed * S.fps).toFixed(1)} frames/s)`);
    return true;
  }
  /// A stepped frame wraps when looping, else stops at the ends (Engine::step_frame).
  function stepFrame(d) {
    const n = S.db.frames, f = clock.currentFrame() + d;
    S.playing = false;
    clock.setFrame(S.loop ? ((f % n) + n) % n : Math.max(0, Math.min(n - 1, f)));
    return true;
  }
  const stepAxis = (d) => S.db.axes[S.axis] !== undefined &&
    select(S.camera, stepTaskOnAxis(S.db, S.task, S.db.axes[S.axis].name, d), d > 0 ? "axis_up" : "axis_down");
  /// A / Shift+A: the next / previous axis becomes the active one, wrapping (Engine::apply).
  const turnAxis = (d) => {
    const n = S.db.axes.length;
    if (!n) return false;
    S.axis = (S.axis + d + n) % n;
    return true;
  };
  const T = () => S.db.tasks.length;
  const ops = {
    play_pause: () => { clock.setPlaying(!S.playing); return true; },
    frame_forward: () => stepFrame(1),
    frame_back: () => stepFrame(-1),
    first_frame: () => { clock.setFrame(0); return true; },
    last_frame: () => { clock.setFrame(S.db.frames - 1); return true; },
    toggle_loop: () => { const f = clock.currentFrame(); S.loop = !S.loop; clock.setFrame(f); notify(S.loop ? "loop on" : "loop off"); return true; },
    faster: () => setSpeed(S.speed * pb("faster_factor", 2)),
    slower: () => setSpeed(S.speed / pb("faster_factor", 2)),
    reverse: () => { const f = clock.currentFrame(); S.dir = -S.dir; clock.setFrame(f); return true; },
    speed_up: () => setSpeed(S.speed * pb("fine_factor", 1.1)),
    speed_down: () => setSpeed(S.speed / pb("fine_factor", 1.1)),
    speed_reset: () => setSpeed(1),
    camera_left: () => move("left"),
    camera_right: () => move("right"),
    camera_up: () => move("up"),
    camera_down: () => move("down"),
    shell_in: () => move("in"),
    shell_out: () => move("out"),
    walk_forward: () => walk("forward"),
    walk_back: () => walk("back"),
    walk_left: () => walk("left"),
    walk_right: () => walk("right"),
    walk_up: () => walk("up"),
    walk_down: () => walk("down"),
    next_task: () => select(S.camera, (S.task + 1) % T(), "next_task"),
    previous_task: () => select(S.camera, (S.task + T() - 1) % T(), "previous_task"),
    axis_up: () => stepAxis(1),
    axis_down: () => stepAxis(-1),
    next_axis: () => turnAxis(1),
    previous_axis: () => turnAxis(-1),
    // Controls' field of view of 360° streams (+ / - / 0 there); false at a limit, as Controls::apply.
    fov_narrow: () => changed(S.look.fov, (setLook({ ...S.look, fov: S.look.fov / lk("key_fov_factor", 1.25) }), S.look.fov)),
    fov_widen: () => changed(S.look.fov, (setLook({ ...S.look, fov: S.look.fov * lk("key_fov_factor", 1.25) }), S.look.fov)),
    fov_reset: () => changed(S.look.fov, (setLook({ ...S.look, fov: lk("fov_deg", 90) }), S.look.fov)),
  };
  for (let k = 1; k <= 9; k++) ops[`task_${k}`] = () => select(S.camera, k - 1, `task_${k}`);
  return { ops, setSpeed };
}
