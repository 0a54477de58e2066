// Many weight pages: each object exported again with pages of one tile each (shrefract-export
// --max-texture at the tile's side, assets.js), one page per coefficient. The material holds the
// pages as layers of one array texture, so it must load every one and draw the very frame the
// default export draws.
//   node pages.test.js --assets DIR
import { basename } from 'node:path';
import { openExample, grab, withBrowser } from './browser.js';
import { objectPsnr } from './images.js';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };

const dir = arg('--assets');
const assets = readAssets(dir);
await withBrowser(dir, {}, async (browser, base) => {
  let failed = false;
  for (const [name, object] of Object.entries(assets.objects)) {
    const params = (glb) => ({ glb: `/files/${basename(glb)}`, env: `/files/${basename(assets.env)}`, size: '128x128' });
    const plain = await openExample(browser, base, params(object.glb));
    const reference = await grab(plain);
    const fewer = await plain.evaluate(() => shrefract.materials[0].refraction.pages.length);
    await plain.context().close();
    const page = await openExample(browser, base, params(object.paged));
    const ready = page.state.state === 'ready';
    const pages = ready ? await page.evaluate(() => shrefract.materials[0].refraction.pages.length) : 0;
    const r = ready ? objectPsnr((await grab(page)).color, reference.color, reference.mask) : { psnr: 0, pixels: 0 };
    // Measured: identical pixels (PSNR infinite). 60 dB still fails a page read from the wrong
    // layer (pages of one tile: every coefficient but the first wrong) or a blank frame.
    const ok = ready && pages > 4 && r.psnr >= 60 && r.pixels > 100 && !page.problems.length;
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: ${pages} weight pages (the default export ${fewer}); ` +
                `${ready ? `vs the default export: PSNR ${r.psnr} dB over ${r.pixels} px` : `page error: ${page.state.error}`}` +
                `${page.problems.length ? `; page: ${page.problems.join('; ')}` : ''}`);
    await page.context().close();
  }
  return failed;
});
