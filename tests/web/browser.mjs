// browser.mjs - headless Debian chromium (WebGL2 on SwiftShader) driven by playwright-core, with
// the test page (tests/web/page) and the case files served by web/viewer/serve.mjs.
import { chromium } from '../../web/node_modules/playwright-core/index.mjs';
import { startServer } from '../../web/viewer/serve.mjs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const HERE = dirname(fileURLToPath(import.meta.url));
export const CHROMIUM = process.env.SKINPACK_CHROMIUM || '/usr/bin/chromium';
export const CHROMIUM_ARGS = ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
  '--no-sandbox', '--disable-dev-shm-usage'];

/** Opens the test page; returns {page, url, close()}. files: folder served at /files/. */
export async function openTestPage(files) {
  const { server, url } = await startServer({ mounts: { '/test/': join(HERE, 'page'), '/files/': files } });
  const browser = await chromium.launch({ executablePath: CHROMIUM, args: CHROMIUM_ARGS, headless: true });
  const page = await browser.newPage();
  const log = [];
  page.on('console', (m) => log.push(`${m.type()}: ${m.text()}`));
  page.on('pageerror', (e) => log.push(`pageerror: ${e.message}`));
  await page.goto(`${url}/test/index.html`);
  await page.waitForFunction(() => window.skinpackTestReady === true, null, { timeout: 60000 });
  return { page, url, log, browser, close: async () => { await browser.close(); server.close(); } };
}

/** Per-image difference: pixels whose largest channel difference exceeds tolerance. */
export function compareImages(a, b, tolerance) {
  const x = Buffer.from(a, 'base64'), y = Buffer.from(b, 'base64');
  let differing = 0, maxDelta = 0;
  for (let i = 0; i < x.length; i += 4) {
    const d = Math.max(Math.abs(x[i] - y[i]), Math.abs(x[i + 1] - y[i + 1]), Math.abs(x[i + 2] - y[i + 2]));
    if (d > tolerance) differing++;
    if (d > maxDelta) maxDelta = d;
  }
  return { differing, maxDelta, pixels: x.length / 4 };
}
