// The browser's Record as a WebM (VP9): each frame the app hands over is encoded by the
// browser's own WebCodecs encoder and muxed by webm-muxer (vendored, MIT: web/vendor/), which
// is fetched only when a recording starts. A wasm-bindgen snippet of the app
// (src/ui/platform_web.rs); where WebCodecs is missing the app records PNGs instead.

let muxer = null;
/** webm-muxer's module, from the folder Trunk copies next to index.html. */
function loadMuxer() {
  // (A failed fetch is not kept: the next recording tries again.)
  muxer ??= import(new URL('vendor/webm-muxer.js', document.baseURI).href).catch((e) => { muxer = null; throw e; });
  return muxer;
}

/** Whether this browser has the WebCodecs video encoder. */
export function videoSupported() {
  return typeof VideoEncoder === 'function' && typeof VideoFrame === 'function';
}

/** A key frame every this many frames (seeking lands on one). */
const KEY_EVERY = 24;
/** Frames queued (copied, waiting for the encoder or in it) before the app waits: each holds
 *  its pixels, 8 MB at 1080p. */
const MAX_QUEUED = 3;
/** How long a recording's encoder may take to start before the app records PNGs instead. */
const START_WITHIN_MS = 20_000;

/** One recording: frames `width`×`height` (even) at `fps` frames a second. */
export class WebmRecorder {
  constructor(width, height, fps) {
    this.width = width;
    this.height = height;
    this.fps = fps;
    this.problem = null;
    this.frames = 0;
    // Frames handed over and not yet in the encoder.
    this.pending = 0;
    this.started = false;
    // An error here (no muxer, no VP9 at this size) is kept: the app, which waits for the
    // start (busy), then records PNGs instead.
    // A start that hangs (a module fetch that never answers) counts as failed.
    const late = new Promise((_, fail) => setTimeout(() => fail(new Error('the video encoder did not start within 20 s')), START_WITHIN_MS));
    this.ready = Promise.race([this.start(), late])
      .catch((e) => { this.problem ??= String(e?.message ?? e); })
      .finally(() => { this.started = true; });
  }

  /** Whether the app should wait before the next frame: still starting, or enough queued. */
  busy() {
    return !this.started || this.pending + (this.encoder?.encodeQueueSize ?? 0) >= MAX_QUEUED;
  }

  async start() {
    const { Muxer, ArrayBufferTarget } = await loadMuxer();
    const config = {
      codec: 'vp09.00.10.08',
      width: this.width,
      height: this.height,
      // Half a bit a pixel a frame: clean gradients in a sky (at 1080p24, 25 Mbit/s).
      bitrate: Math.max(200_000, Math.round(0.5 * this.width * this.height * this.fps)),
      framerate: this.fps,
    };
    const support = await VideoEncoder.isConfigSupported(config);
    if (!support.supported) throw new Error(`this browser cannot encode VP9 at ${this.width}×${this.height}`);
    this.target = new ArrayBufferTarget();
    this.muxer = new Muxer({
      target: this.target,
      video: { codec: 'V_VP9', width: this.width, height: this.height, frameRate: this.fps },
      firstTimestampBehavior: 'offset',
    });
    this.encoder = new VideoEncoder({
      output: (chunk, meta) => this.muxer.addVideoChunk(chunk, meta),
      error: (e) => { this.problem ??= String(e?.message ?? e); },
    });
    this.encoder.configure(config);
    // Configuring is reported through the error callback, later: an empty flush waits for it
    // (and rejects if it failed), so a refusing encoder is known before the first frame.
    await this.encoder.flush();
    if (this.problem) {
      // (Failed, or given up on by the time it started: nothing will use it.)
      try { this.encoder.close(); } catch { /* closed by its error already */ }
      throw new Error(this.problem);
    }
  }

  /** Queues frame `index` (0 first): straight-alpha RGBA bytes, copied here (they are a view
   *  of the app's memory, which may move). */
  addFrame(rgba, index) {
    const data = rgba.slice();
    this.frames = Math.max(this.frames, index + 1);
    this.pending += 1;
    this.ready = this.ready.then(() => {
      this.pending -= 1;
      if (this.problem) return;
      const frame = new VideoFrame(data, {
        format: 'RGBA',
        codedWidth: this.width,
        codedHeight: this.height,
        timestamp: Math.round((index * 1e6) / this.fps),
        duration: Math.round(1e6 / this.fps),
      });
      this.encoder.encode(frame, { keyFrame: index % KEY_EVERY === 0 });
      frame.close();
    }).catch((e) => { this.problem ??= String(e?.message ?? e); });
  }

  /** The first error so far, if any. */
  failed() {
    return this.problem;
  }

  /** Encodes what is queued and closes the file: a promise of the WebM as a Blob. */
  async finish() {
    await this.ready;
    if (this.problem) throw new Error(this.problem);
    await this.encoder.flush();
    if (this.problem) throw new Error(this.problem);
    this.encoder.close();
    this.muxer.finalize();
    const bytes = new Uint8Array(this.target.buffer);
    // webm-muxer states the duration as the last frame's start (11 s for 12 frames at 1 a
    // second; it is no longer maintained): the Segment's Duration (ID 0x4489, an 8-byte float
    // in milliseconds, near the file's start) is set to the frames' whole length.
    for (let i = 0; i + 11 <= Math.min(bytes.length, 1024); i++) {
      if (bytes[i] === 0x44 && bytes[i + 1] === 0x89 && bytes[i + 2] === 0x88) {
        new DataView(bytes.buffer).setFloat64(i + 3, (this.frames * 1000) / this.fps, false);
        break;
      }
    }
    return new Blob([bytes], { type: 'video/webm' });
  }

  /** Drops the recording: the encoder stops (frames still queued are not encoded). */
  cancel() {
    this.problem ??= 'cancelled';
    this.ready.then(() => { try { this.encoder?.close(); } catch { /* closed already */ } });
  }
}
