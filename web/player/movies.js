// Movie access for the web player: per stream a fragment index (api/index/C/T.json), the init
// segment and single fragments fetched with byte ranges, demuxed by mp4box.js and decoded by a
// WebCodecs VideoDecoder. Decoded frames go to a bounded LRU cache of VideoFrames.
import { createFile, DataStream, Endianness, MP4BoxBuffer } from "./vendor/mp4box/mp4box.all.mjs";

/// Byte and request counters (the benchmark reports bytes fetched per switch).
export const traffic = { bytes: 0, requests: 0 };

async function fetchBytes(url, range) {
  const headers = range ? { Range: `bytes=${range[0]}-${range[1] - 1}` } : {};
  const res = await fetch(url, { headers, cache: "no-store" });
  if (!res.ok) throw Object.assign(new Error(`${url}: HTTP ${res.status}`), { status: res.status });
  let buf = await res.arrayBuffer();
  traffic.bytes += buf.byteLength;
  traffic.requests++;
  // A static server without range support answers 200 with the whole file: cut the range out.
  if (range && res.status === 200 && buf.byteLength > range[1] - range[0]) buf = buf.slice(range[0], range[1]);
  return buf;
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
    this.url = base + "db/" + db.movie_pattern.replaceAll("{camera}", camera).replaceAll("{task}", task);
    this.indexUrl = `${base}api/index/${camera}/${task}.json`;
    this.status = "new";  // new | ok | missing | unreadable
    this.message = "";
    this.opening = null;
    this.chain = Promise.resolve();
    this.inflight = new Map();  // fragment number → promise
    this.decoder = null;
    this.frameCount = db.frames;
  }

  open() {
    if (!this.opening) this.opening = this._open();
    return this.opening;
  }

  async _open() {
    try {
      const res = await fetch(this.indexUrl, { cache: "no-store" });
      if (res.status === 404) throw Object.assign(new Error("missing"), { kind: "missing" });
      if (!res.ok) throw Object.assign(new Error(`unreadable (HTTP ${res.status})`), { kind: "unreadable" });
      const text = await res.text();
      traffic.bytes += text.length;
      traffic.requests++;
      this.index = JSON.parse(text);
      this.init = await fetchBytes(this.url, [0, this.index.init_size]);
      const { file, info } = await demux(this.init, null);
      const track = info.videoTracks[0];
      this.config = {
        codec: track.codec,
        description: avcDescription(file, track.id),
        codedWidth: track.video.width,
        codedHeight: track.video.height,
        optimizeForLatency: true,
      };
      const support = await VideoDecoder.isConfigSupported(this.config);
      if (!support.supported) throw new Error(`this browser cannot decode ${track.codec}`);
      this.status = "ok";
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

  /// Decodes the fragment holding `frame`, and the following ones up to `batchFrames` frames, into
  /// the cache: one range request and one decoder flush for the lot (with intra-only movies a
  /// fragment is one frame, and a request per frame costs more than the decode). Resolves when done.
  async ensure(frame, cache, batchFrames = 4) {
    await this.open();
    if (this.status !== "ok") return;
    const n = this.fragmentOf(frame);
    if (n < 0) return;  // beyond a truncated movie's end: the player shows its placeholder
    if (!this.inflight.has(n)) {
      const f = this.index.fragments;
      let m = n + 1;
      while (m < f.length && f[m][2] + f[m][3] - f[n][2] <= batchFrames && !this.inflight.has(m) &&
             !cache.has(`${this.camera}/${this.task}/${f[m][2]}`)) m++;
      const p = (this.chain = this.chain.then(() => this._decodeFragments(n, m, cache)));
      for (let k = n; k < m; k++) {
        this.inflight.set(k, p);
      }
      p.finally(() => { for (let k = n; k < m; k++) if (this.inflight.get(k) === p) this.inflight.delete(k); });
    }
    return this.inflight.get(n);
  }

  /// Fragments [n, m): contiguous in the file, so one range; init + those fragments is itself a valid
  /// fragmented MP4 for mp4box.js (offsets are relative to each moof).
  async _decodeFragments(n, m, cache) {
    const f = this.index.fragments;
    const first = f[n][2];
    if (cache.has(`${this.camera}/${this.task}/${first}`) && m === n + 1) return;  // decoded meanwhile
    try {
      const bytes = await fetchBytes(this.url, [f[n][0], f[m - 1][0] + f[m - 1][1]]);
      const { samples } = await demux(this.init, bytes);
      if (!this.decoder || this.decoder.state === "closed") {
        this.decoder = new VideoDecoder({
          output: (vf) => cache.put(`${this.camera}/${this.task}/${vf.timestamp}`, vf),
          error: (e) => { this.decodeError = e; },
        });
        this.decoder.configure(this.config);
      }
      samples.forEach((s, i) => {
        this.decoder.decode(new EncodedVideoChunk({ type: s.is_sync ? "key" : "delta", timestamp: first + i, data: s.data }));
      });
      await this.decoder.flush();
      if (this.decodeError) throw this.decodeError;
    } catch (e) {
      this.status = "unreadable";
      this.message = `${this.url}: fragments ${n}..${m - 1}: ${e.message || e}`;
      if (this.decoder && this.decoder.state !== "closed") this.decoder.close();
    }
  }

  close() {
    if (this.decoder && this.decoder.state !== "closed") this.decoder.close();
    this.decoder = null;
  }
}
