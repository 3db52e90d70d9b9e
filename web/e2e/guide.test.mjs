// The guide image in the browser: loaded through the file input (the Load… button's picker)
// and by drag & drop onto the view, shown as a semi-transparent underlay; a broken file gives
// a clear message and keeps the current guide. Screenshots: test-results/screenshots/guide-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { PNG } from 'pngjs';
import { serve, launch, openApp, waitForBody, state, screenshot, until } from './harness.mjs';

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
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});
