// Scenes leave the page and come back, as a user moves them: a sketch survives a reload; Copy
// link (Ctrl+L) puts a URL on the clipboard that opens the same scene in another page; Save
// (Ctrl+S) downloads a file that Open (Ctrl+O) and a drop bring back in a fresh browser, each
// an undoable step; a broken link, pasted into the address bar or opened cold, shows a message
// and leaves the autosaved session as it was.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import { serve, launch, openApp, waitForBody, state, until, watchFileChoosers } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const CLIPBOARD = { permissions: ['clipboard-read', 'clipboard-write'] };
const VIEW = { width: 1280, height: 800 };

/** A lumpy closed loop of `n` screen points around (cx, cy). */
const lumpy = (cx, cy, r, n) => Array.from({ length: n + 1 }, (_, i) => {
  const a = (i / n) * 2 * Math.PI;
  const rr = r * (1 + 0.15 * Math.sin(a * 5));
  return [cx + rr * Math.cos(a) * 1.4, cy - rr * Math.sin(a)];
});

/** Draws with the Sketch tool (e2e/input.test.mjs checks input at real rates). */
async function sketch(page, pts) {
  const [vw, vh] = (await state(page)).view.viewport;
  await page.mouse.click(vw * 0.05, vh * 0.95);
  await page.keyboard.press('d');
  await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
  await page.mouse.move(pts[0][0], pts[0][1]);
  await page.mouse.down();
  for (const [x, y] of pts.slice(1)) await page.mouse.move(x, y);
  await page.mouse.up();
}

/** Each plane's stroke, exactly, and where it stands, to 4 digits (a link keeps 5). */
const strokes = (s) => s.scene.planes.map((p) => JSON.stringify([
  [...p.origin, ...p.rotation].map((v) => Number(v.toPrecision(4))), p.points]));
const autosaved = (page) => page.evaluate(() => JSON.parse(localStorage.getItem('cloudsketch.autosave') ?? 'null'));

test('reload, Copy link, Save and Open, a broken link (webgpu)', { timeout: 300_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty', VIEW, CLIPBOARD);
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    const [vw, vh] = (await state(page)).view.viewport;
    await sketch(page, lumpy(vw * 0.45, vh * 0.5, vh * 0.18, 120));
    let s = await until(page, (s) => s.scene.planes.length === 1, 'the stroke became a plane');
    const drawn = strokes(s);
    assert.ok(s.view.unsaved, 'a new stroke is an unsaved change');
    await page.waitForFunction(() => JSON.parse(localStorage.getItem('cloudsketch.autosave') ?? '{}').planes?.length === 1,
      null, { timeout: 10_000, polling: 100 });

    // A reload continues the session.
    await page.reload();
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    s = await state(page);
    assert.deepEqual(strokes(s), drawn, 'the sketch survived the reload');

    // Copy link: the URL on the clipboard opens the same scene in another page.
    await page.mouse.click(vw * 0.05, vh * 0.95);
    await page.keyboard.press('Control+l');
    s = await until(page, (s) => s.view.link != null, 'a link');
    assert.match(s.view.notice.text, /Link copied: \d+ characters/);
    const clipboard = await page.evaluate(() => navigator.clipboard.readText());
    assert.equal(clipboard, s.view.link);
    assert.ok(clipboard.startsWith(`${server.url.replace(/\?.*$/, '')}#s=`), clipboard);
    const other = await browser.newPage({ viewport: VIEW });
    await other.goto(clipboard);
    await waitForBody(other, 'data-ready', (v) => v === 'true');
    const opened = await state(other);
    assert.deepEqual(strokes(opened), drawn, 'the link holds the stroke exactly');
    assert.deepEqual(opened.scene.render, s.scene.render);
    assert.match(opened.view.notice.text, /Opened the scene from the link/);
    assert.equal(await other.evaluate(() => location.hash), '', 'the link left the address bar');
    await other.close();

    // Save: Ctrl+S downloads the scene; the marker clears.
    const [download] = await Promise.all([page.waitForEvent('download'), page.keyboard.press('Control+s')]);
    assert.equal(download.suggestedFilename(), 'untitled.json');
    const saved = fs.readFileSync(await download.path(), 'utf8');
    assert.equal(JSON.parse(saved).planes.length, 1);
    s = await until(page, (s) => !s.view.unsaved, 'saved');

    // A broken link pasted into the address bar: a message, the scene untouched.
    await page.goto(`${server.url}#s=AXsomething-cut-short`);
    s = await until(page, (s) => s.view.notice?.error, 'the broken link refused');
    assert.match(s.view.notice.text, /damaged/);
    assert.deepEqual(strokes(s), drawn);
    // Opened cold, too: the last session continues and the autosave is not written over.
    await page.goto(`${server.url}?cold#s=AXsomething-cut-short`);
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    s = await state(page);
    assert.ok(s.view.notice.error && /damaged/.test(s.view.notice.text), s.view.notice.text);
    assert.deepEqual(strokes(s), drawn, 'the autosaved session is open');
    await page.waitForTimeout(1500);
    assert.equal((await autosaved(page)).planes.length, 1);
    assert.deepEqual(errors, []);

    // Open the saved file in a fresh browser: Ctrl+O's picker, then a drop; each undoable.
    const fresh = await launch({ webgpu: true });
    try {
      const { page: p2, errors: e2 } = await openApp(fresh.browser, server.url, '?preset=stratus', VIEW);
      const choosers = watchFileChoosers(p2);
      await waitForBody(p2, 'data-ready', (v) => v === 'true');
      await p2.mouse.click(vw * 0.05, vh * 0.95);
      await p2.keyboard.press('Control+o');
      const chooser = await choosers.next();
      await chooser.setFiles({ name: 'untitled.json', mimeType: 'application/json', buffer: Buffer.from(saved) });
      let t = await until(p2, (s) => s.scene.planes.length === 1, 'the file opened');
      assert.deepEqual(strokes(t), drawn, 'Open brings the same scene');
      assert.ok(!t.view.unsaved);
      await p2.keyboard.press('Control+z');
      t = await until(p2, (s) => s.scene.planes.length === 0 && s.scene.ellipsoids.length > 20, 'undo the open');
      await p2.evaluate(({ text, x, y }) => {
        const dt = new DataTransfer();
        dt.items.add(new File([text], 'dropped.json', { type: 'application/json' }));
        const canvas = document.getElementById('cloudsketch_canvas');
        for (const type of ['dragenter', 'dragover', 'drop']) {
          canvas.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true, clientX: x, clientY: y }));
        }
      }, { text: saved, x: vw / 2, y: vh / 2 });
      t = await until(p2, (s) => s.scene.planes.length === 1, 'the dropped file opened');
      assert.equal(t.view.file, 'dropped.json', 'Save now writes the dropped file\'s name');
      assert.deepEqual(strokes(t), drawn);
      // A broken file: a message, nothing changes.
      await p2.setInputFiles('#scene_input', { name: 'broken.json', mimeType: 'application/json', buffer: Buffer.from(saved.slice(0, 200)) });
      t = await until(p2, (s) => s.view.notice?.error, 'the broken file refused');
      assert.match(t.view.notice.text, /Nothing opened: broken\.json/);
      assert.deepEqual(strokes(t), drawn);
      assert.deepEqual(e2, []);
    } finally {
      await fresh.close();
    }
  } finally {
    await close();
  }
});

test('a link opens on WebGL2 too', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: false });
  try {
    // The stratus preset's link, made by the page itself on a first visit.
    const { page, errors } = await openApp(browser, server.url, '?preset=stratus', VIEW, CLIPBOARD);
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    assert.equal((await state(page)).view.backend, 'webgl2');
    // The File group's "Copy link" button, at the top of the side panel (300 px wide, at the
    // right edge): its third button in the row under the file name.
    await page.mouse.click(VIEW.width - 137, 59);
    const { view } = await until(page, (s) => s.view.link != null, 'a link from the Copy link button');
    assert.equal(await page.evaluate(() => navigator.clipboard.readText()), view.link);
    const { page: other } = await openApp(browser, view.link, '', VIEW);
    await waitForBody(other, 'data-ready', (v) => v === 'true');
    const s = await state(other);
    const stratus = await state(page);
    assert.equal(s.scene.ellipsoids.length, stratus.scene.ellipsoids.length);
    assert.equal(s.scene.render.noise_filter, stratus.scene.render.noise_filter);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

test('an edit that takes the billows over their cap says so once, and undo takes it back', { timeout: 240_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty', VIEW);
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    // 300 ellipsoids with 4 levels of billows on a coarse field grid: its texels are too big
    // for the finest puffs, so the document stays under the cap of puffs.
    const doc = (await state(page)).scene;
    let seed = 9;
    const u = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
    doc.render.field_resolution = 48;
    doc.ellipsoids = Array.from({ length: 300 }, () => ({
      center: [u() * 60, u() * 10, u() * 60], radii: Array(3).fill(2 + u() * 2), rotation: [0, 0, 0, 1],
      strength: 1, hidden: false, billows: { levels: 4, ratio: 0.3, coverage: 1 },
    }));
    await page.setInputFiles('#scene_input', { name: 'puffy.json', mimeType: 'application/json', buffer: Buffer.from(JSON.stringify(doc)) });
    let s = await until(page, (s) => s.scene.ellipsoids.length === 300, 'the file opened', 120_000);
    assert.equal(s.view.puffs_left_out, 0, 'under the cap on the coarse grid');
    assert.doesNotMatch(s.view.notice?.text ?? '', /puffs over the cap/);
    // A finer grid grows finer puffs, over the cap: the finest level goes, and a notice says so.
    await page.evaluate(() => window.cloudsketch.set('/render/field_resolution=128'));
    s = await until(page, (s) => s.view.puffs_left_out > 0, 'over the cap', 120_000);
    assert.match(s.view.notice.text, /^Billows: the finest level of puffs is left out \(\d+ puffs over the cap of 16000\)/);
    assert.ok(!s.view.notice.error, 'a note, not a refusal: the edit is kept');
    assert.equal(s.scene.render.field_resolution, 128);
    await page.mouse.click(VIEW.width * 0.05, VIEW.height * 0.95);
    await page.keyboard.press('Control+z');
    s = await until(page, (s) => s.scene.render.field_resolution === 48 && s.view.puffs_left_out === 0, 'undone', 120_000);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});
