// The cloud simulation in the browser: the `simulated` preset opens with clouds in its three
// parcels; playing changes the image while the clouds stay where the parcels are; moving a
// parcel moves where the clouds form. Screenshots: test-results/screenshots/simulation-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { serve, state, screenshot, countChanged, until, withApp, waitForFullQuality, recordTiming, reveal, openGroup, BOTH_BUILDS } from './harness.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

/** The cloud's pixels (away from the flat sky `bg`): count, bounding box, mean x. */
function cloud(img, rect, bg) {
  let n = 0, sx = 0, x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (let y = rect.y; y < rect.y + rect.h; y++) {
    for (let x = rect.x; x < rect.x + rect.w; x++) {
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - bg[0]) + Math.abs(img.data[i + 1] - bg[1]) + Math.abs(img.data[i + 2] - bg[2]);
      if (d > 18) { n++; sx += x; x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
    }
  }
  return { n, cx: sx / Math.max(n, 1), box: [x0, y0, x1, y1] };
}

for (const backend of BOTH_BUILDS) {
  test(`the simulated preset plays inside its parcels and follows a moved parcel (${backend})`, { timeout: 300_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=simulated', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      assert.ok(s.scene.simulation, 'the preset simulates');
      assert.ok(s.scene.light.ground, 'over a ground plane');
      // Without the ground, every pixel away from the flat sky is cloud.
      await page.evaluate(() => window.cloudsketch.set('/light/ground=false'));
      s = await until(page, (s) => !s.scene.light.ground, 'no ground');
      const [vw, vh] = s.view.viewport;
      // Below the sun handle and short of the side panel's border, which would read as cloud.
      const body = { x: 0, y: 130, w: vw - 12, h: vh - 160 };
      const bg = s.scene.light.background.map((v) => Math.round(v * 255));
      await page.mouse.click(5, vh - 5);
      await waitForFullQuality(page);
      const start = await screenshot(page, `simulation-1-start-${backend}`);
      const c0 = cloud(start, body, bg);
      assert.ok(c0.n > 2000, `clouds in the parcels at the start: ${c0.n} px`);

      // Play for a few seconds of scene time: the image changes, the camera stays.
      const camera = JSON.stringify(s.scene.camera);
      const t0 = s.scene.time;
      const wall0 = Date.now();
      await page.keyboard.press('Alt+a');
      s = await until(page, (s) => s.scene.time > t0 + 3, 'the clock runs', 90_000);
      const wall = (Date.now() - wall0) / 1000;
      await page.keyboard.press('Alt+a');
      // Steps the page simulated per second of wall time while playing (the clock is the
      // scene's: `rate` steps per scene second).
      const steps = (s.scene.time - t0) * s.scene.simulation.rate;
      recordTiming({ test: 'simulation_play_128x32x128', backend, stepsPerSecond: steps / wall, sceneSeconds: s.scene.time - t0, wallSeconds: wall });
      s = await until(page, (s) => !s.view.playing, 'paused');
      await waitForFullQuality(page);
      const played = await screenshot(page, `simulation-2-played-${backend}`);
      const changed = countChanged(start, played, body);
      assert.ok(changed > 500, `the clouds evolved: ${changed} px changed after ${(s.scene.time - t0).toFixed(1)} s`);
      assert.equal(JSON.stringify(s.scene.camera), camera, 'the camera stayed');
      const c1 = cloud(played, body, bg);
      const margin = 0.06 * vw;
      assert.ok(c1.box[0] >= c0.box[0] - margin && c1.box[2] <= c0.box[2] + margin,
        `the clouds stay in the parcels: x ${c0.box[0]}–${c0.box[2]} then ${c1.box[0]}–${c1.box[2]}`);

      // Drag the leftmost parcel far to the right with the move gizmo's X arrow (selected
      // from its E1 button in the Scene group): clouds form there, not where it was.
      const undo = s.view.undo;
      await openGroup(page, 'Scene');
      const button = await reveal(page, 'ellipsoid:1');
      await page.mouse.click(button[0] + button[2] / 2, button[1] + button[3] / 2);
      await page.mouse.move(5, vh - 5);
      await page.keyboard.press('Shift+G');
      s = await until(page, (s) => s.view.gizmo?.x, 'the move gizmo on the first parcel');
      const c0p = s.scene.ellipsoids[0].center;
      const { center, x: xEnd } = s.view.gizmo;
      const grab = [center[0] + 0.7 * (xEnd[0] - center[0]), center[1] + 0.7 * (xEnd[1] - center[1])];
      await page.mouse.move(grab[0], grab[1]);
      await page.mouse.down();
      for (let i = 1; i <= 30; i++) await page.mouse.move(grab[0] + i * 20, grab[1] + (i % 2 ? -8 : 8));
      await page.mouse.up();
      s = await until(page, (s) => s.view.undo === undo + 1, 'the parcel moved, one undo step');
      const c1p = s.scene.ellipsoids[0].center;
      assert.ok(c1p[0] > c0p[0] + 8, `dragged far right: x ${c0p[0]} → ${c1p[0].toFixed(2)}`);
      assert.ok(Math.abs(c1p[1] - c0p[1]) < 1e-4 && Math.abs(c1p[2] - c0p[2]) < 1e-4, 'along x only');
      await page.mouse.move(5, vh - 5);
      await waitForFullQuality(page);
      const moved = await screenshot(page, `simulation-3-parcel-moved-${backend}`);
      const c2 = cloud(moved, body, bg);
      assert.ok(c2.cx > c1.cx + 40, `the clouds' middle moves right with the parcel: ${c1.cx.toFixed(0)} → ${c2.cx.toFixed(0)} px`);
      assert.ok(c2.box[2] > c1.box[2] + 40, `a cloud where the parcel went: right edge ${c1.box[2]} → ${c2.box[2]}`);
    });
  });
}

// The automaton's step in the page (`?bench=ca`): the same grid and code as the native bench's
// `ca_step_256x64x256_one_thread` (the page has one thread), timed by the page's clock, with the
// same step a word at a time (no SIMD) as its baseline. The figures go to
// test-results/timings.json with their ratios; speed is not asserted.
test('the page times the automaton as the native bench does (?bench=ca)', { timeout: 240_000 }, async () => {
  await withApp({ base: server.url, webgpu: true, query: '?preset=empty&bench=ca', viewport: { width: 1280, height: 800 } }, async (page) => {
    const s = await until(page, (s) => s.bench, 'the page bench', 180_000);
    const b = s.bench;
    assert.equal(b.cells, 256 * 64 * 256, 'the benchmarks\' grid');
    assert.ok(b.ca_step_ms > 0 && b.ca_word_step_ms > 0 && b.ca_smoothing_ms > 0, JSON.stringify(b));
    // The page's step runs the rule on two words per SIMD register; a word at a time must give
    // the same cells (this is the only place the wasm SIMD path runs under test).
    assert.equal(b.ca_pairs_match, true, 'the paired step gives the word-at-a-time step\'s bits');
    let native = null;
    const exe = path.resolve(here, '../../target/release/cloudsketch');
    if (fs.existsSync(exe)) {
      const out = execFileSync(exe, ['bench', '--json', '--only', 'simulate'], { encoding: 'utf8', env: { ...process.env, NODEVICE_SELECT: '1' } });
      const step = JSON.parse(out).results.find((r) => r.name === 'ca_step_256x64x256_one_thread');
      native = step?.value ?? null;
    }
    recordTiming({
      test: 'ca_step_256x64x256', backend: 'wasm', pageMs: b.ca_step_ms, pageWordStepMs: b.ca_word_step_ms,
      pageSmoothingMs: b.ca_smoothing_ms,
      nativeMs: native, pageOverNative: native ? b.ca_step_ms / native : null,
    });
  });
});

// A far jump in time: the simulation catches up over frames (200 steps a frame) while the
// document stays as it is, and the image must show where it arrives, as a fresh image of the
// same view does. Which passed clouds a refinement begun during the catching up draws on is a
// matter of timing here (late in a long jump they look like the arrival), so the view's image
// key, which must change with each frame's cloud, is tested apart
// (`ui::viewport::tests::each_frame_a_simulation_catches_up_keys_a_new_image`); this test
// asserts no timing, only that the arrival looks unlike the start (an image kept from before
// the jump cannot pass for it) and that the shown image is the arrival's. The jump goes to the
// automaton's last step, 20,000 (2,000 s at the preset's 10 steps a second).
test('after a far jump in time the image shows the cloud the simulation caught up with', { timeout: 420_000 }, async () => {
  await withApp({ base: server.url, webgpu: true, query: '?preset=simulated&refine=whole', viewport: { width: 900, height: 560 } }, async (page) => {
    await page.evaluate(() => window.cloudsketch.set('/light/ground=false'));
    let s = await until(page, (s) => !s.scene.light.ground, 'no ground');
    const settled = await waitForFullQuality(page);
    const [vw, vh] = s.view.viewport;
    const body = { x: 0, y: 130, w: vw - 320, h: vh - 160 };
    const start = await screenshot(page, 'simulation-jump-start');
    await page.evaluate(() => window.cloudsketch.set('/time=2000'));
    s = await until(page, (s) => s.scene.time === 2000 && s.view.catching_up, 'catching up');
    const t0 = Date.now();
    await until(page, (s) => !s.view.catching_up, 'caught up', 240_000);
    const caught = (Date.now() - t0) / 1000;
    const after = await waitForFullQuality(page);
    console.log(`# caught up in ${caught} s, then full quality in ${after.seconds} s (the view refined in ${settled.seconds} s)`);
    const shown = await screenshot(page, 'simulation-jump-shown');
    // The same view drawn afresh: a slice count there and back (two edits) redraws it.
    await page.evaluate(() => window.cloudsketch.set('/render/slices=127'));
    await until(page, (s) => s.scene.render.slices === 127, '127 slices');
    await page.evaluate(() => window.cloudsketch.set('/render/slices=128'));
    await until(page, (s) => s.scene.render.slices === 128, '128 slices');
    await waitForFullQuality(page);
    const fresh = await screenshot(page, 'simulation-jump-fresh');
    const changed = countChanged(shown, fresh, body);
    assert.ok(changed <= 50, `${changed} px differ from a fresh image of the same view`);
    const moved = countChanged(start, fresh, body);
    console.log(`# ${changed} px off a fresh image; ${moved} px off the start`);
    assert.ok(moved > 20 * 50, `the arrival looks like the start: ${moved} px differ`);

    // The clock's frame rate is the document's (an undo step that redraws nothing).
    const undo = (await state(page)).view.undo;
    assert.equal((await state(page)).scene.clock?.end, 2880, "the preset's two-minute range");
    await page.evaluate(() => window.cloudsketch.set('/clock/fps=30'));
    s = await until(page, (s) => s.scene.clock?.fps === 30, 'a frame rate of 30');
    assert.equal(s.view.undo, undo + 1);
    assert.ok(s.view.quality.startsWith('full'), 'the image stays: no image depends on the frame rate');
  });
});

// An outline sketched in a simulated scene is cloud too, beside the simulation's (before, a
// simulated scene drew no stroke at all).
test('an outline sketched in the simulated preset becomes cloud beside the simulated ones', { timeout: 300_000 }, async () => {
  await withApp({ base: server.url, webgpu: true, query: '?preset=simulated', viewport: { width: 1280, height: 800 } }, async (page) => {
    await page.evaluate(() => window.cloudsketch.set('/light/ground=false'));
    let s = await until(page, (s) => !s.scene.light.ground, 'no ground');
    const [vw, vh] = s.view.viewport;
    const bg = s.scene.light.background.map((v) => Math.round(v * 255));
    await page.mouse.click(5, vh - 5);
    await waitForFullQuality(page);
    // An outline in the empty sky above the simulated clouds (top left of the view).
    const [cx, cy, r] = [vw * 0.25, vh * 0.2, vh * 0.08];
    const area = { x: Math.round(cx - r), y: Math.round(cy - r * 0.5), w: Math.round(2 * r), h: Math.round(r) };
    const before = cloud(await screenshot(page, 'simulation-outline-0'), area, bg);
    assert.ok(before.n < 50, `empty sky where the outline goes: ${before.n} px`);
    await page.keyboard.press('d');
    await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
    await page.mouse.move(cx + r * 1.4, cy);
    await page.mouse.down();
    for (let i = 1; i <= 60; i++) {
      const a = (i / 60) * 2 * Math.PI;
      await page.mouse.move(cx + r * 1.4 * Math.cos(a), cy - r * Math.sin(a) * (1 + 0.15 * Math.sin(5 * a)));
    }
    await page.mouse.up();
    s = await until(page, (s) => s.scene.planes.length === 1, 'the stroke became a plane');
    assert.ok(s.scene.simulation, 'still a simulated scene');
    await waitForFullQuality(page);
    const after = cloud(await screenshot(page, 'simulation-outline-1'), area, bg);
    assert.ok(after.n > 0.3 * area.w * area.h, `the outline is cloud: ${after.n} of ${area.w * area.h} px`);
  });
});
