// One-off: the README's screenshot (not a test; deleted after use).
import { serve, withApp, waitForFullQuality, screenshot } from './harness.mjs';
const server = await serve();
await withApp({ base: server.url, webgpu: true, viewport: { width: 900, height: 560 } }, async (page) => {
  await waitForFullQuality(page);
  await page.waitForTimeout(1500);
  await screenshot(page, 'readme-default');
});
await server.close?.();
process.exit(0);
