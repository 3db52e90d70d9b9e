// Nothing a user makes is lost on a reload: the scene is written to the page's storage a
// second after it changes and a plain visit continues it (with a notice); opening a link to a
// preset never replaces that session silently: it is kept aside under its own key.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { serve, launch, openApp, waitForBody, state, until, recordTiming, openGroup } from './harness.mjs';

let server;
before(async () => { server = await serve(); });
after(async () => { await server?.close(); });

const saved = (page, key) => page.evaluate((k) => JSON.parse(localStorage.getItem(k) ?? 'null'), key);

test('a reload continues the session; a link keeps it aside (webgpu)', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '', { width: 1280, height: 800 });
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    assert.equal(await saved(page, 'cloudsketch.autosave'), null, 'an untouched session writes nothing');
    await page.evaluate(() => window.cloudsketch.set('/ellipsoids/0/center=[5,5,5]'));
    await until(page, (s) => s.scene.ellipsoids[0].center[0] === 5, 'edited');
    // Written about a second later, without any further input.
    const t0 = Date.now();
    await page.waitForFunction(() => {
      const s = JSON.parse(localStorage.getItem('cloudsketch.autosave') ?? 'null');
      return s && s.ellipsoids[0].center[0] === 5;
    }, null, { timeout: 60_000, polling: 50 });
    // How soon is a figure for timings.json, not an assertion (a busy machine is slower).
    recordTiming({ test: 'autosave', backend: 'webgpu', seconds_to_autosave: (Date.now() - t0) / 1000 });

    await page.reload();
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    let s = await state(page);
    assert.deepEqual(s.scene.ellipsoids[0].center, [5, 5, 5], 'the session came back');
    assert.match(s.view.notice.text, /Restored your last session/);

    await page.goto(`${server.url}?preset=stratus`);
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    s = await state(page);
    assert.ok(s.scene.ellipsoids.length > 20, 'the link opened the stratus preset');
    const previous = await saved(page, 'cloudsketch.autosave.previous');
    assert.deepEqual(previous.ellipsoids[0].center, [5, 5, 5], 'the last session is kept aside');
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

test('a user\'s own presets are kept by the page and listed after a reload (webgpu)', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '?preset=empty', { width: 1280, height: 800 });
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    assert.deepEqual((await state(page)).view.my_presets, []);
    // As the Scene group's "Save look" stores them; one entry out of range, one unnamed.
    await page.evaluate(() => localStorage.setItem('cloudsketch.presets', JSON.stringify({
      looks: [
        { name: 'golden hour', light: { sun_elevation_deg: 6, ambient: 99 }, render: { noise_filter: 'wispy' } },
        { name: '   ', light: {}, render: {} },
      ],
    })));
    await page.reload();
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    assert.deepEqual((await state(page)).view.my_presets, ['golden hour']);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});

test('the side panel opens the groups a new user needs, then as the user left them (webgpu)', { timeout: 180_000 }, async () => {
  const { browser, close } = await launch({ webgpu: true });
  try {
    const { page, errors } = await openApp(browser, server.url, '', { width: 1280, height: 800 });
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    let open = (await state(page)).view.groups_open;
    for (const title of ['Sketch', 'Render']) assert.ok(open.includes(title), `${title} open at first: ${open}`);
    for (const title of ['Light', 'Scene', 'Export', 'Simulation']) assert.ok(!open.includes(title), `${title} closed at first: ${open}`);
    // Opened by a click on its header, Export stays open over a reload.
    await openGroup(page, 'Export');
    await page.reload();
    await waitForBody(page, 'data-ready', (v) => v === 'true');
    open = (await until(page, (s) => s.view.groups_open.includes('Render'), 'the panel drawn')).view.groups_open;
    assert.ok(open.includes('Export'), `Export kept open: ${open}`);
    assert.deepEqual(errors, []);
  } finally {
    await close();
  }
});
