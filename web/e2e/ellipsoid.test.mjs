// Ellipsoids in the browser: the Ellipsoid tool adds one where a click lands; the Move tool
// drags it (the cloud follows, the camera stays); Ctrl+Z undoes the drag as one step; the
// Scale tool grows it; Delete removes it. Screenshots: test-results/screenshots/ellipsoid-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { PNG } from 'pngjs';
import { serve, state, screenshot, countChanged, until, withApp, waitForFullQuality, recordTiming, SCREENSHOTS, cloudColumns, EDITING_BUILDS, BOTH_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const toBytes = (rgb) => rgb.map((v) => Math.round(v * 255));

/** Focuses the view, takes the Ellipsoid tool (E) and clicks once at each of `at` (fractions of
 * the view); resolves to the state once every ellipsoid is in the scene. */
async function addEllipsoids(page, at) {
  const [vw, vh] = (await state(page)).view.viewport;
  await page.mouse.click(vw * 0.05, vh * 0.95);
  await page.keyboard.press('e');
  await until(page, (s) => s.view.tool === 'ellipsoid', 'ellipsoid tool');
  let s;
  for (const [i, [fx, fy]] of at.entries()) {
    await page.mouse.click(vw * fx, vh * fy);
    s = await until(page, (s) => s.scene.ellipsoids.length === i + 1, `ellipsoid ${i + 1}`);
  }
  return s;
}

const cloud = cloudColumns;

for (const backend of EDITING_BUILDS) {
  test(`add an ellipsoid with its tool, move it, undo, scale it, delete (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const view = s.view.viewport;
      const [vw, vh] = view;
      const bg = toBytes(s.scene.light.background);
      s = await addEllipsoids(page, [[0.4, 0.5]]);
      assert.equal(s.view.selected_ellipsoid, 0);
      assert.match(s.view.notice.text, /Added Ellipsoid 1/);
      await page.keyboard.press('h'); // the indicator off: look at the cloud alone
      await waitForFullQuality(page);
      const placedImg = await screenshot(page, `ellipsoid-1-added-${backend}`);
      const placed = cloud(placedImg, view, bg);
      assert.ok(placed.n > 0.01 * vw * vh, `a cloud where the click was: ${placed.n} px`);
      assert.ok(Math.abs(placed.x - vw * 0.4) < vw * 0.05, `centred on the click: ${placed.x}`);

      // Move: the cloud follows the drag, the camera stays.
      const camera = JSON.stringify(s.scene.camera);
      const undo = s.view.undo;
      const x0 = s.scene.ellipsoids[0].center[0];
      await page.keyboard.press('Shift+G');
      await until(page, (s) => s.view.tool === 'move', 'move tool');
      await page.mouse.move(vw * 0.4, vh * 0.5);
      await page.mouse.down();
      for (let i = 1; i <= 15; i++) await page.mouse.move(vw * 0.4 + i * 12, vh * 0.5);
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[0].center[0] > x0 + 0.5, 'the ellipsoid moved right');
      assert.equal(JSON.stringify(s.scene.camera), camera, 'the camera stayed');
      assert.equal(s.view.undo, undo + 1, 'one drag, one undo step');
      await waitForFullQuality(page);
      const movedImg = await screenshot(page, `ellipsoid-2-moved-${backend}`);
      const moved = cloud(movedImg, view, bg);
      assert.ok(moved.x > placed.x + 100, `the cloud followed: ${placed.x} → ${moved.x}`);

      await page.keyboard.press('Control+z');
      s = await until(page, (s) => Math.abs(s.scene.ellipsoids[0].center[0] - x0) < 1e-4, 'the move undone');
      // Undo restores the image, not only the numbers (the moved one differs widely).
      await waitForFullQuality(page);
      const undone = await screenshot(page, `ellipsoid-2b-undone-${backend}`);
      const body = { x: 0, y: 60, w: vw, h: vh - 90 };
      const back = countChanged(placedImg, undone, body);
      const away = countChanged(placedImg, movedImg, body);
      assert.ok(back < 0.02 * away, `after undo the image is as placed: ${back} px differ (${away} when moved)`);
      // Scale: a drag right grows it, and the cloud with it.
      const r0 = s.scene.ellipsoids[0].radii[0];
      await page.keyboard.press('Shift+S');
      await until(page, (s) => s.view.tool === 'scale', 'scale tool');
      await waitForFullQuality(page);
      const before = cloud(await screenshot(page, `ellipsoid-3-before-scale-${backend}`), view, bg);
      await page.mouse.move(vw * 0.4, vh * 0.5);
      await page.mouse.down();
      for (let i = 1; i <= 10; i++) await page.mouse.move(vw * 0.4 + i * 10, vh * 0.5);
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[0].radii[0] > 1.3 * r0, 'the ellipsoid grew');
      await waitForFullQuality(page);
      const grown = cloud(await screenshot(page, `ellipsoid-4-scaled-${backend}`), view, bg);
      assert.ok(grown.n > 1.5 * before.n, `the cloud grew: ${before.n} → ${grown.n} px`);
      await page.keyboard.press('Delete');
      s = await until(page, (s) => s.scene.ellipsoids.length === 0, 'deleted');
      assert.match(s.view.notice.text, /Deleted Ellipsoid 1/);
    });
  });
}

// The gizmo: a drag on the X arrow moves the ellipsoid along x only, however the pointer
// wanders; G then X does the same from anywhere; Esc in the middle of a drag takes it back;
// Shift+H hides the ellipsoid (the cloud goes), Alt+H shows it; F frames it; Ctrl+D is kept
// from the browser (its bookmark dialog).
for (const backend of EDITING_BUILDS) {
  test(`gizmo arrows, axis lock, Esc, hide and frame (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const view = s.view.viewport;
      const [vw, vh] = view;
      const bg = toBytes(s.scene.light.background);
      s = await addEllipsoids(page, [[0.4, 0.5]]);
      await page.keyboard.press('Shift+G');
      s = await until(page, (s) => s.view.gizmo?.x, 'the move gizmo with an x arrow');
      const camera = JSON.stringify(s.scene.camera);
      const c0 = s.scene.ellipsoids[0].center;
      const { center, x: xEnd } = s.view.gizmo;
      await screenshot(page, `gizmo-1-move-${backend}`);

      // Along the X arrow, with the pointer wandering up and down by 60 px: pointer events at
      // input rate, not one per frame.
      const grab = [center[0] + 0.7 * (xEnd[0] - center[0]), center[1] + 0.7 * (xEnd[1] - center[1])];
      await page.mouse.move(grab[0], grab[1]);
      await page.mouse.down();
      for (let i = 1; i <= 20; i++) await page.mouse.move(grab[0] + i * 8, grab[1] + (i % 2 ? -60 : 60) * (i / 20));
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[0].center[0] > c0[0] + 0.3, 'moved along x');
      let c1 = s.scene.ellipsoids[0].center;
      assert.ok(Math.abs(c1[1] - c0[1]) < 1e-4 && Math.abs(c1[2] - c0[2]) < 1e-4, `along x only: ${c0} → ${c1}`);
      assert.equal(JSON.stringify(s.scene.camera), camera, 'the camera stayed');

      // A free drag (from the empty sky) would move up too; with X locked it moves along x only.
      await page.keyboard.press('x');
      await until(page, (s) => s.view.axis_lock === 'X', 'x locked');
      await page.mouse.move(vw * 0.2, vh * 0.8);
      await page.mouse.down();
      for (let i = 1; i <= 15; i++) await page.mouse.move(vw * 0.2 + i * 6, vh * 0.8 - i * 10);
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[0].center[0] > c1[0] + 0.2, 'moved along x (locked)');
      const c2 = s.scene.ellipsoids[0].center;
      assert.ok(Math.abs(c2[1] - c1[1]) < 1e-4 && Math.abs(c2[2] - c1[2]) < 1e-4, `locked to x: ${c1} → ${c2}`);
      await page.keyboard.press('x');
      await until(page, (s) => s.view.axis_lock === null, 'free again');

      // Esc in the middle of a drag: back where it began, no undo step.
      const undo = s.view.undo;
      await page.mouse.move(vw * 0.2, vh * 0.8);
      await page.mouse.down();
      for (let i = 1; i <= 10; i++) await page.mouse.move(vw * 0.2 + i * 10, vh * 0.8 - i * 10);
      await until(page, (s) => s.scene.ellipsoids[0].center[1] > c2[1] + 0.2, 'dragging');
      await page.keyboard.press('Escape');
      s = await until(page, (s) => /Cancelled/.test(s.view.notice?.text ?? ''), 'cancelled');
      for (let i = 1; i <= 5; i++) await page.mouse.move(vw * 0.4 + i * 10, vh * 0.6);
      await page.mouse.up();
      s = await state(page);
      assert.deepEqual(s.scene.ellipsoids[0].center, c2, 'back where the drag began');
      assert.equal(s.view.undo, undo, 'no undo step');
      assert.equal(s.view.selected_ellipsoid, 0, 'still selected');

      // Shift+H hides it (the sky is empty), Alt+H shows it again.
      await page.keyboard.press('h'); // guides off, to see the cloud alone
      await waitForFullQuality(page);
      const shown = cloud(await screenshot(page, `gizmo-2-shown-${backend}`), view, bg);
      await page.keyboard.down('Shift'); await page.keyboard.press('h'); await page.keyboard.up('Shift');
      s = await until(page, (s) => s.scene.ellipsoids[0].hidden === true, 'hidden');
      await waitForFullQuality(page);
      const hidden = cloud(await screenshot(page, `gizmo-3-hidden-${backend}`), view, bg);
      assert.ok(shown.n > 5000 && hidden.n < 0.02 * shown.n, `hidden: ${shown.n} → ${hidden.n} px`);
      await page.keyboard.down('Alt'); await page.keyboard.press('h'); await page.keyboard.up('Alt');
      s = await until(page, (s) => !s.scene.ellipsoids[0].hidden, 'shown again');
      await page.keyboard.press('h');

      // F frames the selection: the camera turns to the ellipsoid.
      await page.keyboard.press('f');
      s = await until(page, (s) => Math.hypot(...s.scene.camera.target.map((t, i) => t - c2[i])) < 1e-3, 'framed on the ellipsoid');

      // Ctrl+D duplicates, and the browser's own Ctrl+D (bookmark) is prevented.
      const prevented = await page.evaluate(() => {
        const e = new KeyboardEvent('keydown', { key: 'd', code: 'KeyD', ctrlKey: true, bubbles: true, cancelable: true });
        document.getElementById('cloudsketch_canvas').dispatchEvent(e);
        return e.defaultPrevented;
      });
      assert.ok(prevented, 'Ctrl+D kept from the browser');
      await until(page, (s) => s.scene.ellipsoids.length === 2, 'duplicated');
    });
  });
}

// Several at once: a box dragged with Move and nothing selected selects both ellipsoids; a drag
// on the X arrow moves both by the same distance; Shift+click takes one out; Ctrl+D duplicates
// the selection; one Ctrl+Z undoes the whole move.
for (const backend of EDITING_BUILDS) {
  test(`box select, move several, Shift+click (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const [vw, vh] = s.view.viewport;
      s = await addEllipsoids(page, [[0.3, 0.5], [0.6, 0.5]]);
      const before = s.scene.ellipsoids.map((e) => e.center);
      await page.keyboard.press('Shift+G');
      await page.keyboard.press('Escape'); // nothing selected: a drag now draws a box
      await until(page, (s) => s.view.selected_ellipsoids.length === 0, 'nothing selected');
      await page.mouse.move(vw * 0.15, vh * 0.3);
      await page.mouse.down();
      for (let i = 1; i <= 12; i++) await page.mouse.move(vw * (0.15 + i * 0.05), vh * (0.3 + i * 0.03));
      await screenshot(page, `select-1-box-${backend}`);
      await page.mouse.up();
      s = await until(page, (s) => s.view.selected_ellipsoids.length === 2, 'both in the box');
      assert.deepEqual(s.scene.ellipsoids.map((e) => e.center), before, 'a box moves nothing');
      const undo = s.view.undo;
      const { center, x: xEnd } = s.view.gizmo;
      const grab = [center[0] + 0.7 * (xEnd[0] - center[0]), center[1] + 0.7 * (xEnd[1] - center[1])];
      await page.mouse.move(grab[0], grab[1]);
      await page.mouse.down();
      for (let i = 1; i <= 12; i++) await page.mouse.move(grab[0] + i * 10, grab[1]);
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[1].center[0] > before[1][0] + 0.3, 'moved');
      const dx = s.scene.ellipsoids.map((e, i) => e.center[0] - before[i][0]);
      assert.ok(Math.abs(dx[0] - dx[1]) < 1e-4 && dx[0] > 0.3, `both moved alike: ${dx}`);
      assert.equal(s.view.undo, undo + 1, 'one undo step for both');
      await screenshot(page, `select-2-moved-${backend}`);
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => Math.abs(s.scene.ellipsoids[0].center[0] - before[0][0]) < 1e-4 && Math.abs(s.scene.ellipsoids[1].center[0] - before[1][0]) < 1e-4, 'both back with one undo');
      // Shift+click on the first one's cloud takes it out of the selection.
      await page.keyboard.down('Shift');
      await page.mouse.click(vw * 0.3, vh * 0.5);
      await page.keyboard.up('Shift');
      s = await until(page, (s) => s.view.selected_ellipsoids.length === 1, 'one taken out');
      assert.deepEqual(s.view.selected_ellipsoids, [1]);
      await page.keyboard.press('Control+d');
      s = await until(page, (s) => s.scene.ellipsoids.length === 3, 'the selection duplicated');
      assert.deepEqual(s.view.selected_ellipsoids, [2]);
    });
  });
}

// One renderer on both sides: the same scene (the default cumulus of six ellipsoids, one of
// them moved) rendered by the native CLI (lavapipe) and shown in the page covers the same
// pixels. The native binary is the one `cargo test` built before these tests run.
const NATIVE = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../target/debug/cloudsketch');

/** Cloud mask of an RGBA image over `w`×`h` (pixels away from the sky colour `bg`). */
function mask(img, w, h, bg) {
  const m = new Uint8Array(w * h);
  for (let y = 60; y < h - 30; y++) {
    for (let x = 0; x < w; x++) {
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - bg[0]) + Math.abs(img.data[i + 1] - bg[1]) + Math.abs(img.data[i + 2] - bg[2]);
      m[y * w + x] = d > 24 ? 1 : 0;
    }
  }
  return m;
}

for (const backend of BOTH_BUILDS) {
  test(`a scene with ellipsoids looks the same natively and in the page (${backend})`, { timeout: 240_000 }, async () => {
    assert.ok(fs.existsSync(NATIVE), `${NATIVE} missing: run cargo test (it builds the CLI) first`);
    await withApp({ base: server.url, webgpu: backend === 'webgpu', viewport: { width: 1280, height: 800 } }, async (page) => {
      await page.evaluate(() => window.cloudsketch.set('/ellipsoids/2/center=[4,5,1]'));
      await until(page, (s) => s.scene.ellipsoids[2].center[1] === 5, 'moved by set()');
      await page.mouse.click(5, 795);
      await page.keyboard.press('h');
      await waitForFullQuality(page);
      const s = await state(page);
      const [vw, vh] = s.view.viewport;
      const bg = toBytes(s.scene.light.background);
      const shot = await screenshot(page, `parity-page-${backend}`);
      const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cloudsketch-parity-'));
      const scene = path.join(dir, 'scene.json');
      fs.writeFileSync(scene, JSON.stringify(s.scene));
      const out = path.join(SCREENSHOTS, `parity-native-${backend}.png`);
      execFileSync(NATIVE, ['render', scene, '-o', out, '--size', `${vw}x${vh}`], { env: { ...process.env, NODEVICE_SELECT: '1' } });
      const native = PNG.sync.read(fs.readFileSync(out));
      const [a, b] = [mask(shot, vw, vh, bg), mask(native, vw, vh, bg)];
      let both = 0, either = 0;
      for (let i = 0; i < a.length; i++) { both += a[i] & b[i]; either += a[i] | b[i]; }
      const iou = both / either;
      assert.ok(either > 20_000, `a cloud is drawn: ${either} px`);
      assert.ok(iou > 0.9, `page and native cover the same pixels: IoU ${iou.toFixed(3)}`);
    });
  });
}

// Thousands of primitives in the page: 2,000 ellipsoids, then one moved at a time. Each move
// re-evaluates only the bricks it reaches (a partial update, checked by its texel count), and
// its wall time in the wasm build is recorded (test-results/timings.json) beside the native
// bench's figure; no time is asserted.
test('one of 2,000 ellipsoids moved updates only what it reaches (webgpu)', { timeout: 240_000 }, async () => {
  await withApp({ base: server.url, webgpu: true, query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
    let seed = 2000;
    const u = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
    const bank = Array.from({ length: 2000 }, () => ({
      center: [u() * 24 - 12, u() * 5, u() * 24 - 12],
      radii: [0.5 + u(), 0.3 + u() * 0.5, 0.5 + u()],
    }));
    await page.evaluate((json) => window.cloudsketch.set(`/ellipsoids=${json}`), JSON.stringify(bank));
    let s = await until(page, (s) => s.scene.ellipsoids.length === 2000 && s.view.geometry_update?.of > 0, '2,000 ellipsoids baked', 120_000);
    const full = s.view.geometry_update;
    assert.equal(full.texels, full.of, 'the first bake evaluates every texel');
    const times = [];
    for (let k = 0; k < 7; k++) {
      const count = s.view.geometry_update.count;
      const i = (k * 283) % 2000;
      const c = bank[i].center;
      await page.evaluate((p) => window.cloudsketch.set(p), `/ellipsoids/${i}/center=[${c[0] + 0.4},${c[1]},${c[2]}]`);
      s = await until(page, (s) => s.view.geometry_update.count > count, `move ${k}`);
      const g = s.view.geometry_update;
      assert.ok(g.texels < g.of / 4, `a partial update: ${g.texels} of ${g.of} texels`);
      times.push(g.ms);
    }
    times.sort((a, b) => a - b);
    recordTiming({ test: 'field_one_of_2000_moved', backend: 'webgpu', medianMs: times[3], fullBakeMs: full.ms, texels: full.of });
  });
});
