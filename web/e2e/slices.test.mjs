// Marched and rasterised slices in the browser. On a GPU the page marches the slices in a
// compute pass (shaders/volume_march.wgsl); on a CPU adapter (SwiftShader here) it rasterises
// them, and WebGL2 has no compute. `?slices=march` asks for the march on the CPU adapter, so this
// test runs the compute path through the browser's own shader compiler and checks that it gives
// the rasterised slices' image: the same preset, camera and full quality both ways, pixels
// within rounding. Screenshots: test-results/screenshots/slices-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, launch, openApp, waitForBody, state, screenshot, waitForFullQuality, recordTiming } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const VIEWPORT = { width: 1280, height: 800 };

/** Opens `query`, waits for full quality, returns the page's slice method, a screenshot and
 *  the seconds from navigation to full quality. */
async function shot(browser, query, name) {
  const t0 = Date.now();
  const { page, errors } = await openApp(browser, server.url, query, VIEWPORT);
  await waitForBody(page, 'data-ready', (v) => v === 'true');
  // The pointer away from the cloud and the sun handle, as in the other image tests.
  await page.mouse.click(5, VIEWPORT.height - 5);
  await waitForFullQuality(page);
  const seconds = (Date.now() - t0) / 1000;
  const s = await state(page);
  const img = await screenshot(page, name);
  assert.deepEqual(errors, [], `${name}: errors logged`);
  await page.close();
  return { slices: s.view.slices, quality: s.view.quality, img, seconds, viewport: s.view.viewport, background: s.scene.light.background };
}

test('marched slices give the rasterised image in the page (webgpu)', { timeout: 300_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    // By default (read from the first image: the choice is made with the renderer).
    const first = await openApp(browser, server.url, '?preset=cumulus', VIEWPORT);
    await waitForBody(first.page, 'data-ready', (v) => v === 'true');
    assert.equal((await state(first.page)).view.slices, 'rasterised', 'a CPU adapter rasterises the slices by default');
    await first.page.close();
    // Full quality at the view's whole resolution both ways (`refine=whole`): the planner
    // otherwise fits the resolution to the measured speed, which a busy machine changes
    // between the two loads (1,149 pixels over 6 in a full run beside other work).
    const marched = await shot(browser, '?preset=cumulus&slices=march&refine=whole', 'slices-marched-webgpu');
    assert.equal(marched.slices, 'marched', '?slices=march marches them');
    const rasterised = await shot(browser, '?preset=cumulus&slices=raster&refine=whole', 'slices-rasterised-webgpu');
    assert.equal(rasterised.slices, 'rasterised');
    assert.equal(marched.quality, rasterised.quality, 'the same full quality both ways');
    // The view's body (below the toolbar, above the status line, left of the side panel),
    // pixel by pixel.
    const [vw, vh] = marched.viewport;
    const right = vw - 320;
    const a = marched.img;
    const b = rasterised.img;
    let sum = 0;
    let n = 0;
    let far = 0;
    let cloud = 0;
    const sky = rasterised.background.map((v) => Math.round(v * 255));
    for (let y = 60; y < vh - 30; y++) {
      for (let x = 0; x < right; x++) {
        const i = 4 * (y * a.width + x);
        let d = 0;
        for (let c = 0; c < 3; c++) {
          d = Math.max(d, Math.abs(a.data[i + c] - b.data[i + c]));
          sum += Math.abs(a.data[i + c] - b.data[i + c]);
        }
        n += 3;
        if (d > 6) far++;
        // The cloud is on screen (the comparison is not of two skies).
        if (Math.abs(b.data[i] - sky[0]) + Math.abs(b.data[i + 1] - sky[1]) + Math.abs(b.data[i + 2] - sky[2]) > 12) cloud++;
      }
    }
    const mean = sum / n;
    recordTiming({ test: 'marched and rasterised slices (cumulus, 1280×800)', backend: 'webgpu', marched_full_quality_s: marched.seconds, rasterised_full_quality_s: rasterised.seconds, mean_difference: mean, pixels_over_6: far });
    console.log(`# webgpu ${JSON.stringify({ marched_s: marched.seconds, rasterised_s: rasterised.seconds, quality: marched.quality, mean, far })}`);
    assert.ok(mean < 0.5, `marched and rasterised differ by ${mean.toFixed(3)} on average`);
    assert.ok(far < 0.001 * vw * vh, `${far} pixels differ by more than 6`);
    assert.ok(cloud > 0.1 * right * (vh - 90), `the cloud covers ${cloud} px`);
  } finally {
    await close();
  }
});

test('the WebGL2 build rasterises the slices even when asked to march them (webgl2)', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: false });
  try {
    const asked = await shot(browser, '?preset=cumulus&slices=march', 'slices-asked-webgl2');
    assert.equal(asked.slices, 'rasterised', 'no compute in WebGL2');
  } finally {
    await close();
  }
});
