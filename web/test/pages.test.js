// Many weight pages: each object exported again with pages of one tile each (shrefract-export
// --max-texture at the tile's side, assets.js), one page per coefficient. The material holds the
// pages as layers of one array texture, so it must load every one and draw the very frame the
// default export draws.
//   node pages.test.js --assets DIR
import { basename } from 'node:path';
import { sameFrameAs, withBrowser } from './browser.js';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };

const dir = arg('--assets');
const assets = readAssets(dir);
await withBrowser(dir, {}, async (browser, base) => {
  let failed = false;
  for (const [name, object] of Object.entries(assets.objects)) {
    const params = (glb) => ({ glb: `/files/${basename(glb)}`, env: `/files/${basename(assets.env)}`, size: '128x128' });
    const pageCount = (page) => page.evaluate(() => shrefract.materials[0]?.refraction.pages.length ?? 0);
    const r = await sameFrameAs(browser, base, params(object.glb), { params: params(object.paged) }, pageCount);
    // Measured: identical pixels (PSNR infinite). 60 dB still fails a page read from the wrong
    // layer (pages of one tile: every coefficient but the first wrong) or a blank frame.
    const ok = r.ready && r.probed > 4 && r.psnr >= 60 && r.pixels > 100 && !r.problems.length;
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: ${r.probed} weight pages (the default export ${r.probedFirst}); ` +
                `${r.ready ? `vs the default export: PSNR ${r.psnr} dB over ${r.pixels} px` : `page error: ${r.error}`}` +
                `${r.problems.length ? `; page: ${r.problems.join('; ')}` : ''}`);
  }
  return failed;
});
