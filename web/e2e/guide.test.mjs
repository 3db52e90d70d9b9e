// The reference image in the browser: loaded through the file input (the Load… button's
// picker) and by drag & drop onto the view, placed in the scene facing the view (it turns with
// the scene when the view orbits), under or over the cloud, undoable; a broken file gives a
// clear message and keeps the current picture. Screenshots: test-results/screenshots/guide-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { PNG } from 'pngjs';
import { serve, launch, openApp, waitForBody, state, screenshot, until, withApp, BOTH_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

function solidPng(w, h, [r, g, b]) {
  const png = new PNG({ width: w, height: h });
  for (let i = 0; i < w * h; i++) png.data.set([r, g, b, 255], i * 4);
  return PNG.sync.write(png);
}

async function drop(page, name, bytes) {
  const [vw, vh] = (await state(page)).view.viewport;
  await page.evaluate(({ name, data, x, y }) => {
    const file = new File([new Uint8Array(data)], name, { type: 'image/png' });
    const dt = new DataTransfer();
    dt.items.add(file);
    const canvas = document.getElementById('cloudsketch_canvas');
    for (const type of ['dragenter', 'dragover', 'drop']) {
      canvas.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true, clientX: x, clientY: y }));
    }
  }, { name, data: [...bytes], x: vw / 2, y: vh / 2 });
}

const centre = (img, [vw, vh]) => {
  const i = 4 * (Math.round(vh / 2) * img.width + Math.round(vw / 2));
  return [img.data[i], img.data[i + 1], img.data[i + 2]];
};

test('guide image from the file picker and from drag & drop', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty');
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    const viewport = (await state(page)).view.viewport;

    const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cloudsketch-guide-'));
    const red = path.join(dir, 'red.png');
    fs.writeFileSync(red, solidPng(64, 48, [255, 0, 0]));
    await page.setInputFiles('#guide_input', red);
    let s = await until(page, (s) => s.view.guide_image?.name === 'red.png', 'the picked guide');
    assert.deepEqual(s.view.guide_image.size, [64, 48]);
    await page.waitForTimeout(300);
    const [r1, g1, b1] = centre(await screenshot(page, 'guide-1-picked'), viewport);
    assert.ok(r1 > 140 && b1 < 190 && r1 > g1 + 60, `red underlay at the centre: ${[r1, g1, b1]}`);

    await drop(page, 'green.png', solidPng(32, 32, [0, 255, 0]));
    s = await until(page, (s) => s.view.guide_image?.name === 'green.png', 'the dropped guide');
    await page.waitForTimeout(300);
    const [r2, g2] = centre(await screenshot(page, 'guide-2-dropped'), viewport);
    assert.ok(g2 > r2 + 60, `green underlay at the centre: ${[r2, g2]}`);

    await drop(page, 'broken.png', Buffer.from('definitely not a png'));
    s = await until(page, (s) => s.view.guide_error, 'an error for a broken file');
    assert.equal(s.view.guide_image.name, 'green.png', 'a broken file keeps the current guide');
    assert.equal(s.view.guide_image.embedded, true, 'a small file is saved in the document');
    // Loading a picture is an edit: Ctrl+Z brings the previous one back.
    await page.mouse.click(viewport[0] * 0.5, viewport[1] * 0.9);
    await page.keyboard.press('Control+z');
    await until(page, (s) => s.view.guide_image?.name === 'red.png', 'undo of the second picture');
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

/** Pixels of the view where red clearly dominates. */
function reddish(img, [vw, vh]) {
  let n = 0;
  for (let y = 0; y < vh; y++) {
    for (let x = 0; x < vw; x++) {
      const i = 4 * (y * img.width + x);
      const [r, g, b] = [img.data[i], img.data[i + 1], img.data[i + 2]];
      if (r > g + 60 && r > b + 30) n++;
    }
  }
  return n;
}

for (const backend of BOTH_BUILDS) {
  test(`the reference image stays in the scene when orbiting, under or over the cloud (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', viewport: { width: 1280, height: 800 } }, async (page) => {
      const view = (await state(page)).view.viewport;
      const [vw, vh] = view;
      const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cloudsketch-reference-'));
      const red = path.join(dir, 'red.png');
      fs.writeFileSync(red, solidPng(64, 48, [255, 0, 0]));
      await page.setInputFiles('#guide_input', red);
      await until(page, (s) => s.view.guide_image?.name === 'red.png', 'the picture');
      await page.waitForTimeout(500);
      const facing = reddish(await screenshot(page, `guide-3-facing-${backend}`), view);
      assert.ok(facing > 0.05 * vw * vh, `the picture shows: ${facing} px`);
      // Orbit sideways: a picture glued to the screen would not change; one in the scene turns
      // away from the camera and narrows.
      await page.mouse.click(vw * 0.5, vh * 0.95);
      await page.keyboard.press('v');
      await page.mouse.move(vw * 0.3, vh * 0.5);
      await page.mouse.down();
      for (let i = 1; i <= 10; i++) await page.mouse.move(vw * 0.3 + i * 15, vh * 0.5);
      await page.mouse.up();
      await page.waitForTimeout(800);
      const turned = reddish(await screenshot(page, `guide-4-orbited-${backend}`), view);
      assert.ok(turned < 0.85 * facing && turned > 0.1 * facing, `after the orbit: ${facing} → ${turned} px`);
      // Over the cloud, the picture shows where the cloud hid it.
      await page.evaluate(() => window.cloudsketch.set('/reference/in_front=true'));
      await until(page, (s) => s.view.guide_image.in_front, 'over the cloud');
      await page.waitForTimeout(500);
      const over = reddish(await screenshot(page, `guide-5-over-${backend}`), view);
      assert.ok(over > 1.1 * turned, `under the cloud ${turned} px, over it ${over} px`);
      const s = await state(page);
      assert.equal(s.scene.reference.in_front, true);
      assert.equal(s.scene.reference.data, '', 'the page state leaves the bytes out');
    });
  });
}
