// The cloud's media in the browser: a Table 2 filter changes the image, and with wind the
// scene clock (Alt+A plays) moves the noise while the camera stays. Screenshots:
// test-results/screenshots/media-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, launch, openApp, waitForBody, state, screenshot, countChanged, until, withApp, waitForFullQuality } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

for (const backend of ['webgpu', 'webgl2']) {
  test(`a filter changes the media and playing moves it with the wind (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', viewport: { width: 1280, height: 800 } }, async (page) => {
      let s = await state(page);
      const [vw, vh] = s.view.viewport;
      const body = { x: 0, y: 60, w: vw, h: vh - 90 };
      await page.mouse.click(5, vh - 5);
      await waitForFullQuality(page);
      const plain = await screenshot(page, `media-1-default-${backend}`);
      await page.evaluate(() => window.cloudsketch.set('/render/noise_filter="wispy"'));
      await until(page, (s) => s.scene.render.noise_filter === 'wispy', 'wispy');
      await waitForFullQuality(page);
      const wispy = await screenshot(page, `media-2-wispy-${backend}`);
      const byFilter = countChanged(plain, wispy, body);
      assert.ok(byFilter > 2000, `the filter changed the image: ${byFilter} px`);

      // Wind, then play: the time runs, the image changes, the camera and the undo stack stay.
      await page.evaluate(() => window.cloudsketch.set('/render/wind=[2,0]'));
      s = await until(page, (s) => s.scene.render.wind[0] === 2, 'wind');
      await waitForFullQuality(page);
      const still = await screenshot(page, `media-3-windy-t0-${backend}`);
      const camera = JSON.stringify(s.scene.camera);
      const undo = s.view.undo;
      await page.keyboard.press('Alt+a');
      s = await until(page, (s) => s.view.playing && s.scene.time > 1.0, 'the clock runs', 60_000);
      await page.keyboard.press('Alt+a');
      s = await until(page, (s) => !s.view.playing, 'paused');
      await waitForFullQuality(page);
      const moved = await screenshot(page, `media-4-windy-played-${backend}`);
      const byWind = countChanged(still, moved, body);
      assert.ok(byWind > 2000, `the wind moved the noise: ${byWind} px after ${s.scene.time.toFixed(2)} s`);
      assert.equal(JSON.stringify(s.scene.camera), camera, 'the camera stayed');
      assert.equal(s.view.undo, undo, 'playing is no undo step');
    });
  });
}

// Every preset opens from its link (?preset=NAME) with its own framing and media, and each looks
// unlike every other (pairwise pixel differences; the shapes are measured offscreen).
for (const backend of ['webgpu', 'webgl2']) {
  test(`each preset opens from a link and looks its own (${backend})`, { timeout: 300_000 }, async () => {
    const { browser, close } = await launch({ webgpu: backend === 'webgpu' });
    try {
      const shots = {};
      for (const name of ['cumulus', 'stratus', 'cirrus', 'cumulonimbus', 'sunset']) {
        const { page, errors } = await openApp(browser, server.url, `?preset=${name}`, { width: 1280, height: 800 });
        await waitForBody(page, 'data-ready', (v) => v === 'true');
        await page.mouse.click(5, 795);
        await waitForFullQuality(page);
        const s = await state(page);
        assert.ok(s.scene.ellipsoids.length > 0, `${name}: a cloud`);
        shots[name] = { img: await screenshot(page, `preset-${name}-${backend}`), view: s.view.viewport };
        assert.deepEqual(errors, [], `${name}: errors logged`);
        await page.close();
      }
      const names = Object.keys(shots);
      const [vw, vh] = shots.cumulus.view;
      const body = { x: 0, y: 60, w: vw, h: vh - 90 };
      for (let i = 0; i < names.length; i++) {
        for (let j = i + 1; j < names.length; j++) {
          const d = countChanged(shots[names[i]].img, shots[names[j]].img, body);
          assert.ok(d > 0.05 * vw * vh, `${names[i]} vs ${names[j]}: ${d} px differ`);
        }
      }
    } finally {
      await close();
    }
  });
}
