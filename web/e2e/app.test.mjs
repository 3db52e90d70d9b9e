// The app in the browser: the default cloud is drawn (WebGPU, then the WebGL2 fallback), each
// browser fetches only the build it needs (the WebGPU build, or the one with the WebGL2
// fallback, also where a WebGPU device fails to start or `?backend=webgl` asks for it) and gets
// its precompressed Brotli copy, a drag orbits the camera and changes the image, nothing logs an
// error, ?preset=empty opens an empty scene, and a browser with neither WebGPU nor WebGL2 gets a
// plain message.
// Screenshots: web/test-results/screenshots/.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import {
  serve, launch, openApp, fetchedBuilds, waitForBody, waitForFullQuality, state, screenshot, countDiffering, countChanged, recordTiming, sunHandleBox, BOTH_BUILDS,
} from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const toBytes = (rgb) => rgb.map((v) => Math.round(v * 255));

/** Drags with the primary button from the viewport's centre by (dx, dy) in a few steps. */
async function drag(page, rect, dx, dy) {
  const x = rect.x + rect.w / 2;
  const y = rect.y + rect.h / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let i = 1; i <= 6; i++) {
    await page.mouse.move(x + (dx * i) / 6, y + (dy * i) / 6);
    await page.waitForTimeout(30);
  }
  await page.mouse.up();
}

for (const backend of BOTH_BUILDS) {
  test(`default cloud drawn and orbited (${backend})`, { timeout: 300_000 }, async () => {
    const { browser, close } = await launch({ webgpu: backend === 'webgpu' });
    try {
      const { page, errors, log, started } = await openApp(browser, server.url);
      try {
        // The first image of the cloud (a preview) on screen, then the first full-quality one.
        await waitForBody(page, 'data-quality', (v) => typeof v === 'string' && v.length > 0);
        const firstImageSeconds = (Date.now() - started) / 1000;
        await waitForBody(page, 'data-ready', (v) => v === 'true');
        const readySeconds = (Date.now() - started) / 1000;
        assert.equal(await page.getAttribute('body', 'data-backend'), backend, 'active backend');
        const builds = await fetchedBuilds(page);
        assert.deepEqual(builds.map((b) => b.build), [backend === 'webgpu' ? 'webgpu' : 'webgl'], 'the one build fetched');
        // The build came as its Brotli copy (web/precompress.mjs; the server sends it where the
        // browser accepts br, as Chromium does) and decoded to the build's own wasm.
        const [wasm] = builds;
        assert.ok(wasm.brotliBytes > 0 && wasm.gzipBytes > 0, `precompressed copies of the wasm: ${JSON.stringify(wasm)}`);
        assert.equal(wasm.transferBytes, wasm.brotliBytes, 'the browser received the Brotli copy');
        assert.equal(wasm.decodedBytes, wasm.bytes, 'which decoded to the wasm file');
        assert.ok(wasm.brotliBytes < wasm.gzipBytes, `Brotli ${wasm.brotliBytes} B < gzip ${wasm.gzipBytes} B`);
        const adapter = await page.getAttribute('body', 'data-adapter');
        const before = await state(page);
        const [vw, vh] = before.view.viewport;
        const rect = { x: 0, y: 0, w: vw, h: vh };
        const bg = toBytes(before.scene.light.background);

        const first = await screenshot(page, `${backend}-1-default`);
        const cloud = countDiffering(first, rect, bg);
        assert.ok(cloud > 0.03 * vw * vh, `cloud covers ${cloud} of ${vw * vh} viewport pixels (${first.file})`);
        // Away from the cloud the background is untouched: the viewport's top corners.
        for (const [x, y] of [[3, 3], [vw - 4, 3]]) {
          assert.equal(countDiffering(first, { x, y, w: 1, h: 1 }, bg), 0, `background at (${x},${y})`);
        }

        // The side panel's background (drawn by the renderer's flat fill under the panel, not by
        // egui): one colour, not the sky's, down its left margin, with the panel's widgets over it.
        const panel = { x: vw + 1, y: 0, w: first.width - vw - 1, h: first.height };
        const margin = { x: vw + 4, y: 100, w: 2, h: first.height - 120 };
        const at = 4 * (margin.y * first.width + margin.x);
        const fill = [...first.data.subarray(at, at + 3)];
        assert.equal(countDiffering(first, margin, fill, 6), 0, `panel background at x = ${margin.x} (${first.file})`);
        assert.equal(countDiffering(first, { ...margin, w: 1, h: 1 }, bg, 60), 1, `the panel's ${fill} is not the sky's ${bg}`);
        const widgets = countDiffering(first, panel, fill, 24);
        assert.ok(widgets > 3000, `${widgets} pixels of the panel's widgets over its background`);

        const t0 = Date.now();
        await drag(page, rect, 160, 0);
        const dragSeconds = (Date.now() - t0) / 1000;
        const { seconds: refineSeconds } = await waitForFullQuality(page);
        const afterDrag = await state(page);
        const yaw = afterDrag.scene.camera.yaw_deg - before.scene.camera.yaw_deg;
        // The whole drag, however few frames it fell in (six moves 30 ms apart: two or three
        // frames on a CPU adapter): 0.35° a point, leftward turns (yaw falls).
        const turned = ((yaw % 360) + 540) % 360 - 180;
        assert.ok(Math.abs(turned + 160 * 0.35) < 1.5, `drag turned the camera by ${turned.toFixed(1)}°, not ${-160 * 0.35}°`);
        const second = await screenshot(page, `${backend}-2-orbited`);
        const changed = countChanged(first, second, rect);
        assert.ok(changed > 0.01 * vw * vh, `orbit changed ${changed} viewport pixels (${second.file})`);
        assert.ok(countDiffering(second, rect, bg) > 0.03 * vw * vh, 'cloud still drawn after orbiting');

        assert.deepEqual(errors, [], `errors logged:\n${errors.join('\n')}`);
        recordTiming({ test: 'orbit', backend, adapter, wasmBytes: wasm.bytes, wasmGzipBytes: wasm.gzipBytes, wasmBrotliBytes: wasm.brotliBytes, wasmTransferBytes: wasm.transferBytes, firstImageSeconds, readySeconds, dragSeconds, refineSeconds, quality: afterDrag.view.quality });
      } catch (e) {
        console.error(log.slice(-40).join('\n'));
        await screenshot(page, `${backend}-failure`).catch(() => {});
        throw e;
      }
    } finally {
      await close();
    }
  });
}

test('a WebGPU device that fails to start falls back to the WebGL2 build; ?backend=webgl asks for it', { timeout: 240_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    // The browser offers a WebGPU adapter, but no device: the WebGPU build starts, fails, and
    // hands over to the WebGL2 build, which opens the preset the address asked for.
    const failing = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    const log = [];
    failing.on('console', (m) => log.push(`[${m.type()}] ${m.text()}`));
    await failing.addInitScript(() => {
      GPUAdapter.prototype.requestDevice = () => Promise.reject(new Error('no device (test)'));
    });
    await failing.goto(`${server.url}?preset=empty`);
    try {
      await waitForBody(failing, 'data-ready', (v) => v === 'true');
    } catch (e) {
      console.error(log.slice(-40).join('\n'));
      throw e;
    }
    assert.equal(await failing.getAttribute('body', 'data-backend'), 'webgl2');
    assert.deepEqual((await fetchedBuilds(failing)).map((b) => b.build), ['webgpu', 'webgl']);
    const s = await state(failing);
    assert.equal(s.scene.ellipsoids.length, 0, 'the preset survived the hand-over');
    assert.ok(!failing.url().includes('preset='), `the preset left the address once the app ran (${failing.url()})`);
    assert.equal(await failing.$('#error[style*="display:block"]'), null, 'no error box');
    await screenshot(failing, 'fallback-after-failed-device');
    await failing.close();

    // A working WebGPU, and the address asks for WebGL2.
    const { page, errors } = await openApp(browser, server.url, '?backend=webgl');
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    assert.equal(await page.getAttribute('body', 'data-backend'), 'webgl2');
    assert.deepEqual((await fetchedBuilds(page)).map((b) => b.build), ['webgl']);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

test('?preset=empty opens an empty scene', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty');
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    const s = await state(page);
    assert.equal(s.scene.ellipsoids.length, 0);
    const [vw, vh] = s.view.viewport;
    const img = await screenshot(page, 'webgpu-3-empty');
    // Only the hint text may differ from the background in an empty viewport (the sun handle
    // aside).
    assert.ok(s.view.sun_handle, 'the sun handle is drawn');
    const differing = countDiffering(img, { x: 0, y: 0, w: vw, h: vh }, toBytes(s.scene.light.background), 12, sunHandleBox(s.view));
    assert.ok(differing < 0.01 * vw * vh, `${differing} px differ from the sky`);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

test('without WebGPU and WebGL2 the page says so plainly', { timeout: 120_000 }, async () => {
  const { browser, close } = await launch({ webgpu: false, webgl: false });
  try {
    const { page } = await openApp(browser, server.url);
    await page.waitForSelector('#error[style*="display:block"]', { timeout: 60_000 });
    const text = await page.textContent('#error');
    assert.match(text, /neither WebGPU nor WebGL2/);
    assert.equal(await page.$('#loading'), null, 'the loading note is gone');
    assert.equal(await page.getAttribute('body', 'data-ready'), null);
    await screenshot(page, 'no-gpu-message');
  } finally {
    await close();
  }
});
