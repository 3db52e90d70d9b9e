// Ellipsoids in the browser: the Ellipsoid tool adds one where a click lands; the Move tool
// drags it (the cloud follows, the camera stays); Ctrl+Z undoes the drag as one step; the
// Scale tool grows it; Delete removes it. Screenshots: test-results/screenshots/ellipsoid-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, state, screenshot, countDiffering, until, withApp, waitForFullQuality } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const toBytes = (rgb) => rgb.map((v) => Math.round(v * 255));

/** Horizontal centroid and count of the pixels that differ from the sky. */
function cloud(img, [vw, vh], bg) {
  let n = 0, sx = 0;
  for (let y = 0; y < vh; y++) {
    for (let x = 0; x < vw; x++) {
      const i = 4 * (y * img.width + x);
      const d = Math.abs(img.data[i] - bg[0]) + Math.abs(img.data[i + 1] - bg[1]) + Math.abs(img.data[i + 2] - bg[2]);
      if (d > 24) { n++; sx += x; }
    }
  }
  return { n, x: n ? sx / n : NaN };
}

for (const backend of ['webgpu', 'webgl2']) {
  test(`add an ellipsoid with its tool, move it, undo, scale it, delete (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const view = s.view.viewport;
      const [vw, vh] = view;
      const bg = toBytes(s.scene.light.background);
      await page.mouse.click(vw * 0.05, vh * 0.95);
      await page.keyboard.press('e');
      await until(page, (s) => s.view.tool === 'ellipsoid', 'ellipsoid tool');
      await page.mouse.click(vw * 0.4, vh * 0.5);
      s = await until(page, (s) => s.scene.ellipsoids.length === 1, 'an ellipsoid');
      assert.equal(s.view.selected_ellipsoid, 0);
      assert.match(s.view.notice.text, /Added Ellipsoid 1/);
      await page.keyboard.press('h'); // the indicator off: look at the cloud alone
      await waitForFullQuality(page);
      const placed = cloud(await screenshot(page, `ellipsoid-1-added-${backend}`), view, bg);
      assert.ok(placed.n > 0.01 * vw * vh, `a cloud where the click was: ${placed.n} px`);
      assert.ok(Math.abs(placed.x - vw * 0.4) < vw * 0.05, `centred on the click: ${placed.x}`);

      // Move: the cloud follows the drag, the camera stays.
      const camera = JSON.stringify(s.scene.camera);
      const undo = s.view.undo;
      const x0 = s.scene.ellipsoids[0].center[0];
      await page.keyboard.press('g');
      await until(page, (s) => s.view.tool === 'move', 'move tool');
      await page.mouse.move(vw * 0.4, vh * 0.5);
      await page.mouse.down();
      for (let i = 1; i <= 15; i++) await page.mouse.move(vw * 0.4 + i * 12, vh * 0.5);
      await page.mouse.up();
      s = await until(page, (s) => s.scene.ellipsoids[0].center[0] > x0 + 0.5, 'the ellipsoid moved right');
      assert.equal(JSON.stringify(s.scene.camera), camera, 'the camera stayed');
      assert.equal(s.view.undo, undo + 1, 'one drag, one undo step');
      await waitForFullQuality(page);
      const moved = cloud(await screenshot(page, `ellipsoid-2-moved-${backend}`), view, bg);
      assert.ok(moved.x > placed.x + 100, `the cloud followed: ${placed.x} → ${moved.x}`);

      await page.keyboard.press('Control+z');
      s = await until(page, (s) => Math.abs(s.scene.ellipsoids[0].center[0] - x0) < 1e-4, 'the move undone');
      // Scale: a drag right grows it, and the cloud with it.
      const r0 = s.scene.ellipsoids[0].radii[0];
      await page.keyboard.press('s');
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
