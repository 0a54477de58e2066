// WEBGL_lose_context: the context is lost (a frame asked for meanwhile must not throw), then
// restored, and the material draws the same image again: three re-uploads the error layers and
// cube map from the sources the loader keeps and recompiles the programs, and the material copies
// the weight pages into their array texture again.
//   node context-loss.test.js --assets DIR
import { basename } from 'node:path';
import { openExample, grab, withBrowser } from './browser.js';
import { objectPsnr } from './images.js';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };
const dir = arg('--assets');
const assets = readAssets(dir);
const [name, object] = Object.entries(assets.objects)[0];
await withBrowser(dir, {}, async (browser, base) => {
  let failed = false;
  const page = await openExample(browser, base, {
    glb: `/files/${basename(object.glb)}`, env: `/files/${basename(assets.env)}`, size: '128x128',
  });
  if (page.state.state !== 'ready') throw new Error(`the page says: ${page.state.error}`);
  const before = await grab(page);
  const lost = await page.evaluate(async () => {
    const canvas = shrefract.renderer.domElement;
    const ext = shrefract.renderer.getContext().getExtension('WEBGL_lose_context');
    const event = (type) => new Promise((done) => canvas.addEventListener(type, done, { once: true }));
    const gone = event('webglcontextlost');
    ext.loseContext();
    await gone;
    // Restoring is allowed once the lost event's dispatch has ended, not from within it.
    await new Promise((done) => setTimeout(done, 0));
    const whileLost = shrefract.renderer.getContext().isContextLost();
    shrefract.render();  // a frame while lost: three skips it, nothing throws
    const back = event('webglcontextrestored');
    ext.restoreContext();
    await back;
    shrefract.render();
    return { whileLost, state: shrefract.state, error: shrefract.error };
  });
  const after = await grab(page);
  const r = objectPsnr(after.color, before.color, before.mask);
  // Measured: identical pixels (PSNR infinite). 60 dB would still catch a missing texture or a
  // black frame (those measure below 15 dB).
  const ok = lost.whileLost && lost.state === 'ready' && r.psnr >= 60 && r.pixels > 100 && !page.problems.length;
  failed = !ok;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: context lost (${lost.whileLost}) and restored; after vs before: ` +
              `PSNR ${r.psnr} dB over ${r.pixels} px, largest difference ${r.worst}; page state ${lost.state}` +
              `${lost.error ? ` (${lost.error})` : ''}${page.problems.length ? `; page: ${page.problems.join('; ')}` : ''}`);
  return failed;
});
