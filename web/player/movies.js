// Movie access for the web player: per stream a fragment index (api/index/C/T.json, or for a static
// site of a packed database an entry of its binary stream index), the init segment and fragments
// fetched with byte ranges (of the stream's movie file, or of the packs that hold it), demuxed by
// mp4box.js or fragmentSamples and decoded by a WebCodecs VideoDecoder. Decoded frames go to a
// bounded LRU cache of VideoFrames.
import { createFile, DataStream, Endianness, MP4BoxBuffer } from "./vendor/mp4box/mp4box.all.mjs";

const MAX_FRAGMENTS_PER_STREAM = 256;
const INIT_GUESS = 2048;
const ownDemux = new URLSearchParams(location.search).get("demux") !== "mp4box";
// Configured VideoDecoders of streams gone cold, by configuration (codec, size, avcC bytes), for the
// next stream that needs one: a switch makes ~4.6 streams cold and ~3 hot, and closing one decoder
// and creating another costs the main thread ms each (docs/web.md, round 5). Every batch starts at
// a keyframe and ends with a flush, so a decoder carries nothing from one stream to the next.
// ?decoderpool=0: closed and created as before.
const DECODER_POOL = 8;
const decoderPool = new URLSearchParams(location.search).get("decoderpool") === "0" ? null : new Map();  // bytes fetched with the fragment index, before init_size is known

/// Byte and request counters (the benchmark reports bytes fetched per switch).
export const traffic = { bytes: 0, requests: 0, batches: 0, fetchMs: 0, demuxMs: 0, decodeMs: 0, frames: 0, outputMs: 0, warmMs: 0, warms: 0, reused: 0 };

/// When each step of opening the player first happened (performance.now() ms since navigation start):
/// the benchmark's breakdown of the time to the first frame.
export const marks = {};
export function mark(name) { if (!(name in marks)) marks[name] = performance.now(); }

async function fetchBytes(url, range) {
  const t0 = performance.now();
  const headers = range ? { Range: `bytes=${range[0]}-${range[1] - 1}` } : {};
  const res = await fetch(url, { headers, cache: "no-store" });
  if (!res.ok) throw Object.assign(new Error(`${url}: HTTP ${res.status}`), { status: res.status });
  let buf = await res.arrayBuffer();
  traffic.fetchMs += performance.now() - t0;
  traffic.bytes += buf.byteLength;
  traffic.requests++;
  // A static server without range support answers 200 with the whole file: cut the range out.
  if (range && res.status === 200 && buf.byteLength > range[1] - range[0]) buf = buf.slice(range[0], range[1]);
  return buf;
}

// Init segments by file and range: every stream of a pack shares the pack's init segment, so a packed
// database fetches it once per pack, not once per stream.
const initSegments = new Map();
function initSegment(url, offset, size) {
  const key = `${url} ${offset} ${size}`;
  if (!initSegments.has(key))
    initSegments.set(key, fetchBytes(url, [offset, offset + size]).catch((e) => { initSegments.delete(key); throw e; }));
  return initSegments.get(key);
}

/// The index of stream `stream` read from a static site's binary stream index (database.json
/// `stream_index`, written by export-web for a packed database; docs/web.md, "A static site from a
/// packed database"): one Range request for its fixed-size entry (and one more for its damaged-frame
/// list when it has one). Returns what api/index/C/T.json holds for a packed database.
export async function readStreamIndexEntry(base, si, stream, streams) {
  const shard = Math.floor(stream / si.streams_per_shard), slot = stream % si.streams_per_shard;
  if (shard >= si.shards.length) throw Object.assign(new Error(`stream ${stream}: no shard ${shard}`), { kind: "missing" });
  const url = base + si.shards[shard], at = si.header_bytes + slot * si.entry_bytes;
  const buf = await fetchBytes(url, [at, at + si.entry_bytes]);
  const v = new DataView(buf);
  const bad = (why) => { throw new Error(`${url}: entry of stream ${stream} (bytes ${at}+${si.entry_bytes}): ${why}`); };
  if (buf.byteLength !== si.entry_bytes) bad(`${buf.byteLength} bytes`);
  if (v.getUint32(0, true) !== stream) bad(`names stream ${v.getUint32(0, true)}`);
  const n = v.getUint32(4, true);
  if (n === 0) throw Object.assign(new Error("missing (no fragment indexed)"), { kind: "missing" });
  if (32 + 16 * n > si.entry_bytes) bad(`${n} fragments do not fit`);
  const fragments = [];
  for (let k = 0, frame = 0; k < n; k++) {
    const p = 32 + 16 * k, where = v.getBigUint64(p, true), frames = v.getUint32(p + 12, true);
    const pack = Number(where >> 48n);
    if (pack >= si.packs.length || frames === 0) bad(`fragment ${k}: pack ${pack}, ${frames} frames`);
    fragments.push([Number(where & 0xffffffffffffn), v.getUint32(p + 8, true), frame, frames, pack]);
    frame += frames;
  }
  const index = { files: si.packs, init: [v.getUint32(8, true), Number(v.getBigUint64(16, true)), v.getUint32(12, true)], fragments };
  index.init_size = index.init[2];
  const damaged = v.getUint32(24, true);
  if (damaged > 0) {
    // The shard's damaged-frame list follows its entries.
    const inShard = Math.min(si.streams_per_shard, streams - shard * si.streams_per_shard);
    const from = si.header_bytes + inShard * si.entry_bytes + 4 * v.getUint32(28, true);
    const list = new DataView(await fetchBytes(url, [from, from + 4 * damaged]));
    index.damaged_frames = Array.from({ length: damaged }, (_, k) => list.getUint32(4 * k, true));
  }
  return index;
}

/// Runs mp4box.js over an init segment followed by one fragment (a valid fragmented MP4 by itself:
/// with default-base-is-moof every offset is relative to its moof) and returns the track info and
/// the fragment's samples.
function demux(init, fragment) {
  return new Promise((resolve, reject) => {
    const file = createFile();
    let info = null;
    const samples = [];
    file.onError = (e) => reject(new Error(`mp4box: ${e}`));
    file.onReady = (i) => {
      info = i;
      if (!i.videoTracks.length) return reject(new Error("no video track"));
      file.setExtractionOptions(i.videoTracks[0].id, null, { nbSamples: 100000 });
      file.start();
    };
    file.onSamples = (_id, _user, s) => samples.push(...s);
    file.appendBuffer(MP4BoxBuffer.fromArrayBuffer(init, 0));
    if (fragment) file.appendBuffer(MP4BoxBuffer.fromArrayBuffer(fragment, init.byteLength));
    file.flush();
    if (!info) return reject(new Error("not a movie (no moov box)"));
    resolve({ file, info, samples });
  });
}

/// The samples of consecutive `moof` + `mdat` fragments (bytes as fetched by one range request), read
/// from each fragment's `tfhd` and `trun` directly: sizes, keyframe flags and data offsets, the sample
/// data as views into `bytes` (no copy). mp4box.js builds every box as an object and copies every
/// sample on the main thread, for each range of every stream fetched ahead; this is what the player
/// needs of it. Throws on anything that is not a fragment the way ISO/IEC 14496-12 lays it out.
export function fragmentSamples(bytes, where = "fragments") {
  const v = new DataView(bytes), out = [];
  const fail = (why, at) => { throw new Error(`${where}: ${why} at byte ${at}`); };
  const box = (at, end) => {
    if (at + 8 > end) fail("truncated box header", at);
    let size = v.getUint32(at), head = 8;
    const type = String.fromCharCode(v.getUint8(at + 4), v.getUint8(at + 5), v.getUint8(at + 6), v.getUint8(at + 7));
    if (size === 1) { size = Number(v.getBigUint64(at + 8)); head = 16; } else if (size === 0) size = end - at;
    if (size < head || at + size > end) fail(`box '${type}' of ${size} bytes past the end (${end})`, at);
    return { type, at, body: at + head, end: at + size };
  };
  let at = 0;
  while (at < bytes.byteLength) {
    const moof = box(at, bytes.byteLength);
    if (moof.type !== "moof") { at = moof.end; continue; }  // styp, sidx, free: skipped; mdat follows its moof
    const mdat = moof.end < bytes.byteLength ? box(moof.end, bytes.byteLength) : null;
    if (!mdat || mdat.type !== "mdat") fail("moof without its mdat", moof.end);
    let nextData = mdat.body;  // a trun without data_offset continues where the previous one ended
    for (let t = moof.body; t < moof.end;) {
      const traf = box(t, moof.end);
      t = traf.end;
      if (traf.type !== "traf") continue;
      let base = moof.at, defSize = 0, defFlags = -1;
      for (let c = traf.body; c < traf.end;) {
        const b = box(c, traf.end);
        c = b.end;
        const flags = v.getUint32(b.body) & 0xffffff;
        let p = b.body + 8;
        if (b.type === "tfhd") {
          if (flags & 0x1) { base = Number(v.getBigUint64(p)); p += 8; }
          if (flags & 0x2) p += 4;
          if (flags & 0x8) p += 4;
          if (flags & 0x10) { defSize = v.getUint32(p); p += 4; }
          if (flags & 0x20) { defFlags = v.getUint32(p); p += 4; }
        } else if (b.type === "trun") {
          const count = v.getUint32(b.body + 4);
          let data = nextData, first = -1;
          if (flags & 0x1) { data = base + v.getInt32(p); p += 4; }
          if (flags & 0x4) { first = v.getUint32(p); p += 4; }
          for (let i = 0; i < count; i++) {
            if (flags & 0x100) p += 4;
            let size = defSize, sflags = i === 0 && first >= 0 ? first : defFlags;
            if (flags & 0x200) { size = v.getUint32(p); p += 4; }
            if (flags & 0x400) { sflags = v.getUint32(p); p += 4; }
            if (flags & 0x800) p += 4;
            if (p > b.end) fail("trun entries past the box", b.at);
            if (data < mdat.body || data + size > mdat.end) fail(`sample ${i} (${size} bytes at ${data}) outside its mdat`, b.at);
            // sample_is_non_sync_sample (bit 16); without flags a fragment starts with a keyframe.
            out.push({ data: new Uint8Array(bytes, data, size), key: sflags >= 0 ? (sflags & 0x10000) === 0 : i === 0 });
            data += size;
          }
          nextData = data;
        }
      }
    }
    at = mdat.end;
  }
  return out;
}

/// The avcC box of the track, as WebCodecs' `description`.
function avcDescription(file, trackId) {
  const trak = file.getTrackById(trackId);
  for (const entry of trak.mdia.minf.stbl.stsd.entries) {
    const box = entry.avcC || entry.hvcC;
    if (box) {
      const stream = new DataStream(undefined, 0, Endianness.BIG_ENDIAN);
      box.write(stream);
      return new Uint8Array(stream.buffer, 8);  // without the box header
    }
  }
  throw new Error("no avcC box");
}

/// A bounded LRU of decoded frames, keyed "camera/task/frame". Evicted frames are closed.
export class FrameCache {
  constructor(capacity) {
    this.capacity = capacity;
    this.map = new Map();
  }
  get(key) {
    const f = this.map.get(key);
    if (f) { this.map.delete(key); this.map.set(key, f); }
    return f;
  }
  has(key) { return this.map.has(key); }
  put(key, frame) {
    if (this.onPut) this.onPut(key);
    const old = this.map.get(key);
    if (old) { old.close(); this.map.delete(key); }
    this.map.set(key, frame);
    while (this.map.size > this.capacity) {
      const [k, f] = this.map.entries().next().value;
      this.map.delete(k);
      f.close();
    }
  }
  clear() { for (const f of this.map.values()) f.close(); this.map.clear(); }
}

/// One (camera, task) movie: opened lazily, decodes one fragment at a time (each starts with a
/// keyframe), one decode at a time (a VideoDecoder per stream, closed when the stream is evicted).
export class Stream {
  constructor(base, db, camera, task) {
    this.camera = camera;
    this.task = task;
    this.base = base;
    // A packed database keeps every stream in ranges of pack files its index names (docs/web.md);
    // `url` then only names the stream in messages.
    this.packed = db.layout === "packed";
    this.url = this.packed ? `${base}db/packs (camera ${camera}, task ${task})`
      : base + "db/" + db.movie_pattern.replaceAll("{camera}", camera).replaceAll("{task}", task);
    this.indexUrl = `${base}api/index/${camera}/${task}.json`;
    // A static site of a packed database has no JSON per stream but a binary stream index.
    this.streamIndex = db.stream_index || null;
    this.streamNumber = camera * db.tasks.length + task;
    this.streamCount = db.cameras.count * db.tasks.length;
    this.status = "new";  // new | ok | missing | unreadable
    this.message = "";
    this.opening = null;
    this.chain = Promise.resolve();
    this.inflight = new Map();  // fragment number → promise of its decode
    this.samples = new Map();  // fragment number → [{data, key}], compressed, fetched ahead
    this.fetching = new Map();  // fragment number → promise of its range fetch
    this.decoder = null;
    this.frameCount = db.frames;
  }

  open() {
    if (!this.opening) this.opening = this._open();
    return this.opening;
  }

  async _open() {
    try {
      // The init segment's size is in the index, but waiting for it costs a round trip: ask for the
      // first INIT_GUESS bytes at the same time (an init segment is ~800 bytes) and only fetch
      // again when it is larger.
      // A packed stream's init segment is shared by its pack (initSegment): no guess.
      const head = this.packed ? null : fetchBytes(this.url, [0, INIT_GUESS]).catch((e) => e);
      if (this.streamIndex) {
        this.index = await readStreamIndexEntry(this.base, this.streamIndex, this.streamNumber, this.streamCount);
      } else {
        const res = await fetch(this.indexUrl, { cache: "no-store" });
        if (res.status === 404) throw Object.assign(new Error("missing"), { kind: "missing" });
        if (!res.ok) throw Object.assign(new Error(`unreadable (HTTP ${res.status})`), { kind: "unreadable" });
        const text = await res.text();
        traffic.bytes += text.length;
        traffic.requests++;
        this.index = JSON.parse(text);
      }
      // The files holding the bytes: the movie, or the packs the index names (fragment field 4).
      this.files = Array.isArray(this.index.files) ? this.index.files.map((u) => this.base + u) : [this.url];
      // Frames that fail their database's frame checks (checksum, identity, position): the server
      // and export-web name them; the player shows a placeholder instead of a frame that lies.
      this.damaged = new Set(Array.isArray(this.index.damaged_frames) ? this.index.damaged_frames : []);
      mark("index");
      if (this.index.init) {
        const [file, offset, size] = this.index.init;
        if (!this.files[file]) throw new Error(`the index names init file ${file} of ${this.files.length}`);
        this.init = (await initSegment(this.files[file], offset, size)).slice(0);
      } else {
        const n = this.index.init_size, guess = await head;
        this.init = !(guess instanceof Error) && guess.byteLength >= n ? guess.slice(0, n) : await fetchBytes(this.url, [0, n]);
      }
      mark("init");
      const { file, info } = await demux(this.init, null);
      const track = info.videoTracks[0];
      this.config = {
        codec: track.codec,
        description: avcDescription(file, track.id),
        codedWidth: track.video.width,
        codedHeight: track.video.height,
        optimizeForLatency: true,
      };
      this.configKey = `${track.codec} ${track.video.width}x${track.video.height} ${Array.from(this.config.description).join(",")}`;
      const support = await VideoDecoder.isConfigSupported(this.config);
      if (!support.supported) throw new Error(`this browser cannot decode ${track.codec}`);
      this.status = "ok";
      mark("configured");
    } catch (e) {
      this.status = e.kind === "missing" ? "missing" : "unreadable";
      this.message = `${this.url}: ${e.message}`;
    }
  }

  fragmentOf(frame) {
    const f = this.index.fragments;
    let lo = 0, hi = f.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (f[mid][2] <= frame) lo = mid; else hi = mid - 1;
    }
    return f.length && frame >= f[lo][2] && frame < f[lo][2] + f[lo][3] ? lo : -1;
  }

  /// Frames from `frame` on whose compressed samples are in memory or on their way (at most `limit`).
  bytesAhead(frame, limit) {
    const f = this.index.fragments;
    let k = this.fragmentOf(frame), covered = 0;
    while (k >= 0 && k < f.length && covered < limit && (this.samples.has(k) || this.fetching.has(k))) {
      covered = f[k][2] + f[k][3] - frame;
      k++;
    }
    return { covered, atEnd: k >= f.length };
  }

  /// Keeps the compressed samples of [frame, frame + frames) in memory, fetched ahead of decoding so
  /// that a decode never waits for the network: when less than half of that window is there, the
  /// missing run is fetched with one range request (a window slides a frame at a time; fetching at
  /// half of it makes one request per frames/2 frames, not one per frame). Resolves when the
  /// fragment holding `frame` is in memory (or the stream turned out unreadable).
  async fetchAhead(frame, frames) {
    await this.open();
    if (this.status !== "ok") return;
    const n = this.fragmentOf(frame);
    if (n < 0) return;
    const { covered, atEnd } = this.bytesAhead(frame, frames);
    if (covered < (this.samples.has(n) ? frames / 2 : 1) && !atEnd) {
      const f = this.index.fragments;
      let a = n;
      while (this.samples.has(a) || this.fetching.has(a)) a++;
      let b = a + 1;
      while (b < f.length && !this.samples.has(b) && !this.fetching.has(b) && f[b][2] < frame + frames) b++;
      const p = this._fetch(a, b);
      for (let k = a; k < b; k++) this.fetching.set(k, p);
      p.finally(() => { for (let k = a; k < b; k++) if (this.fetching.get(k) === p) this.fetching.delete(k); });
    }
    if (!this.samples.has(n)) await this.fetching.get(n);
  }

  /// Fragments [a, b), with one range request per maximal run of them that lies back to back in one
  /// file (a movie file's fragments are one run; a pack's hold other streams' fragments between
  /// them). Init + a run is itself a valid fragmented MP4 for mp4box.js (offsets are relative to
  /// each moof).
  async _fetch(a, b) {
    const f = this.index.fragments, file = (k) => f[k][4] ?? 0;
    const runs = [];
    for (let k = a; k < b; k++) {
      const last = runs[runs.length - 1];
      if (last && file(k) === file(k - 1) && f[k][0] === f[k - 1][0] + f[k - 1][1]) last[1] = k + 1;
      else runs.push([k, k + 1]);
    }
    try {
      await Promise.all(runs.map(([ra, rb]) => this._fetchRun(ra, rb)));
      // Bounded memory: the oldest fetched fragments go first.
      for (const k of this.samples.keys()) {
        if (this.samples.size <= MAX_FRAGMENTS_PER_STREAM) break;
        this.samples.delete(k);
      }
    } catch (e) {
      this.status = "unreadable";
      this.message = `${this.url}: fragments ${a}..${b - 1}: ${e.message || e}`;
    }
  }

  /// Fragments [a, b), back to back in one file: one range request.
  async _fetchRun(a, b) {
    const f = this.index.fragments, url = this.files[f[a][4] ?? 0];
    if (!url) throw new Error(`fragment ${a} names file ${f[a][4]} of ${this.files.length}`);
    const bytes = await fetchBytes(url, [f[a][0], f[b - 1][0] + f[b - 1][1]]);
    mark("fragments fetched");
    const td = performance.now();
    const samples = ownDemux ? fragmentSamples(bytes, `${url} fragments ${a}..${b - 1}`)
      : (await demux(this.init, bytes)).samples.map((x) => ({ data: x.data, key: x.is_sync }));
    traffic.demuxMs += performance.now() - td;
    if (samples.length !== f[b - 1][2] + f[b - 1][3] - f[a][2])
      throw new Error(`${samples.length} samples, the index says ${f[b - 1][2] + f[b - 1][3] - f[a][2]}`);
    let i = 0;
    for (let k = a; k < b; k++) {
      this.samples.set(k, samples.slice(i, i + f[k][3]));
      i += f[k][3];
    }
  }

  /// Decodes the fragment holding `frame`, and the following ones up to `batchFrames` frames, into
  /// the cache with one decoder flush (every fragment starts with a keyframe); their samples are
  /// fetched first if they are not in memory yet (`fetchFrames` ahead). Resolves when done.
  /// With `stride` > 1 and a stream of keyframes only (one frame per fragment, i.e. gop 1) only every
  /// stride-th fragment of the batch is decoded: a neighbour then has a frame at most stride - 1
  /// behind any playhead for a stride-th of the decoding (see pump() in player.js).
  async ensure(frame, cache, batchFrames = 4, fetchFrames = 16, stride = 1) {
    await this.open();
    if (this.status !== "ok") return;
    const step = stride > 1 && this.intraOnly() ? stride : 1;
    const n = this.fragmentOf(frame - (frame % step));  // on the grid 0, step, 2 step, …
    if (n < 0) return;  // beyond a truncated movie's end: the player shows its placeholder
    if (!this.inflight.has(n)) {
      const f = this.index.fragments;
      const list = [n];
      for (let m = n + step; m < f.length && f[m][2] < this.frameCount && f[m][2] + f[m][3] - f[n][2] <= batchFrames && !this.inflight.has(m) &&
           !cache.has(`${this.camera}/${this.task}/${f[m][2]}`); m += step) list.push(m);
      const p = (this.chain = this.chain.then(() => this._decodeFragments(list, cache, fetchFrames)));
      for (const k of list) this.inflight.set(k, p);
      p.finally(() => { for (const k of list) if (this.inflight.get(k) === p) this.inflight.delete(k); });
    }
    return this.inflight.get(n);
  }

  /// Every fragment holds one frame, so every frame is a keyframe (each fragment starts with one):
  /// any subset of the frames can be decoded.
  intraOnly() {
    if (this._intraOnly === undefined) this._intraOnly = this.index.fragments.every((x) => x[3] === 1);
    return this._intraOnly;
  }

  async _decodeFragments(list, cache, fetchFrames) {
    const f = this.index.fragments, n = list[0];
    if (list.every((k) => cache.has(`${this.camera}/${this.task}/${f[k][2]}`))) return;  // decoded meanwhile
    // Configured before the samples are awaited: the codec's set-up overlaps the range request.
    this.warm(cache);
    for (const k of list) {
      if (this.status !== "ok") break;
      if (!this.samples.has(k)) await this.fetchAhead(f[k][2], fetchFrames);
    }
    if (this.status !== "ok") return;
    try {
      const t0 = (this.decodeCalled = performance.now());
      let count = 0;
      for (const k of list) {
        const samples = this.samples.get(k);
        if (!samples) break;  // evicted meanwhile: the pump asks again
        samples.forEach((s, i) => {
          this.decoder.decode(new EncodedVideoChunk({ type: s.key ? "key" : "delta", timestamp: f[k][2] + i, data: s.data }));
        });
        count += samples.length;
      }
      await this.decoder.flush();
      mark("decoded");
      traffic.batches++; traffic.frames += count; traffic.decodeMs += performance.now() - t0;
      if (this.decodeError) throw this.decodeError;
    } catch (e) {
      if (e.name === "AbortError") return;  // abortDecodes(): not decoded, the pump asks again if needed
      this.status = "unreadable";
      this.message = `${this.url}: fragments ${n}..${list[list.length - 1]}: ${e.message || e}`;
      if (this.decoder && this.decoder.state !== "closed") this.decoder.close();
    }
  }

  /// Creates and configures the stream's VideoDecoder if it has none, without decoding anything: a
  /// neighbour decoded only when a switch comes to it (player.js, `nbdecode=switch`) then pays one
  /// decode, not the decoder's set-up as well.
  warm(cache) {
    if (this.status !== "ok" || (this.decoder && this.decoder.state !== "closed")) return;
    const t0 = performance.now();
    const pooled = decoderPool ? decoderPool.get(this.configKey) : null;
    let d = pooled && pooled.pop();
    if (d && d.state === "configured") {
      traffic.reused++;
    } else {
      d = new VideoDecoder({
        // The decoder may serve several streams in turn (decoderPool): frames go to its owner of the moment.
        output: (vf) => {
          if (!d.owner) return vf.close();
          const t = performance.now();
          cache.put(`${d.owner.camera}/${d.owner.task}/${vf.timestamp}`, vf);
          traffic.outputMs += performance.now() - t;
        },
        error: (e) => { if (d.owner) d.owner.decodeError = e; },
      });
      d.configure(this.config);
      traffic.warms++;
    }
    d.owner = this;
    this.decoder = d;
    traffic.warmMs += performance.now() - t0;
  }

  /// Drops the decodes queued on the stream's decoder and configures it again: a switch away from a
  /// keyframe-only stream makes its frames ahead useless (a neighbour is decoded on switch only), and
  /// on two cores they would take the CPU from the new stream's first decode.
  abortDecodes() {
    if (!this.decoder || this.decoder.state !== "configured" || this.inflight.size === 0) return;
    this.decoder.reset();
    this.decoder.configure(this.config);
  }

  /// Whether the compressed samples of `frame` are in memory (a decode of it need not wait for the network).
  hasSamples(frame) {
    const n = this.status === "ok" ? this.fragmentOf(frame) : -1;
    return n >= 0 && this.samples.has(n);
  }

  /// Gives the stream's decoder up: idle and configured, it goes to decoderPool for the next stream of
  /// the same configuration; otherwise (decodes in flight, an error, the pool full) it is closed.
  close() {
    const d = this.decoder;
    this.decoder = null;
    if (!d || d.state === "closed") return;
    d.owner = null;
    if (decoderPool && d.state === "configured" && this.inflight.size === 0 && d.decodeQueueSize === 0) {
      const list = decoderPool.get(this.configKey) ?? [];
      decoderPool.set(this.configKey, list);
      if (list.length < DECODER_POOL) return void list.push(d);
    }
    d.close();
  }
}
