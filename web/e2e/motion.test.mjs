// Particle motion in the browser (Schpok et al. 2003 §3.1, Figure 5), driven as a user drives
// it at 1280×800: the developing preset scrubbed from its first frame to its last rises and
// widens; the Scene group's "moves with time" takes one ellipsoid's motion off (it then stays
// put while the others go back in time) and undo puts it back.
// Screenshots: test-results/screenshots/motion-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, state, screenshot, until, withApp, waitForFullQuality, openGroup, reveal, scrubTo, cloudExtent, EDITING_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const toBytes = (rgb) => rgb.map((v) => Math.round(v * 255));

for (const backend of EDITING_BUILDS) {
  test(`the developing cumulus rises and widens along the timeline; a motion taken off stays put and undo restores it (${backend})`, { timeout: 300_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=developing', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const view = s.view.viewport;
      const bg = toBytes(s.scene.light.background);
      assert.equal(s.scene.clock.end, 480, 'a 20 s range');
      assert.ok(s.scene.ellipsoids.every((e) => e.motion || e.id === 100), 'every ellipsoid moves but the anvil, which is keyed');
      assert.ok(s.scene.wind_field.shear > 0, 'a sheared wind');
      await waitForFullQuality(page);
      const first = cloudExtent(await screenshot(page, `motion-1-frame0-${backend}`), view, bg);
      assert.ok(first.width > 40, `a cloud: ${JSON.stringify(first)}`);

      s = await scrubTo(page, 480);
      await waitForFullQuality(page);
      const last = cloudExtent(await screenshot(page, `motion-2-frame480-${backend}`), view, bg);
      assert.ok(last.top < first.top - 40, `the top rose: ${first.top} → ${last.top}`);
      assert.ok(last.width > first.width + 60, `it widened: ${first.width} → ${last.width}`);

      // Ellipsoid 8 (in the column) without its motion: it stays where it stands now.
      await openGroup(page, 'Scene');
      let r = await reveal(page, 'ellipsoid:8');
      await page.mouse.click(r[0] + r[2] / 2, r[1] + r[3] / 2);
      await until(page, (s) => s.view.selected_ellipsoid === 7, 'ellipsoid 8 selected');
      r = await reveal(page, 'motion:moves');
      await page.mouse.click(r[0] + 8, r[1] + r[3] / 2);
      s = await until(page, (s) => !s.scene.ellipsoids[7].motion, 'its motion off');
      const stays = s.scene.ellipsoids[7].center;
      const other = s.scene.ellipsoids[8].center;
      s = await scrubTo(page, 0);
      assert.deepEqual(s.scene.ellipsoids[7].center, stays, 'without motion it stays');
      assert.ok(s.scene.ellipsoids[8].center[1] < other[1] - 1, 'the others go back down');
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => s.scene.ellipsoids[7].motion, 'its motion back');
      assert.match(s.view.notice.text, /Undid: change the motion of an ellipsoid/);
      assert.ok(s.scene.ellipsoids[7].center[1] < stays[1] - 1, `back at its start at frame 0: ${s.scene.ellipsoids[7].center}`);
    });
  });
}
