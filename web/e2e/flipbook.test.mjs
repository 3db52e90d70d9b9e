// Cached playback (a flipbook) in the browser, driven as a user drives it at 1280×800: Cache
// renders every frame of the range once (progress on the timeline, the page answering
// meanwhile), Play then shows the kept frames at the document's frame rate; caching again
// with nothing changed renders nothing, and an edit that changes every frame renders them all
// again. The quality is lowered to 16 slices first (setup) so the run fits the suite's time.
// Screenshots: test-results/screenshots/flipbook-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, state, screenshot, until, withApp, BOTH_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function click(page, name) {
  const [x, y, w, h] = (await state(page)).view.widgets[name];
  await page.mouse.click(x + w / 2, y + h / 2);
}

for (const backend of BOTH_BUILDS) {
  test(`Cache renders the range once, Play shows the cached frames at the frame rate, an edit re-renders what it changes (${backend})`, { timeout: 600_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=developing', viewport: { width: 1280, height: 800 } }, async (page) => {
      await page.evaluate(() => { window.cloudsketch.set('/clock/end=11'); window.cloudsketch.set('/render/slices=16'); });
      let s = await until(page, (s) => s.scene.clock.end === 11 && s.scene.render.slices === 16, 'a 12-frame range');
      assert.equal(s.view.timeline.cache.frames, 0);

      await click(page, 'timeline:cache');
      s = await until(page, (s) => s.view.timeline.cache.building, 'caching');
      // The page answers while it caches: the progress moves on, frame by frame.
      const seen = new Set();
      s = await until(page, (s) => {
        const p = s.view.timeline.cache.progress;
        if (p) seen.add(p[0]);
        return !s.view.timeline.cache.building;
      }, 'cached', 420_000);
      assert.equal(s.view.timeline.cache.frames, 12, JSON.stringify(s.view.timeline.cache));
      assert.ok(seen.size >= 4, `progress seen at ${[...seen]}`);
      assert.match(s.view.notice.text, /Cached 12 frames/);
      assert.equal(Math.round(s.view.timeline.frame), 0, 'back where it began');

      // Loop and Play: the time runs at 24 frames a second and the kept frames are shown.
      await click(page, 'timeline:loop');
      await click(page, 'timeline:play');
      await sleep(500);
      // Frames played (the range loops every 12), summed over page-state reads a few frames
      // apart; where a second or more played between two reads (stalled frames), the whole
      // loops the frame number cannot show are counted from the time the page played.
      const t0 = Date.now();
      const a = await state(page);
      const playedS = (s) => s.view.timeline.ticked_s - s.view.timeline.stalled_s;
      let prev = a, played = 0, b = a;
      while (Date.now() - t0 < 3000) {
        await sleep(100);
        b = await state(page);
        const step = (b.view.timeline.frame - prev.view.timeline.frame + 12) % 12;
        const loops = Math.round((24 * (playedS(b) - playedS(prev)) - step) / 12);
        played += step + 12 * Math.max(0, loops);
        prev = b;
      }
      const seconds = (Date.now() - t0) / 1000;
      await screenshot(page, `flipbook-1-playing-${backend}`);
      // The page's own account of the wall time it ticked through, and of the stalls it did
      // not play (a frame may advance the clock half a second at most). What it ticked must be
      // the wall time; what it played must be its frames at 24 a second, with nothing lost at
      // the wraps (a loop that dropped its overshoot played 15–20 a second). A machine busy
      // enough to stall frames for over half a second plays slower, and says so.
      const ticked = b.view.timeline.ticked_s - a.view.timeline.ticked_s;
      const stalled = b.view.timeline.stalled_s - a.view.timeline.stalled_s;
      const rate = played / (ticked - stalled);
      console.log(`# ${backend} ${JSON.stringify({ played, seconds, ticked, stalled, rate })}`);
      // (Each read sees the state of a frame that began up to a frame before it.)
      assert.ok(ticked <= seconds + 0.5 && ticked >= 0.6 * seconds, `ticked ${ticked.toFixed(2)} s of ${seconds} s`);
      assert.ok(ticked - stalled > 1, `played ${(ticked - stalled).toFixed(2)} s of ${seconds} s: the page stalled`);
      assert.ok(Math.abs(rate - 24) < 2.5, `${played.toFixed(1)} frames in ${(ticked - stalled).toFixed(2)} s played (${stalled.toFixed(2)} s stalled, ${seconds} s in all)`);
      assert.ok(b.view.timeline.cache.showing, 'a cached frame shown');
      const shown = b.view.timeline.cache.shown - a.view.timeline.cache.shown;
      assert.ok(shown >= 5, `cached frames drawn: ${shown}`);
      await click(page, 'timeline:play');
      s = await until(page, (s) => !s.view.timeline.playing, 'paused');

      // Nothing changed: caching again renders nothing.
      await click(page, 'timeline:cache');
      s = await until(page, (s) => !s.view.timeline.cache.building && /Cached 12 frames/.test(s.view.notice.text) && s.view.timeline.cache.frames === 12, 'nothing to cache', 30_000);
      // The sun lower: every frame changes, and every frame is rendered again.
      await page.evaluate(() => window.cloudsketch.set('/light/sun_elevation_deg=15'));
      await until(page, (s) => s.scene.light.sun_elevation_deg === 15, 'sun lower');
      await click(page, 'timeline:cache');
      s = await until(page, (s) => s.view.timeline.cache.progress?.[0] === 0 && s.view.timeline.cache.progress?.[1] === 12, 'every frame again');
      await click(page, 'timeline:cache');
      s = await until(page, (s) => !s.view.timeline.cache.building, 'cancelled');
      assert.match(s.view.notice.text, /Caching cancelled/);
    });
  });
}
