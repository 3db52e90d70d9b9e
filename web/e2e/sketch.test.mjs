// Sketching in the browser (WebGPU): drawing an outline with pointer events makes a cloud
// where it was drawn and a drawing plane in the list; a cut stroke flattens its base; undo
// removes it; Move and Rotate drag a plane; Ctrl+D duplicates and Delete removes it.
// Screenshots: web/test-results/screenshots/sketch-*.png.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, launch, openApp, waitForBody, waitForFullQuality, state, screenshot, countDiffering, countChanged, until, withApp, recordTiming, reveal, BOTH_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const toBytes = (rgb) => rgb.map((v) => Math.round(v * 255));

async function stroke(page, points) {
  await page.mouse.move(points[0][0], points[0][1]);
  await page.mouse.down();
  for (const [x, y] of points.slice(1)) await page.mouse.move(x, y);
  await page.mouse.up();
}

test('draw an outline, then cut its base', { timeout: 300_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors, log } = await openApp(browser, server.url, '?preset=empty');
    try {
      await waitForBody(page, 'data-ready', (v) => v === 'true');
      let s = await state(page);
      const [vw, vh] = s.view.viewport;
      const bg = toBytes(s.scene.light.background);
      // Focus the canvas, pick the Sketch tool with its shortcut.
      await page.mouse.click(vw * 0.1, vh * 0.9);
      await page.keyboard.press('d');
      await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');

      // A cumulus outline: flat base, bumpy top, centred in the viewport.
      const cx = vw * 0.5, base = vh * 0.62, w = vw * 0.42, h = vh * 0.36;
      const pts = [];
      for (let i = 0; i <= 30; i++) pts.push([cx - w / 2 + (w * i) / 30, base]);
      for (let i = 1; i < 60; i++) {
        const a = (i / 60) * Math.PI;
        const bump = 1 + 0.12 * Math.abs(Math.sin(a * 5));
        pts.push([cx + (w / 2) * Math.cos(a), base - h * Math.sin(a) * bump]);
      }
      pts.push(pts[0]);
      await stroke(page, pts);
      s = await until(page, (s) => s.scene.planes.length === 1, 'a drawing plane');
      assert.equal(s.scene.planes[0].name, 'Outline 1');
      assert.equal(s.view.selected_plane, 0, 'the new plane is selected in the list');
      await page.keyboard.press('h'); // hide guides: look at the cloud alone
      await until(page, (s) => s.view.guides_hidden, 'guides hidden');
      await waitForFullQuality(page);
      const drawn = await screenshot(page, 'sketch-1-outline');

      const box = { x: Math.round(cx - w / 2), y: Math.round(base - h), w: Math.round(w), h: Math.round(h) };
      const inside = countDiffering(drawn, box, bg);
      assert.ok(inside > 0.35 * box.w * box.h, `cloud fills ${inside} of ${box.w * box.h} px of the drawn box`);
      // Nothing far from the stroke: the strips left and right of it.
      const left = { x: 2, y: box.y, w: Math.round(box.x * 0.5), h: box.h };
      const right = { x: Math.round(box.x + box.w + (vw - box.x - box.w) * 0.5), y: box.y, w: Math.round((vw - box.x - box.w) * 0.45), h: box.h };
      assert.equal(countDiffering(drawn, left, bg), 0, 'cloud left of the stroke');
      assert.equal(countDiffering(drawn, right, bg), 0, 'cloud right of the stroke');

      // A new outline has billows (a new user's first cloud looks like a cloud). The plane's
      // "billow levels" slider, pressed at its left end, smooths it in one undo step and the
      // cloud changes; Ctrl+Z brings the billows back.
      assert.equal(s.scene.planes[0].billows?.levels, 3, 'a new outline has billows');
      const undoBefore = (await state(page)).view.undo;
      const levels = await reveal(page, 'param:billow levels');
      await page.mouse.click(levels[0] + 1, levels[1] + levels[3] / 2);
      s = await until(page, (s) => !s.scene.planes[0].billows, 'billows off');
      assert.equal(s.view.undo, undoBefore + 1, 'one undo step');
      await page.mouse.move(vw * 0.05, vh * 0.95);
      await waitForFullQuality(page);
      const smooth = await screenshot(page, 'sketch-1a-no-billows');
      const moved = countChanged(drawn, smooth, box);
      assert.ok(moved > 0.03 * box.w * box.h, `billows off changed ${moved} px of the cloud's box`);
      await page.keyboard.press('Control+z');
      await until(page, (s) => s.scene.planes[0].billows?.levels === 3, 'billows back');
      await waitForFullQuality(page);

      // K shows the selected outline's skeleton (yellow lines) and spheres (Figure 4 of the
      // paper) over the cloud; K again hides them.
      const frames = (n) => page.evaluate((n) => new Promise((r) => {
        const tick = () => (--n ? requestAnimationFrame(tick) : r());
        requestAnimationFrame(tick);
      }), n);
      const yellow = (img) => box.w * box.h - countDiffering(img, box, [255, 220, 60], 40);
      await page.keyboard.press('h');
      await until(page, (s) => !s.view.guides_hidden, 'guides shown');
      await frames(3);
      const plain = yellow(await screenshot(page, 'sketch-1b-guides'));
      await page.keyboard.press('k');
      await until(page, (s) => s.view.skeleton_shown, 'skeleton shown');
      await frames(3);
      const withSkeleton = yellow(await screenshot(page, 'sketch-1c-skeleton'));
      assert.ok(withSkeleton > plain + 200, `skeleton pixels: ${plain} → ${withSkeleton}`);
      await page.keyboard.press('k');
      await page.keyboard.press('h');
      await until(page, (s) => !s.view.skeleton_shown && s.view.guides_hidden, 'skeleton and guides hidden');

      // Cut: a horizontal line through the lower part of the cloud, wider than it.
      const cutY = base - h * 0.35;
      const lower = { x: box.x, y: Math.round(cutY + 6), w: box.w, h: Math.round(base - cutY - 6) };
      const upper = { x: box.x, y: box.y, w: box.w, h: Math.round(cutY - 6 - box.y) };
      const lowerBefore = countDiffering(drawn, lower, bg);
      const upperBefore = countDiffering(drawn, upper, bg);
      assert.ok(lowerBefore > 0.3 * lower.w * lower.h, `cloud below the cut line before cutting: ${lowerBefore}`);
      await page.keyboard.press('c');
      await until(page, (s) => s.view.tool === 'cut', 'cut tool');
      const cut = [];
      for (let i = 0; i <= 20; i++) cut.push([cx - w * 0.7 + (w * 1.4 * i) / 20, cutY]);
      await stroke(page, cut);
      s = await until(page, (s) => s.scene.planes.length === 2, 'a cut plane');
      assert.equal(s.scene.planes[1].kind, 'cut');
      await waitForFullQuality(page);
      const flattened = await screenshot(page, 'sketch-2-cut');
      const lowerAfter = countDiffering(flattened, lower, bg);
      const upperAfter = countDiffering(flattened, upper, bg);
      // The default view looks 8° down, so the cut's plane stands vertical and the base it
      // makes is level in the world: seen from a little above, the near underside of the base
      // still shows a sliver below the line (measured 14%; a cut that did nothing leaves 100%).
      assert.ok(lowerAfter < 0.25 * lowerBefore, `below the cut: ${lowerBefore} → ${lowerAfter} px`);
      assert.ok(upperAfter > 0.7 * upperBefore, `above the cut: ${upperBefore} → ${upperAfter} px`);

      // Undo removes the cut.
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => s.scene.planes.length === 1, 'undo of the cut');
      // Move tool: click the cloud to select its plane, drag it right; one undo step.
      await page.keyboard.press('Shift+G');
      await until(page, (s) => s.view.tool === 'move', 'move tool');
      await page.mouse.click(cx, base - h * 0.4);
      s = await until(page, (s) => s.view.selected_plane === 0, 'the plane selected by a click');
      const before = { x: s.scene.planes[0].origin[0], undo: s.view.undo };
      await stroke(page, Array.from({ length: 8 }, (_, i) => [cx + i * 10, base - h * 0.4]));
      s = await until(page, (s) => s.scene.planes[0].origin[0] > before.x + 0.5, 'the plane moved right');
      assert.equal(s.view.undo, before.undo + 1, 'one drag, one undo step');
      await page.keyboard.press('Control+z');
      await until(page, (s) => Math.abs(s.scene.planes[0].origin[0] - before.x) < 1e-6, 'move undone');

      // Rotate tool: a sideways drag turns the selected plane; duplicate and delete by shortcut.
      await page.keyboard.press('Shift+R');
      await until(page, (s) => s.view.tool === 'rotate', 'rotate tool');
      const rot0 = JSON.stringify(s.scene.planes[0].rotation);
      await stroke(page, Array.from({ length: 8 }, (_, i) => [cx + i * 10, base - h * 0.4]));
      s = await until(page, (s) => JSON.stringify(s.scene.planes[0].rotation) !== rot0, 'the plane rotated');
      // Z locks the turn to world Z and Ctrl snaps it to 15°: right 160 px and up 60 px make
      // 44°, snapped to 45° (free and unsnapped, the same drag turns 32° about Y and 12° about X).
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => JSON.stringify(s.scene.planes[0].rotation) === rot0, 'the turn undone');
      await page.keyboard.press('z');
      await page.keyboard.down('Control');
      await stroke(page, Array.from({ length: 21 }, (_, i) => [cx + i * 8, base - h * 0.4 - i * 3]));
      await page.keyboard.up('Control');
      await until(page, (s) => JSON.stringify(s.scene.planes[0].rotation) !== rot0, 'the locked, snapped turn');
      // The whole drag is in once a few more frames have run.
      await page.evaluate(() => new Promise((r) => {
        let n = 4;
        const tick = () => (--n ? requestAnimationFrame(tick) : r());
        requestAnimationFrame(tick);
      }));
      s = await state(page);
      const [x0, y0, z0, w0] = JSON.parse(rot0);
      const [x1, y1, z1, w1] = s.scene.planes[0].rotation;
      // rel = q1 · conj(q0): the turn the drag applied, in world axes.
      const rel = [
        -w1 * x0 + x1 * w0 - y1 * z0 + z1 * y0,
        -w1 * y0 + y1 * w0 - z1 * x0 + x1 * z0,
        -w1 * z0 + z1 * w0 - x1 * y0 + y1 * x0,
        w1 * w0 + x1 * x0 + y1 * y0 + z1 * z0,
      ];
      const sign = Math.sign(rel[3]) || 1;
      const deg = (2 * Math.acos(Math.min(1, Math.abs(rel[3]))) * 180) / Math.PI;
      assert.ok(Math.abs(rel[0]) < 1e-4 && Math.abs(rel[1]) < 1e-4, `a turn about Z only: ${rel}`);
      assert.ok(Math.abs(deg - 45) < 0.01 && sign * rel[2] > 0, `snapped to 45°: ${deg}°`);
      await page.keyboard.press('Control+d');
      s = await until(page, (s) => s.scene.planes.length === 2, 'a duplicate');
      assert.equal(s.scene.planes[1].name, 'Outline 1 copy');
      assert.equal(s.view.selected_plane, 1);
      await page.keyboard.press('Delete');
      s = await until(page, (s) => s.scene.planes.length === 1, 'the duplicate deleted');

      // A degenerate stroke (a straight line, no inside) is refused with a message, changes nothing.
      await page.keyboard.press('d');
      await stroke(page, Array.from({ length: 10 }, (_, i) => [vw * 0.15 + i * 12, vh * 0.15 + i * 4]));
      s = await until(page, (s) => s.view.notice && s.view.notice.error, 'a refusal message', 20_000);
      assert.equal(s.scene.planes.length, 1);
      assert.deepEqual(errors, [], `errors logged:\n${errors.join('\n')}`);
    } catch (e) {
      console.error(log.slice(-40).join('\n'));
      await screenshot(page, 'sketch-failure').catch(() => {});
      throw e;
    }
  } finally {
    await close();
  }
});

test('touch: one finger sketches, two fingers orbit', { timeout: 240_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty', { width: 900, height: 560 }, { hasTouch: true });
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    let s = await state(page);
    const [vw, vh] = s.view.viewport;
    const cdp = await page.context().newCDPSession(page);
    const touch = (type, points) => cdp.send('Input.dispatchTouchEvent', {
      type, touchPoints: points.map(([x, y], id) => ({ x, y, id, radiusX: 2, radiusY: 2, force: 1 })),
    });
    await page.keyboard.press('d');
    await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
    // One finger: an outline (an ellipse with a flat base).
    const cx = vw * 0.5, cy = vh * 0.5;
    const pts = [];
    for (let i = 0; i <= 48; i++) {
      const a = (i / 48) * 2 * Math.PI;
      pts.push([cx + vw * 0.2 * Math.cos(a), cy + Math.min(vh * 0.18 * Math.sin(a), vh * 0.08)]);
    }
    await touch('touchStart', [pts[0]]);
    for (const p of pts.slice(1)) { await touch('touchMove', [p]); }
    await touch('touchEnd', []);
    s = await until(page, (s) => s.scene.planes.length === 1, 'a plane drawn with one finger');
    const yaw = s.scene.camera.yaw_deg;
    // Two fingers moving together orbit, even in the Sketch tool, and draw nothing.
    let a = [cx - 40, cy], b = [cx + 40, cy];
    await touch('touchStart', [a, b]);
    for (let i = 1; i <= 10; i++) {
      a = [a[0] + 12, a[1]]; b = [b[0] + 12, b[1]];
      await touch('touchMove', [a, b]);
    }
    await touch('touchEnd', []);
    s = await until(page, (s) => Math.abs(s.scene.camera.yaw_deg - yaw) > 5, 'a two-finger orbit');
    assert.equal(s.scene.planes.length, 1, 'two fingers drew no stroke');
    await screenshot(page, 'sketch-touch');
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

/** In the open app: focus the view, pick the Sketch tool; returns the view's size. */
async function startSketching(page) {
  const [vw, vh] = (await state(page)).view.viewport;
  await page.mouse.click(vw * 0.05, vh * 0.95);
  await page.keyboard.press('d');
  await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
  return [vw, vh];
}

/** A closed circle of 41 screen points. */
const loop = (x, y, r) => Array.from({ length: 41 }, (_, i) => {
  const a = (i / 40) * 2 * Math.PI;
  return [x + r * Math.cos(a), y + r * Math.sin(a)];
});

test('a stroke that starts over the cloud lands on a plane through its surface', { timeout: 240_000 }, async () => {
  await withApp({ base: server.url, webgpu: true }, async (page) => {
    const [vw, vh] = await startSketching(page);
    // Starts at the view's centre, over the default cumulus; then one over the empty sky.
    const over = loop(vw * 0.5, vh * 0.5, vh * 0.08).map(([x, y]) => [x - vh * 0.08, y]);
    await stroke(page, [[vw * 0.5, vh * 0.5], ...over.slice(1)]);
    await until(page, (s) => s.scene.planes.length === 1, 'the plane over the cloud');
    await stroke(page, loop(vw * 0.12, vh * 0.12, vh * 0.06));
    const s = await until(page, (s) => s.scene.planes.length === 2, 'the plane over the sky');
    const t = s.scene.camera.target;
    // Depth of each plane along its normal (toward the camera), from the orbit target.
    const depth = (p) => {
      const [x, y, z, w] = p.rotation;
      // The plane's z axis: the rotation applied to (0, 0, 1).
      const n = [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)];
      return p.origin.reduce((acc, o, i) => acc + (o - t[i]) * n[i], 0);
    };
    const [onCloud, onSky] = s.scene.planes.map(depth);
    assert.ok(Math.abs(onSky) < 1e-3, `a stroke over the sky lies on the target's plane: ${onSky}`);
    assert.ok(onCloud > 0.5, `a stroke over the cloud lies on its surface, in front of the target: ${onCloud}`);
  });
});

test('a pen stroke stores its pressure per point; a mouse stroke stores none', { timeout: 240_000 }, async () => {
  await withApp({ base: server.url, webgpu: true, query: '?preset=empty' }, async (page) => {
    const [vw, vh] = await startSketching(page);
    // A pen through the DevTools protocol (real input events, pointerType "pen"), pressure
    // rising from 0.2 to 0.9 around a circle, sent without waiting for frames.
    const cdp = await page.context().newCDPSession(page);
    const n = 60;
    const at = (i) => {
      const a = (i / n) * 2 * Math.PI;
      return { x: vw * 0.35 + vh * 0.15 * Math.cos(a), y: vh * 0.5 + vh * 0.15 * Math.sin(a), force: 0.2 + (0.7 * i) / n };
    };
    const pen = { pointerType: 'pen', button: 'left', buttons: 1 };
    await cdp.send('Input.dispatchMouseEvent', { type: 'mouseMoved', ...at(0), pointerType: 'pen', buttons: 0 });
    await cdp.send('Input.dispatchMouseEvent', { type: 'mousePressed', ...at(0), ...pen, clickCount: 1 });
    for (let i = 1; i <= n; i++) await cdp.send('Input.dispatchMouseEvent', { type: 'mouseMoved', ...at(i), ...pen });
    await cdp.send('Input.dispatchMouseEvent', { type: 'mouseReleased', ...at(n), ...pen, buttons: 0, clickCount: 1 });
    let s = await until(page, (s) => s.scene.planes.length === 1, 'the pen stroke');
    const { points, pressure } = s.scene.planes[0];
    assert.ok(Array.isArray(pressure) && pressure.length === points.length, `${pressure?.length} pressures for ${points.length} points`);
    // The press and every move: all n + 1 samples.
    assert.equal(points.length, n + 1, `${points.length} of ${n + 1} samples`);
    assert.ok(Math.min(...pressure) < 0.3 && Math.max(...pressure) > 0.8, `pressure ${Math.min(...pressure)}–${Math.max(...pressure)}`);
    // The mouse: no pressure stored.
    await stroke(page, loop(vw * 0.7, vh * 0.5, vh * 0.1));
    s = await until(page, (s) => s.scene.planes.length === 2, 'the mouse stroke');
    assert.equal(s.scene.planes[1].pressure, undefined);
  });
});

for (const backend of BOTH_BUILDS) {
  test(`sketching, and the deflate slider changing the image (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: { width: 1280, height: 800 } }, async (page) => {
      const [vw, vh] = await startSketching(page);
      // A fat body with a thin arm: deflating thins the body toward the arm's width.
      const cx = vw * 0.4, cy = vh * 0.5, r = vh * 0.2;
      const pts = [];
      for (let i = 0; i <= 40; i++) {
        const a = (i / 40) * 2 * Math.PI;
        pts.push([cx + r * Math.cos(a), cy + r * Math.sin(a)]);
        if (i === 0) pts.push([cx + r * 2.2, cy - 6], [cx + r * 2.2, cy + 6], [cx + r * 0.99, cy + 8]);
      }
      await stroke(page, pts);
      const t0 = Date.now();
      await until(page, (s) => s.scene.planes.length === 1, 'the outline');
      await page.keyboard.press('h');
      await until(page, (s) => s.view.guides_hidden, 'guides hidden');
      const { seconds } = await waitForFullQuality(page);
      const strokeToFull = (Date.now() - t0) / 1000;
      const before = await screenshot(page, `sketch-deflate-0-${backend}`);
      const box = { x: Math.round(cx - r * 1.2), y: Math.round(cy - r * 1.2), w: Math.round(r * 2.4), h: Math.round(r * 2.4) };
      await page.evaluate(() => window.cloudsketch.set('/planes/0/sketch/inflate=1'));
      await until(page, (s) => s.scene.planes[0].sketch.inflate === 1, 'deflated');
      await waitForFullQuality(page);
      const after = await screenshot(page, `sketch-deflate-1-${backend}`);
      const changed = countChanged(before, after, box);
      assert.ok(changed > 0.1 * box.w * box.h, `deflating changed ${changed} of ${box.w * box.h} px of the body`);
      recordTiming({ test: 'stroke-to-full', backend, viewport: [vw, vh], strokeToFullSeconds: strokeToFull, lastWaitSeconds: seconds });
    });
  });
}
