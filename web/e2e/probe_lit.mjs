import { serve, launch, openApp, waitForBody, waitForFullQuality, state, until } from './harness.mjs';
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function outline(page, cx, cy, r) {
  const pts = [];
  for (let i = 0; i <= 36; i++) { const a = (i / 36) * 2 * Math.PI; const bump = 1 + 0.15 * Math.sin(a * 5);
    pts.push([cx + r * 1.4 * Math.cos(a) * bump, cy - r * Math.max(Math.sin(a), -0.3) * bump]); }
  await page.mouse.move(pts[0][0], pts[0][1]); await page.mouse.down();
  for (const [x, y] of pts.slice(1)) await page.mouse.move(x, y);
  await page.mouse.up();
}
const server = await serve();
const W = +(process.env.W ?? 1280), H = +(process.env.H ?? 800);
const runs = +(process.env.RUNS ?? 1);
for (let r = 0; r < runs; r++) {
const { browser, close } = await launch({ webgpu: (process.env.BK ?? 'webgpu') === 'webgpu' });
const { page } = await openApp(browser, server.url, '', { width: W, height: H });
await waitForBody(page, 'data-ready', (v) => v === 'true');
const [vw, vh] = (await state(page)).view.viewport;
await waitForFullQuality(page);
if (!process.env.NOSTROKE) {
await page.keyboard.press('d');
await until(page, (s) => s.view.tool === 'sketch', 'sketch tool');
await outline(page, vw * 0.3, vh * 0.75, vw * 0.06);
await until(page, (s) => s.scene.planes.length === 1, 'a stroke');
}
await waitForFullQuality(page, 60_000);
if (process.env.REPEAT) {
  await page.evaluate(() => { window.cloudsketch.set('/light/ground=true'); window.cloudsketch.set('/light/shafts=true'); });
  await waitForBody(page, 'data-quality', (v) => typeof v === 'string' && !v.startsWith('full'), 3_000).catch(() => {});
  await waitForFullQuality(page, 120_000);
  await page.evaluate(() => { window.cloudsketch.set('/light/ground=false'); window.cloudsketch.set('/light/shafts=false'); });
  await waitForBody(page, 'data-quality', (v) => typeof v === 'string' && !v.startsWith('full'), 3_000).catch(() => {});
  await waitForFullQuality(page, 120_000);
}
await page.evaluate(() => {
  window.__log = []; window.__t0 = performance.now(); window.__loop = true;
  const loop = (t) => { const v = window.cloudsketch.state().view;
    window.__log.push([Math.round(t - window.__t0), document.body.getAttribute('data-quality'), v.jobs, v.late, v.cost]);
    if (window.__loop) requestAnimationFrame(loop); };
  requestAnimationFrame(loop);
});
await page.evaluate((g) => { if (g) window.cloudsketch.set('/light/ground=true'); }, !process.env.NOGROUND);
await page.evaluate((shafts) => { if (shafts) window.cloudsketch.set('/light/shafts=true'); }, !process.env.NOSHAFTS);
const t0 = Date.now();
await waitForBody(page, 'data-quality', (v) => typeof v === 'string' && !v.startsWith('full'), 3_000).catch(() => {});
await waitForFullQuality(page, 120_000);
const secs = (Date.now() - t0) / 1000;
const log = await page.evaluate(() => { window.__loop = false; return window.__log; });
console.log(`run ${r}: ${secs}s`);
if (process.env.VERBOSE) for (const l of log) console.log(JSON.stringify(l));
await close();
}
await server.close();
