// Nothing in the way, in the browser at 1280×800 (both builds), driven as a person drives it:
// Blender's modal G (X, a typed distance, Enter; then Esc putting it back exactly), R cancelled
// by a right-click, S confirmed by a click; an outline drawn with "behind" (Q) lands beyond the
// first and one drawn without lands in front; a plane drawn from the level default view stands
// upright; the Tiers group stays open after "Add a tier".
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, state, until, withApp, reveal, openGroup, screenshot, BOTH_BUILDS } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const VIEWPORT = { width: 1280, height: 800 };

/** Presses, moves through `points` without waiting for frames (pointer events come faster
 * than frames), releases. */
async function stroke(page, points) {
  await page.mouse.move(points[0][0], points[0][1]);
  await page.mouse.down();
  for (const [x, y] of points.slice(1)) await page.mouse.move(x, y);
  await page.mouse.up();
}

/** A closed, bumpy outline centred at (cx, cy), w by h pixels. */
function outline(cx, cy, w, h) {
  const pts = [];
  for (let i = 0; i <= 20; i++) pts.push([cx - w / 2 + (w * i) / 20, cy + h / 2]);
  for (let i = 1; i < 40; i++) {
    const a = (i / 40) * Math.PI;
    pts.push([cx + (w / 2) * Math.cos(a), cy + h / 2 - h * Math.sin(a) * (1 + 0.1 * Math.abs(Math.sin(a * 4)))]);
  }
  pts.push(pts[0]);
  return pts;
}

/** The camera's eye and unit view direction (as `OrbitCamera::eye`/`forward`). */
function eyeAndForward(c) {
  const yaw = (c.yaw_deg * Math.PI) / 180, pitch = (c.pitch_deg * Math.PI) / 180;
  const back = [Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)];
  return { eye: c.target.map((t, k) => t + back[k] * c.distance), forward: back.map((v) => -v) };
}

/** How far along the view a plane's origin lies. */
function depth(camera, plane) {
  const { eye, forward } = eyeAndForward(camera);
  return plane.origin.reduce((acc, o, k) => acc + (o - eye[k]) * forward[k], 0);
}

/** A quaternion [x, y, z, w] applied to v. */
function rotate([x, y, z, w], v) {
  const u = [x, y, z];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const t = cross(u, v).map((c) => 2 * c);
  const ut = cross(u, t);
  return v.map((vi, k) => vi + w * t[k] + ut[k]);
}

const close = (a, b, eps) => a.every((v, k) => Math.abs(v - b[k]) <= eps);

for (const backend of BOTH_BUILDS) {
  test(`modal G, R and S as in Blender (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: VIEWPORT }, async (page) => {
      let s = await state(page);
      const [vw, vh] = s.view.viewport;
      await page.mouse.click(vw * 0.05, vh * 0.95);
      // Two ellipsoids with the Ellipsoid tool; the second is selected once added.
      await page.keyboard.press('e');
      await until(page, (s) => s.view.tool === 'ellipsoid', 'ellipsoid tool');
      await page.mouse.click(vw * 0.35, vh * 0.5);
      await until(page, (s) => s.scene.ellipsoids.length === 1, 'one ellipsoid');
      await page.mouse.click(vw * 0.65, vh * 0.5);
      s = await until(page, (s) => s.scene.ellipsoids.length === 2 && s.view.selected_ellipsoid === 1, 'two, the second selected');
      await page.keyboard.press('v');
      const start = s.scene.ellipsoids.map((e) => e.center);
      const undo = s.view.undo;

      // G, the mouse moving (events faster than frames), X, "2", Enter.
      await page.mouse.move(vw * 0.6, vh * 0.5);
      await page.keyboard.press('g');
      await until(page, (s) => s.view.modal?.kind === 'grab', 'grab under way');
      for (let i = 1; i <= 12; i++) await page.mouse.move(vw * 0.6 + i * 9, vh * 0.5 - i * 4);
      await until(page, (s) => !close(s.scene.ellipsoids[1].center, start[1], 1e-4), 'the grab follows the mouse');
      await page.keyboard.press('x');
      await page.keyboard.type('2');
      s = await until(page, (s) => s.view.modal?.axis === 'X' && s.view.modal?.typed === '2', 'X locked, 2 typed');
      await screenshot(page, `modal-grab-x-2-${backend}`);
      await page.mouse.move(vw * 0.3, vh * 0.2); // the mouse no longer matters once typed
      await page.keyboard.press('Enter');
      s = await until(page, (s) => s.view.modal === null, 'Enter confirms');
      const want = [start[1][0] + 2, start[1][1], start[1][2]];
      assert.ok(close(s.scene.ellipsoids[1].center, want, 1e-5), `moved exactly 2 along X: ${s.scene.ellipsoids[1].center} vs ${want}`);
      assert.deepEqual(s.scene.ellipsoids[0].center, start[0], 'the other ellipsoid stays');
      assert.equal(s.view.undo, undo + 1, 'one undo step');
      const confirmed = s.scene.ellipsoids[1];

      // G, a move, Esc: exactly back, no undo step.
      await page.keyboard.press('g');
      await until(page, (s) => s.view.modal?.kind === 'grab', 'second grab');
      for (let i = 1; i <= 10; i++) await page.mouse.move(vw * 0.3 - i * 7, vh * 0.2 + i * 11);
      await until(page, (s) => !close(s.scene.ellipsoids[1].center, confirmed.center, 1e-4), 'moved again');
      await page.keyboard.press('Escape');
      s = await until(page, (s) => s.view.modal === null, 'Esc cancels');
      assert.deepEqual(s.scene.ellipsoids[1], confirmed, 'Esc returns exactly');
      assert.equal(s.view.undo, undo + 1, 'no undo step for the cancelled grab');
      assert.equal(s.view.selected_ellipsoid, 1, 'still selected');

      // R, a move, right-click: exactly back.
      await page.keyboard.press('r');
      await until(page, (s) => s.view.modal?.kind === 'rotate', 'rotate under way');
      for (let i = 1; i <= 10; i++) await page.mouse.move(vw * 0.3 + i * 15, vh * 0.3 + i * 9);
      await until(page, (s) => JSON.stringify(s.scene.ellipsoids[1]) !== JSON.stringify(confirmed), 'turned');
      await page.mouse.click(vw * 0.45, vh * 0.4, { button: 'right' });
      s = await until(page, (s) => s.view.modal === null, 'a right-click cancels');
      assert.deepEqual(s.scene.ellipsoids[1], confirmed, 'the right-click returns exactly');
      assert.equal(s.view.undo, undo + 1);

      // S, the mouse moving away from the pivot, a click: confirmed, one step, and the click
      // selects nothing else. The Scale tool's gizmo says where the ellipsoid is on screen.
      await page.keyboard.press('Shift+S');
      s = await until(page, (s) => s.view.tool === 'scale' && s.view.gizmo, 'the scale tool and its gizmo');
      const [gx, gy] = s.view.gizmo.center;
      await page.mouse.move(gx + 40, gy + 5);
      await page.keyboard.press('s');
      await until(page, (s) => s.view.modal?.kind === 'scale', 'scale under way');
      for (let i = 1; i <= 8; i++) await page.mouse.move(gx + 40 + i * 10, gy + 5);
      await until(page, (s) => s.scene.ellipsoids[1].radii[0] > confirmed.radii[0] * 1.5, 'grown');
      await page.mouse.click(gx + 120, gy + 5);
      s = await until(page, (s) => s.view.modal === null, 'a click confirms');
      assert.ok(s.scene.ellipsoids[1].radii[0] > confirmed.radii[0] * 1.5);
      assert.equal(s.view.undo, undo + 2, 'one more step');
      assert.deepEqual(s.view.selected_ellipsoids, [1], 'the confirming click selected nothing');
      await page.keyboard.press('v');
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => s.view.undo === undo + 1, 'undo');
      assert.deepEqual(s.scene.ellipsoids[1].radii, confirmed.radii, 'Ctrl+Z undoes the scale');

      // Nothing selected: G says what to do.
      await page.keyboard.press('Escape');
      await until(page, (s) => s.view.selected_ellipsoid === null, 'nothing selected');
      await page.keyboard.press('g');
      s = await until(page, (s) => /Select something first/.test(s.view.notice?.text ?? ''), 'the message');
      assert.equal(s.view.modal, null);
    });
  });

  test(`outlines land in front of or behind the cloud, on upright planes (${backend})`, { timeout: 240_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', query: '?preset=empty', viewport: VIEWPORT }, async (page) => {
      let s = await state(page);
      const [vw, vh] = s.view.viewport;
      await page.mouse.click(vw * 0.05, vh * 0.95);
      await page.keyboard.press('d');
      await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
      const cx = vw * 0.5, cy = vh * 0.5;
      await stroke(page, outline(cx, cy, vw * 0.4, vh * 0.35));
      s = await until(page, (s) => s.scene.planes.length === 1, 'the first outline');
      // The default view looks 8° down: within 10° of level, the plane stands upright.
      assert.ok(Math.abs(s.scene.camera.pitch_deg) <= 10, `the default view is near level: ${s.scene.camera.pitch_deg}`);
      const up = rotate(s.scene.planes[0].rotation, [0, 1, 0]);
      assert.ok(close(up, [0, 1, 0], 1e-4), `the plane's up is the world's: ${up}`);
      const camera = s.scene.camera;
      const first = depth(camera, s.scene.planes[0]);

      // A second outline over the cloud: in front of the first (Wither's rule).
      await stroke(page, outline(cx, cy, vw * 0.14, vh * 0.12));
      s = await until(page, (s) => s.scene.planes.length === 2, 'a second outline');
      const front = depth(camera, s.scene.planes[1]);
      assert.ok(front < first - 0.3, `in front: ${front} vs the first ${first}`);

      // Q: the next lands behind the cloud, beyond the first.
      await page.keyboard.press('q');
      s = await until(page, (s) => s.view.behind === true, 'behind on');
      await stroke(page, outline(cx, cy, vw * 0.14, vh * 0.12));
      s = await until(page, (s) => s.scene.planes.length === 3, 'a third outline');
      const back = depth(camera, s.scene.planes[2]);
      assert.ok(back > first + 0.3, `behind: ${back} vs the first ${first}`);
      assert.deepEqual(s.scene.camera, camera, 'the camera stayed');
    });
  });

  test(`the Tiers group stays open after "Add a tier" (${backend})`, { timeout: 180_000 }, async () => {
    await withApp({ base: server.url, webgpu: backend === 'webgpu', viewport: VIEWPORT }, async (page) => {
      await openGroup(page, 'Render');
      let s = await state(page);
      const tiers = s.scene.render.tiers.length;
      assert.equal(s.view.widgets['button:Add a tier'], undefined, 'the Tiers group starts closed');
      const header = await reveal(page, 'group:Tiers');
      await page.mouse.click(header[0] + 12, header[1] + header[3] / 2);
      await until(page, (s) => s.view.widgets['button:Add a tier'], 'the Tiers group open');
      assert.equal(tiers, 0, 'the default scene has no tiers (room for two)');
      const add = await reveal(page, 'button:Add a tier');
      await page.mouse.click(add[0] + add[2] / 2, add[1] + add[3] / 2);
      s = await until(page, (s) => s.scene.render.tiers.length === tiers + 1, 'a tier added');
      // The header's label changed ("Tiers (1)"); a few frames later the group is still open:
      // its button is still drawn (there is room for one more).
      await page.waitForTimeout(300);
      s = await state(page);
      assert.ok(s.view.widgets['button:Add a tier'], 'still open after adding a tier');
      // A second tier, then "remove" on the first: the second moves down (its own edit, which
      // takes the first's keys with it: the unit tests key them), and undo brings both back.
      const again = await reveal(page, 'button:Add a tier');
      await page.mouse.click(again[0] + again[2] / 2, again[1] + again[3] / 2);
      s = await until(page, (s) => s.scene.render.tiers.length === 2, 'a second tier');
      const floors = s.scene.render.tiers.map((t) => t.floor);
      assert.ok(floors[1] > floors[0], `floors ${floors}`);
      const remove = await reveal(page, 'button:remove tier 1');
      await page.mouse.click(remove[0] + remove[2] / 2, remove[1] + remove[3] / 2);
      s = await until(page, (s) => s.scene.render.tiers.length === 1, 'tier 1 removed');
      assert.equal(s.scene.render.tiers[0].floor, floors[1], 'tier 2 moved down');
      await page.keyboard.press('Control+z');
      s = await until(page, (s) => s.scene.render.tiers.length === 2, 'undone');
      assert.deepEqual(s.scene.render.tiers.map((t) => t.floor), floors);
    });
  });
}
