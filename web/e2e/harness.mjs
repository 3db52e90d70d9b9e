// Shared browser-test harness: serves the Trunk build (dist/) under a sub-path from a tiny
// static server, launches Debian's Chromium headless through playwright-core with WebGPU on
// (SwiftShader) or off (WebGL2 fallback), and reads the page's test contract
// (<body data-ready data-backend data-quality>, window.cloudsketch.state()).
import http from 'node:http';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { PNG } from 'pngjs';

const here = path.dirname(fileURLToPath(import.meta.url));
/**
 * The builds a test runs in. The WebGL2 fallback draws through wgpu's GL backend (the WGSL
 * translated to GLSL), the WebGPU build through the browser's WebGPU; tools, input handling,
 * undo, animation and the document are the same Rust in both. Tests of drawing, of the page's
 * speed, and of loading run in both builds, and so do the tests of the modal tools, the
 * outlines' planes and the Tiers group, I, auto-key and the shot camera on the timeline, cached
 * playback and frame times while dragging. The other tests of tools and input, the developing
 * preset scrubbed, and a preset opened from each link (`EDITING_BUILDS`) run in the WebGPU build
 * alone, which most visitors get: the WebGL2 build draws the same kinds of scene in the tests
 * that run in both (ellipsoids: the parity test; five presets: the preset buttons test; the
 * developing preset: the flipbook test). Every test in both builds adds about 9 minutes to the
 * suite, too close to CI's 90.
 */
export const BOTH_BUILDS = ['webgpu', 'webgl2'];
/** `CLOUDSKETCH_ALL_BUILDS=1` runs every test in both builds (about 9 minutes more here). */
const ALL_BUILDS = process.env.CLOUDSKETCH_ALL_BUILDS === '1';
/** See [`BOTH_BUILDS`]. */
export const EDITING_BUILDS = ALL_BUILDS ? BOTH_BUILDS : ['webgpu'];
/**
 * The longest tests of drawing (1–1.5 minutes each: refinement at 1280×800 and 1920×1080, an
 * upper tier at whole resolution) run in the WebGPU build alone unless
 * `CLOUDSKETCH_ALL_BUILDS=1`. The WebGL2 build's capture and drawing are covered by tests in
 * both: the Export group's PNGs, an export over frames, cached playback, the default cloud's
 * orbit, the presets, the media filter, the shafts.
 */
export const COSTLY_BUILDS = EDITING_BUILDS;

export const DIST = process.env.CLOUDSKETCH_DIST ?? path.resolve(here, '../../dist');
/** Screenshots of every run land here, for a person to look at. */
export const SCREENSHOTS = path.resolve(here, '../test-results/screenshots');
/** Served under a sub-path to prove the build's asset URLs are relative. */
export const SUB_PATH = '/some/sub/path/';

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm', '.css': 'text/css', '.png': 'image/png', '.json': 'application/json' };

/** The precompressed copies the server prefers, in order. */
const ENCODINGS = [{ name: 'br', suffix: '.br' }, { name: 'gzip', suffix: '.gz' }];

/** Starts a static server for DIST under SUB_PATH; resolves to { url, close }. */
export function serve() {
  if (!fs.existsSync(path.join(DIST, 'index.html'))) {
    throw new Error(`no web build at ${DIST}: run 'trunk build --release' first (scripts/test.sh does)`);
  }
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://x');
    if (!url.pathname.startsWith(SUB_PATH)) { res.writeHead(404); res.end('outside the app'); return; }
    let rel = decodeURIComponent(url.pathname.slice(SUB_PATH.length)) || 'index.html';
    const file = path.resolve(DIST, rel);
    if (!file.startsWith(DIST) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) { res.writeHead(404); res.end(); return; }
    // As a host with precompressed files does (web/precompress.mjs): the Brotli or gzip copy
    // where the browser accepts it, else the file itself.
    // Encodings the browser accepts (`br;q=0` refuses Brotli).
    const accepted = (req.headers['accept-encoding'] ?? '').split(',')
      .map((e) => e.trim().split(';').map((p) => p.trim()))
      .filter(([, q]) => !/^q=0(\.0*)?$/.test(q ?? ''))
      .map(([name]) => name);
    const encoding = ENCODINGS.find((e) => accepted.includes(e.name) && fs.existsSync(file + e.suffix));
    res.writeHead(200, {
      'content-type': TYPES[path.extname(file)] ?? 'application/octet-stream',
      vary: 'accept-encoding',
      ...(encoding ? { 'content-encoding': encoding.name } : {}),
    });
    fs.createReadStream(encoding ? file + encoding.suffix : file).pipe(res);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => {
    const { port } = server.address();
    resolve({ url: `http://127.0.0.1:${port}${SUB_PATH}`, close: () => new Promise((r) => server.close(r)) });
  }));
}

const QUIET = ['--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--disable-quic', '--disable-default-apps', '--disable-extensions', '--no-default-browser-check', '--mute-audio'];
const SWIFTSHADER = ['--use-angle=swiftshader', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'];

/**
 * Launches Chromium; `webgpu: false` leaves WebGPU off so the app must fall back to WebGL2;
 * `webgl: false` also turns WebGL off (no way to draw at all).
 */
export async function launch({ webgpu, webgl = true }) {
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'cloudsketch-chromium-'));
  const args = ['--remote-debugging-pipe', `--user-data-dir=${userDataDir}`, '--headless=new', '--no-sandbox',
    ...QUIET, ...SWIFTSHADER, ...(webgpu ? ['--enable-unsafe-webgpu'] : []),
    ...(webgl ? [] : ['--disable-3d-apis', '--disable-webgl']), 'about:blank'];
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', ignoreDefaultArgs: true, args, timeout: 60_000,
  });
  const close = async () => { await browser.close(); fs.rmSync(userDataDir, { recursive: true, force: true }); };
  return { browser, close };
}

/** Opens the app in a new page and records console errors and page errors. */
export async function openApp(browser, base, query = '', viewport = { width: 900, height: 560 }, options = {}, init = null) {
  const page = await browser.newPage({ viewport, ...options });
  // A script run in the page before the app's own (to stand in for a browser's features).
  if (init) await page.addInitScript(init);
  const errors = [];
  const log = [];
  page.on('console', (m) => { log.push(`[${m.type()}] ${m.text()}`); if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  const started = Date.now();
  await page.goto(base + query);
  return { page, errors, log, started };
}

/**
 * Watches the page's file pickers from now on; `next()` resolves to the next one opened.
 * Call it well before the action that opens one: Playwright turns on its interception of
 * pickers without waiting for the browser, and a picker opened before that lands is cancelled
 * unseen (`Promise.all([page.waitForEvent('filechooser'), press])` missed 1 in 10 beside a
 * cargo build, though the page had opened it with the key's user activation).
 */
export function watchFileChoosers(page) {
  const opened = [];
  const waiting = [];
  page.on('filechooser', (chooser) => { const w = waiting.shift(); if (w) w(chooser); else opened.push(chooser); });
  return {
    next(timeout = 30_000) {
      if (opened.length) return Promise.resolve(opened.shift());
      return new Promise((resolve, reject) => {
        const timer = setTimeout(() => { waiting.splice(waiting.indexOf(done), 1); reject(new Error(`no file picker opened in ${timeout} ms`)); }, timeout);
        const done = (c) => { clearTimeout(timer); resolve(c); };
        waiting.push(done);
      });
    },
  };
}

/**
 * The builds of the app (index.html: `webgpu`, `webgl`) whose wasm the page fetched, in order:
 * the file's size raw (`bytes`), its precompressed copies' sizes (`brotliBytes`, `gzipBytes`:
 * web/precompress.mjs, null where missing), and what the browser says it received
 * (`transferBytes`, the encoded body) and decoded (`decodedBytes`).
 */
export async function fetchedBuilds(page) {
  const entries = await page.evaluate(() => performance.getEntriesByType('resource')
    .map((e) => ({ name: e.name, encoded: e.encodedBodySize, decoded: e.decodedBodySize })));
  const size = (file) => (fs.existsSync(file) ? fs.statSync(file).size : null);
  return entries
    .map((e) => ({ ...e, pathname: new URL(e.name).pathname }))
    .filter((e) => e.pathname.endsWith('_bg.wasm'))
    .map((e) => {
      const rel = decodeURIComponent(e.pathname.slice(e.pathname.indexOf(SUB_PATH) + SUB_PATH.length));
      const file = path.join(DIST, rel);
      return {
        build: rel.split('/')[0], bytes: size(file), brotliBytes: size(`${file}.br`), gzipBytes: size(`${file}.gz`),
        transferBytes: e.encoded, decodedBytes: e.decoded,
      };
    });
}

/** Waits for the body attribute `name` to satisfy `pred` (string → bool); returns its value. */
export async function waitForBody(page, name, pred = (v) => v != null, timeout = 120_000) {
  const handle = await page.waitForFunction(
    ([n, src]) => { const v = document.body.getAttribute(n); return new Function('v', `return (${src})(v)`)(v) ? v : null; },
    [name, pred.toString()], { timeout, polling: 100 });
  return handle.jsonValue();
}

/** The page's state (scene document and view). */
export const state = (page) => page.evaluate(() => window.cloudsketch.state());

/** Waits until the page shows a full-quality image of the current view. */
export async function waitForFullQuality(page, timeout = 120_000) {
  const t0 = Date.now();
  // Give the app a frame to notice a change before trusting "full".
  await page.waitForTimeout(50);
  const quality = await waitForBody(page, 'data-quality', (v) => typeof v === 'string' && v.startsWith('full'), timeout);
  const seconds = (Date.now() - t0) / 1000;
  // Two animation frames more, so a screenshot shows the frame that drew the last chunk.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  return { quality, seconds };
}

/** Screenshot saved under SCREENSHOTS/name.png, decoded to { width, height, data (RGBA) }. */
export async function screenshot(page, name) {
  fs.mkdirSync(SCREENSHOTS, { recursive: true });
  const file = path.join(SCREENSHOTS, `${name}.png`);
  const buffer = await page.screenshot({ path: file });
  const png = PNG.sync.read(buffer);
  return { width: png.width, height: png.height, data: png.data, file };
}

/**
 * Pixels of `img` inside `rect` ({x, y, w, h}) whose colour differs from `rgb` by more than
 * `tol`, leaving out the pixels inside `skip` (a rect, e.g. the sun handle's box), if given.
 */
export function countDiffering(img, rect, rgb, tol = 12, skip = null) {
  let n = 0;
  const skipped = (x, y) => skip && x >= skip.x && x < skip.x + skip.w && y >= skip.y && y < skip.y + skip.h;
  for (let y = rect.y; y < rect.y + rect.h; y++) {
    for (let x = rect.x; x < rect.x + rect.w; x++) {
      if (skipped(x, y)) continue;
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - rgb[0]) + Math.abs(img.data[i + 1] - rgb[1]) + Math.abs(img.data[i + 2] - rgb[2]);
      if (d > tol) n++;
    }
  }
  return n;
}

/** Pixels inside `rect` that differ by more than `tol` between two same-size images. */
export function countChanged(a, b, rect, tol = 24) {
  let n = 0;
  for (let y = rect.y; y < rect.y + rect.h; y++) {
    for (let x = rect.x; x < rect.x + rect.w; x++) {
      const i = 4 * (y * a.width + x);
      const d = Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2]);
      if (d > tol) n++;
    }
  }
  return n;
}

/** Appends a timing record to test-results/timings.json (figures for the README and notes). */
export function recordTiming(entry) {
  const file = path.resolve(here, '../test-results/timings.json');
  fs.mkdirSync(path.dirname(file), { recursive: true });
  const all = fs.existsSync(file) ? JSON.parse(fs.readFileSync(file, 'utf8')) : [];
  all.push({ ...entry, at: new Date().toISOString() });
  fs.writeFileSync(file, JSON.stringify(all, null, 2));
}

/**
 * Scrolls the side panel (with the wheel, over the panel) until widget `name` (a mark in the
 * page state's `view.widgets`) is in view; returns its rectangle [x, y, w, h].
 */
export async function reveal(page, name) {
  // The side panel runs the window's whole height (the timeline sits under the view only).
  const [vw] = (await state(page)).view.viewport;
  const vh = page.viewportSize().height;
  let last = null;
  for (let i = 0; i < 60; i++) {
    const r = (await state(page)).view.widgets[name];
    if (!r) throw new Error(`${name} is not drawn`);
    const inView = r[1] >= 10 && r[1] + r[3] <= vh - 10;
    // egui animates a wheel scroll over several frames: only a box that stayed put since the
    // last look (150 ms earlier) is where a click will land, and only from there is the next
    // wheel aimed (a wheel sent while the last one still played out overshot on a busy
    // machine, back and forth, and the widget never settled in view).
    const settled = last && r.every((v, k) => v === last[k]);
    if (inView && settled) return r;
    if (!inView && (settled || !last)) {
      // As far as brings the widget to the middle of the view.
      const dy = Math.max(-600, Math.min(600, r[1] + r[3] / 2 - vh / 2));
      await page.mouse.move(vw + 100, vh / 2);
      await page.mouse.wheel(0, Math.abs(dy) < 40 ? Math.sign(dy) * 40 : dy);
    }
    last = r;
    await page.waitForTimeout(150);
  }
  throw new Error(`${name} never came into view`);
}

/**
 * Opens the side panel's group `title` (a new user's panel opens File, Sketch and Render only)
 * by clicking its header, as a person does, unless it is open already.
 */
export async function openGroup(page, title) {
  if ((await state(page)).view.groups_open.includes(title)) return;
  const r = await reveal(page, `group:${title}`);
  await page.mouse.click(r[0] + 12, r[1] + r[3] / 2);
  await until(page, (s) => s.view.groups_open.includes(title), `the ${title} group open`);
}

/** The sun handle's box in the page state's view (or null when it is not drawn). */
export function sunHandleBox(view) {
  const o = view.sun_handle;
  if (!o) return null;
  const r = o.radius + 6;
  return { x: Math.floor(o.center[0] - r), y: Math.floor(o.center[1] - r), w: Math.ceil(2 * r), h: Math.ceil(2 * r) };
}

/** Polls the page state until `pred(state)` holds; throws with the view state on timeout. */
export async function until(page, pred, what, timeout = 60_000) {
  const t0 = Date.now();
  for (;;) {
    const s = await state(page);
    if (pred(s)) return s;
    if (Date.now() - t0 > timeout) throw new Error(`timed out waiting for ${what}: ${JSON.stringify(s.view)}`);
    await page.waitForTimeout(100);
  }
}

/**
 * Runs `body(page)` in a fresh Chromium (WebGPU on or off) with the app at `base + query` open
 * and ready; on failure prints the page's last log lines; fails if the page logged an error.
 */
export async function withApp({ base, webgpu, query = '', viewport, init = null }, body) {
  const { browser, close } = await launch({ webgpu });
  try {
    const { page, errors, log } = await openApp(browser, base, query, viewport, {}, init);
    try {
      await waitForBody(page, 'data-ready', (v) => v === 'true');
      await body(page);
      if (errors.length) throw new Error(`errors logged:\n${errors.join('\n')}`);
    } catch (e) {
      console.error(log.slice(-40).join('\n'));
      throw e;
    }
  } finally {
    await close();
  }
}

/** Horizontal centroid and count of the pixels that differ from the sky `bg` (RGB bytes)
 * between the notice and hint lines at the top and the status line at the bottom of a view
 * `vw`×`vh` points. */
export function cloudColumns(img, [vw, vh], bg) {
  let n = 0, sx = 0;
  for (let y = 60; y < vh - 30; y++) {
    for (let x = 0; x < vw; x++) {
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - bg[0]) + Math.abs(img.data[i + 1] - bg[1]) + Math.abs(img.data[i + 2] - bg[2]);
      if (d > 24) { n++; sx += x; }
    }
  }
  return { n, x: n ? sx / n : NaN };
}

/** The page x of `frame` on the timeline's scrub bar (the bar's ends are 8 points in). */
export function frameX(s, frame) {
  const [left, , width] = s.view.widgets['timeline:scrub'];
  const { start, end } = s.scene.clock ?? { start: 0, end: 120 };
  return left + 8 + ((frame - start) / (Math.max(end, start + 1) - start)) * (width - 16);
}

/** Drags along the scrub bar's ruler (its numbers: a press there scrubs even over a key)
 * from where the playhead is to `frame`, with pointer moves at input rate (several a frame,
 * none awaited per frame). */
export async function scrubTo(page, frame) {
  const s = await state(page);
  const [, top] = s.view.widgets['timeline:scrub'];
  const y = top + 5;
  const x0 = frameX(s, s.view.timeline.frame);
  const x1 = frameX(s, frame);
  await page.mouse.move(x0, y);
  await page.mouse.down();
  for (let i = 1; i <= 12; i++) await page.mouse.move(x0 + ((x1 - x0) * i) / 12, y);
  await page.mouse.up();
  // Off the bar: its tooltip is no part of the image compared.
  await page.mouse.move(x1, top - 200);
  return until(page, (s) => Math.round(s.view.timeline.frame) === frame, `frame ${frame}`);
}

/** The topmost row and the width (points) of the pixels that differ from the sky `bg` (RGB
 * bytes) between the notice and hint lines at the top and the status line at the bottom of a
 * view `vw`×`vh` points, left of the orientation gizmo's column at its top right. */
export function cloudExtent(img, [vw, vh], bg) {
  let top = vh, x0 = vw, x1 = -1;
  for (let y = 60; y < vh - 30; y++) {
    for (let x = 0; x < vw - 140; x++) {
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - bg[0]) + Math.abs(img.data[i + 1] - bg[1]) + Math.abs(img.data[i + 2] - bg[2]);
      if (d > 24) { top = Math.min(top, y); x0 = Math.min(x0, x); x1 = Math.max(x1, x); }
    }
  }
  return { top, width: Math.max(0, x1 - x0 + 1) };
}
