// viewer.test.mjs - the viewer page (web/viewer) in headless Chromium: stats, GPU/CPU toggle,
// original vs decoded weights, weight-error colouring, animations, refusals shown as errors.
// SKINPACK_WEB_SCREENSHOT=path also saves a screenshot (docs/images/web_viewer.png is made so).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { basename, join } from 'node:path';
import { chromium } from '../../web/node_modules/playwright-core/index.mjs';
import { startServer } from '../../web/viewer/serve.mjs';
import { CHROMIUM, CHROMIUM_ARGS } from './browser.mjs';
import { allCases, WORK } from './cases.mjs';
import { readGltf, writeGlb } from './gltf_file.mjs';
import { SKINPACK_EXTENSION } from '../../web/src/decode.js';

const cases = allCases();
const fox = (tag) => cases.find((c) => c.name === `Fox_${tag}`);
let server, browser, page, url;
const errors = [];

before(async () => {
  ({ server, url } = await startServer({ mounts: { '/files/': WORK } }));
  browser = await chromium.launch({ executablePath: CHROMIUM, args: CHROMIUM_ARGS, headless: true });
  page = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  page.on('pageerror', (e) => errors.push(e.message));
});
after(async () => { await browser?.close(); server?.close(); });

async function open(file, query = '') {
  await page.goto(`${url}/viewer/?file=/files/${basename(file)}${query}`);
  await page.waitForFunction(() => window.skinpackViewer && !document.getElementById('status').textContent.startsWith('Loading') &&
                                   document.getElementById('status').textContent !== '', null, { timeout: 60000 });
}

async function settle() {
  await page.waitForFunction(() => !document.getElementById('status').textContent.startsWith('Loading'), null, { timeout: 60000 });
}

const text = (selector) => page.locator(selector).innerText();

test('a fallback file: stats, decode toggle, original weights, error colours, animation', async () => {
  await open(fox('fallback').packed);
  let meshes = await text('#meshes');
  assert.match(meshes, /GPU decode/);
  assert.match(meshes, /bits \/ vertex\s+\d+\.\d → \d+\.\d/);
  const error = meshes.match(/max weight error\s+([\d.e+-]+) \(bound ([\d.e+-]+)\)/);
  assert.ok(error, meshes);
  assert.ok(Number(error[1]) > 0 && Number(error[1]) <= Number(error[2]), `error ${error[1]} above bound ${error[2]}`);
  assert.match(meshes, /GPU bytes for the skin\s+[\d,]+ \(3\d\.\d bits\/v\)/); // words + RGBA16UI table
  assert.ok((await page.locator('#clip option').count()) >= 1, 'no animation listed');

  await page.click('#decode-cpu');
  await settle();
  meshes = await text('#meshes');
  assert.match(meshes, /CPU decode/);
  assert.match(meshes, /GPU bytes for the skin\s+[\d,]+ \(160\.0 bits\/v\)/); // 4 x u8 joints + 4 x f32 weights

  await page.click('#weights-original');
  await settle();
  assert.match(await text('#summary'), /original JOINTS_0\/WEIGHTS_0/);
  assert.match(await text('#meshes'), /original weights/);
  assert.ok(await page.locator('#shade-error').isDisabled());

  await page.click('#weights-decoded');
  await page.click('#decode-gpu');
  await page.click('#shade-error');
  await settle();
  assert.ok(await page.locator('#legend').isVisible(), 'no error legend');
  assert.match(await text('#meshes'), /GPU decode/);
  assert.deepEqual(errors, []);
});

test('a compact file: no original weights to show or compare', async () => {
  await open(fox('compact').packed);
  assert.match(await text('#summary'), /compact file/);
  assert.match(await text('#meshes'), /≤ [\d.e+-]+ \(bound; compact: no original\)/);
  assert.ok(await page.locator('#weights-original').isDisabled());
  assert.ok(await page.locator('#shade-error').isDisabled());
});

test('a wide codec shows the CPU fallback and why', async () => {
  await open(fox('oss48').packed);
  assert.match(await text('#meshes'), /CPU decode[\s\S]*CPU fallback: 48 bits a vertex need two words/);
});

test('a broken file is shown as an error naming mesh and primitive', async () => {
  const { json, buffers } = readGltf(fox('fallback').packed);
  json.meshes[0].primitives[0].extensions[SKINPACK_EXTENSION].tupleBits -= 1;
  const broken = join(WORK, 'Fox_viewer_broken.glb');
  writeGlb(broken, json, buffers[0]);
  await open(broken);
  assert.ok(await page.locator('#status.error').isVisible(), 'no error status');
  assert.match(await text('#status'), /mesh 0 "fox1" primitive 0: tupleBits: /);
});

test('a file opened with the Open button decodes too', async () => {
  await page.goto(`${url}/viewer/`);
  await page.setInputFiles('#file', fox('compact').packed);
  await page.waitForFunction(() => window.skinpackViewer.state.gltf && window.skinpackViewer.state.name === 'Fox_compact.glb', null, { timeout: 60000 });
  assert.match(await text('#meshes'), /GPU decode/);
  assert.match(await text('#title'), /Fox_compact\.glb/);
});

test('screenshot', async () => {
  await open(fox('fallback').packed, '&time=1.2');
  await page.waitForTimeout(1500);
  const path = process.env.SKINPACK_WEB_SCREENSHOT || join(WORK, 'web_viewer.png');
  await page.screenshot({ path });
  assert.deepEqual(errors, []);
});
