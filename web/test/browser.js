// Headless Debian chromium through playwright-core, WebGL 2 on SwiftShader (no GPU needed), and
// the static server the example uses: what every browser test and scripts/web-compare share.
import { existsSync } from 'node:fs';
import { chromium } from 'playwright-core';
import { startServer } from '../example/serve.js';
import { objectPsnr } from './images.js';

export const CHROMIUM = process.env.SHREFRACT_CHROMIUM || '/usr/bin/chromium';

// Exit code ctest reads as "skipped" (SKIP_RETURN_CODE in tests/web/CMakeLists.txt).
export const SKIP = 77;

export function skipUnlessReady() {
  if (!existsSync(CHROMIUM)) {
    console.log(`SKIP: no chromium at ${CHROMIUM} (scripts/setup installs Debian's)`);
    process.exit(SKIP);
  }
}

// backend 'swiftshader': ANGLE on SwiftShader's Vulkan (what a machine without a GPU gets);
// 'llvmpipe': ANGLE on Mesa's llvmpipe through EGL, the rasterizer the C++ tests and
// shrefract-render use here, so a web-vs-C++ comparison sees the two codes and not two
// rasterizers (their screen-space derivatives differ, and jitter shading's footprint reads them).
export async function launch({ backend = process.env.SHREFRACT_WEBGL || 'swiftshader' } = {}) {
  const angle = { swiftshader: 'swiftshader', llvmpipe: 'gl-egl' }[backend];
  if (!angle) throw new Error(`unknown WebGL backend ${backend}: swiftshader | llvmpipe`);
  return chromium.launch({
    executablePath: CHROMIUM,
    args: [
      '--no-sandbox',
      '--headless=new',
      '--use-gl=angle',
      `--use-angle=${angle}`,
      '--enable-unsafe-swiftshader',
      '--ignore-gpu-blocklist',
    ],
  });
}

// A page of the served web/ folder that records uncaught exceptions and console errors.
export async function openPage(browser, url, { initScript } = {}) {
  const context = await browser.newContext({ viewport: { width: 400, height: 400 }, deviceScaleFactor: 1 });
  if (initScript) await context.addInitScript(initScript);
  const page = await context.newPage();
  page.problems = [];
  page.on('pageerror', (e) => page.problems.push(`pageerror: ${e.message}`));
  page.on('crash', () => { page.problems.push('the page crashed'); console.log('the page crashed'); });
  page.on('console', (m) => {
    if (m.type() === 'error') page.problems.push(`console.error: ${m.text()}`);
  });
  await page.goto(url);
  return page;
}

export { startServer };

// Opens the example page on `glb` (null: none) with these query parameters, waits until it is
// ready or shows an error, and returns the page with its state.
export async function openExample(browser, base, params, options = {}) {
  const all = { static: '1', ...params };
  for (const k of Object.keys(all)) if (all[k] === null) delete all[k];  // static: null, the live loop
  const query = new URLSearchParams(all).toString();
  const page = await openPage(browser, `${base}/example/?${query}`, options);
  await page.waitForFunction(() => window.shrefract && window.shrefract.state !== 'loading', null,
                             { timeout: options.timeout ?? 120000 });
  page.state = await page.evaluate(() => ({ state: shrefract.state, error: shrefract.error,
                                            firstFrameMs: shrefract.firstFrameMs }));
  return page;
}

// The canvas's pixels and the glass's coverage, as images (test/images.js).
export async function grab(page) {
  const [w, h] = await page.evaluate(() => shrefract.size);
  const color = await page.evaluate(() => shrefract.readPixels());
  const mask = await page.evaluate(() => shrefract.coverage());
  const decode = (b64) => ({ width: w, height: h, data: new Uint8Array(Buffer.from(b64, 'base64')) });
  return { color: decode(color), mask: decode(mask) };
}

// The example drawn with `params`, then again with `variant` ({ params, options }: other query
// parameters, or openExample's options such as an init script): the second frame's object PSNR
// against the first, over the first frame's glass. probe(page), when given, runs on each page
// before it closes (guard it: it runs on a page that shows an error too).
export async function sameFrameAs(browser, base, params, variant, probe = async () => null) {
  const first = await openExample(browser, base, params);
  const reference = await grab(first);
  const probedFirst = await probe(first);
  await first.context().close();
  const page = await openExample(browser, base, variant.params ?? params, variant.options ?? {});
  const ready = page.state.state === 'ready';
  const probed = await probe(page);
  const r = ready ? objectPsnr((await grab(page)).color, reference.color, reference.mask) : { psnr: 0, pixels: 0 };
  await page.context().close();
  return { ready, ...r, probedFirst, probed, error: page.state.error, problems: page.problems };
}

// Serves web/ with the test's asset folder under /files/.
export async function serveAssets(dir) {
  const server = await startServer({ roots: { '/files/': dir } });
  return { server, base: `http://127.0.0.1:${server.address().port}` };
}

// Serves `dir`, launches chromium, runs body(browser, base) (true: something failed), closes
// both and exits: 0, or 1 when the body failed.
export async function withBrowser(dir, launchOptions, body) {
  skipUnlessReady();
  const { server, base } = await serveAssets(dir);
  const browser = await launch(launchOptions);
  let failed = true;
  try {
    failed = await body(browser, base);
  } finally {
    await browser.close();
    server.close();
  }
  process.exit(failed ? 1 : 0);
}
