// The web player's prefetch (player.js's "prefetch" room, issue 43): every display frame (and at once
// after a key) the pump looks at the streams a switch can reach and keeps them decoded a few frames
// past the playhead. It reads the player's state and streams through `env`, which player.js hands over
// once: { S, options, cache, streams, stream(c, t), currentFrame(), neighbourSelections(c, t) }.

/// Returns { pump, releaseDecoders } over the player's state.
export function makePrefetch(env) {
  const { S, options, cache, streams, stream, currentFrame, neighbourSelections } = env;
  // Every display frame (and at once after a key) the pump looks at the streams a switch can reach:
  // the current one first, then every neighbour. A stream whose decoded frames do not reach `ahead`
  // frames past the playhead gets its next batch started — unless it already has one in flight (its
  // decodes are chained on one VideoDecoder anyway). No job ever waits for another's work, which was
  // round 1's tail: workers blocked on batches already in flight while other neighbours went unopened.
  // With spare connections the streams two steps away are opened (fragment index + init segment) so a
  // switch's new neighbours start decoding without two round trips first.
  let inflight = 0;  // batches, fetches and opens started by the pump, not yet done
  /// Keeps the stream's compressed samples `fetchAhead` frames past f in memory (wrapping when looping).
  function fetchAhead(st, f) {
    const n = S.db.frames, W = options.fetchAhead;
    const key = `fetch ${st.camera}/${st.task}`;
    if (busy.has(key)) return;
    const run = (from, frames) => {
      const { covered, atEnd } = st.bytesAhead(from, frames);
      if (covered >= frames / 2 || atEnd) return false;
      busy.add(key);
      inflight++;
      st.fetchAhead(from, frames).finally(() => { busy.delete(key); inflight--; });
      return true;
    };
    if (!run(f, Math.min(W, n - f)) && S.loop && f + W > n) run(0, f + W - n);
  }
  const busy = new Set();  // "c/t" with a pump batch in flight
  /// The first frame in [f, f + ahead) of the stream that is not decoded; -1 if none. With stride s > 1
  /// only the frames on the grid 0, s, 2s, … are asked for (frame k is then covered by k - k % s).
  function firstMissing(c, t, f, ahead, stride = 1) {
    const n = S.db.frames;
    for (let k = 0; k < ahead; k++) {
      let g = S.playing ? (((f + k * S.dir) % n) + n) % n : Math.min(f + k, n - 1);  // ahead in the playback direction (J)
      g -= g % stride;
      if (!cache.has(`${c}/${t}/${g}`)) return g;
    }
    return -1;
  }
  function startBatch(c, t, g, batch, stride = 1) {
    const key = `${c}/${t}`;
    busy.add(key);
    inflight++;
    stream(c, t).ensure(g, cache, batch, options.fetchAhead, stride).finally(() => { busy.delete(key); inflight--; pump(); });
  }
  /// Closes the VideoDecoder of every stream that is neither current nor a neighbour any more and has
  /// no decode in flight (a decoder holds threads and buffers; 96 streams may be open). A stream that
  /// becomes hot again configures a new one.
  function releaseDecoders(max = Infinity) {
    const hot = new Set([`${S.camera}/${S.task}`, ...neighbourSelections(S.camera, S.task).map(([c, t]) => `${c}/${t}`)]);
    let closed = 0;
    for (const [key, st] of streams) {
      if (closed >= max) break;
      if (!hot.has(key) && st.decoder && st.decoder.state !== "closed" && st.inflight.size === 0) { st.close(); closed++; }
    }
    return closed;
  }
  /// The streams a task switch makes neighbours: the graph neighbours of the current camera in the
  /// task-neighbour tasks (after Tab they all become neighbours at once, which was round 2's tail).
  function taskNeighbourGraph(camera, task) {
    const out = [];
    for (const [c0, t0] of neighbourSelections(camera, task)) {
      if (c0 !== camera) continue;
      for (const [c, t] of neighbourSelections(c0, t0)) if (c !== camera && t === t0) out.push([c, t]);
    }
    return out;
  }
  function pump() {
    if (!S.db) return;
    const f = currentFrame();
    const hot = [[S.camera, S.task, S.playing ? options.ahead : 1, options.batch, 1]];
    // Until the first frame is on screen the current stream has the connections and the decoder to
    // itself; so it has, with switchFirst, until a switch's first frame is on screen.
    const nb = options.prefetch && S.firstFrameMs !== null && !(options.switchFirst && S.pending) ? neighbourSelections(S.camera, S.task) : [];
    // While playing, a neighbour of keyframes only (gop 1) is decoded at every stride-th frame: a switch
    // then shows, on the next display frame, the new stream's frame at most stride - 1 frames behind
    // the playhead (at 30 fps, 33 ms of simulated time for stride 2) and the frames after it in step.
    // Decoding every neighbour at every frame was more than a loaded machine could do.
    const nbStride = S.playing ? options.nbStride : 1;
    for (const [c, t] of nb) hot.push([c, t, S.playing ? options.nbAhead : 1, options.nbBatch, nbStride]);
    // Decode on switch: while playing, a neighbour of keyframes only is not decoded at all. Its samples
    // are kept in memory and its decoder configured; a switch to it decodes the frame at the playhead
    // (one intra decode), shown at the next display frame, and the frames after it as the current
    // stream. The neighbours' continuous decoding (~210 frames/s of 528x512 on the demo) was what a
    // 2-core machine could not keep up with; between switches the CPU now idles.
    const onSwitch = options.nbDecode === "switch" && S.playing;
    for (const [c, t, ahead, batch, stride] of hot) {
      if (inflight >= options.connections && c !== S.camera) return;  // the current stream may exceed it
      const key = `${c}/${t}`;
      if (busy.has(key)) continue;
      const st = streams.get(key);
      if (st && (st.status === "missing" || st.status === "unreadable")) continue;
      if (onSwitch && !(c === S.camera && t === S.task)) {
        if (!st || st.status === "new") {  // opened first: whether it is keyframes only is in its index
          busy.add(key);
          inflight++;
          stream(c, t).open().finally(() => { busy.delete(key); inflight--; });
          continue;
        }
        if (st.intraOnly()) {
          st.warm(cache);
          fetchAhead(st, f);
          continue;
        }
      }
      const g = firstMissing(c, t, f, ahead, stride > 1 && st && st.status === "ok" && st.intraOnly() ? stride : 1);
      // The very first frame is decoded alone: a batch of 8 before the first picture is 8 decodes of waiting.
      const first = S.firstFrameMs === null ? 1 : c === S.camera && t === S.task && g === f ? options.switchBatch : batch;
      if (g >= 0 && !(st && st.status === "ok" && st.fragmentOf(g) < 0)) startBatch(c, t, g, first, stride);
      else if (g < 0 && st && st.status === "ok" && S.playing) fetchAhead(st, f);
    }
    if (!nb.length) return;
    // Warm, at a lower priority (a connection kept for the hot streams): the streams a Tab would make
    // neighbours get opened and their compressed samples fetched ahead, so that after the Tab only
    // their decode is left (one batch each, from memory) — no index, init segment or range round trip.
    if (options.warmTasks)
      for (const [c, t] of taskNeighbourGraph(S.camera, S.task)) {
        if (inflight >= options.connections - 1) return;
        const key = `${c}/${t}`;
        if (busy.has(key)) continue;
        const st = stream(c, t);
        if (st.status === "new") {
          busy.add(key);
          inflight++;
          st.open().finally(() => { busy.delete(key); inflight--; });
        } else if (st.status === "ok" && S.playing) fetchAhead(st, f);
      }
    for (const [c0, t0] of nb)
      for (const [c, t] of neighbourSelections(c0, t0)) {
        if (inflight >= options.connections - 1) return;  // keep a connection for the hot streams
        const key = `${c}/${t}`;
        if (busy.has(key) || (streams.has(key) && streams.get(key).status !== "new")) continue;
        busy.add(key);
        inflight++;
        stream(c, t).open().finally(() => { busy.delete(key); inflight--; });
      }
  }
  return { pump, releaseDecoders };
}
