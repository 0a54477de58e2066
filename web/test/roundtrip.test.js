// The glTF round trip in the browser (issue 20): scenes baked from glTF and written back with
// shrefract-export --into load in the example page with their other objects drawn as usual. Each
// glass primitive gets an SHRefractionMaterial, every other primitive keeps its own material, and
// the glass-only scenes (the mug with water; the tumbler under a moved, turned, scaled empty, whose
// primitives sit in their nodes' coordinates) match shrefract-render's image of the same bake.
//   node roundtrip.test.js --assets DIR [--backend llvmpipe|swiftshader] [--min-psnr DB]
import { basename } from 'node:path';
import { openExample, grab, withBrowser } from './browser.js';
import { readPng, objectPsnr } from './images.js';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };
const dir = arg('--assets');
const backend = arg('--backend', 'llvmpipe');
const minPsnr = Number(arg('--min-psnr', '50'));
const assets = readAssets(dir);
await withBrowser(dir, { backend }, async (browser, base) => {
  let failed = false;
  for (const [name, r] of Object.entries(assets.roundTrips)) {
    const page = await openExample(browser, base, {
      glb: `/files/${basename(r.glb)}`, env: `/files/${basename(assets.env)}`,
      size: `${assets.size}x${assets.size}`, camera: r.camera.join(','), target: r.target.join(','),
    });
    if (page.state.state !== 'ready') throw new Error(`${name}: the page says: ${page.state.error}`);
    const counts = await page.evaluate(() => {
      let glass = 0, others = 0, standard = 0;
      shrefract.scene.traverse((o) => {
        if (!o.isMesh || o === shrefract.background) return;
        if (o.material.isRawShaderMaterial && o.material.refraction) ++glass;
        else { ++others; if (o.material.isMeshStandardMaterial) ++standard; }
      });
      return { glass, others, standard };
    });
    const { color, mask } = await grab(page);
    let covered = 0;
    for (let i = 0; i < mask.data.length; i += 4) covered += mask.data[i] > 127;
    let ok = counts.glass === r.glass && counts.others === r.others && counts.standard === r.others && covered > 100;
    let line = `${name}: ${counts.glass} glass primitives (expected ${r.glass}), ${counts.others} others with ` +
               `their own glTF materials (expected ${r.others}), ${covered} px drawn`;
    if (r.view) {
      const p = objectPsnr(color, readPng(r.view.png), mask);
      ok &&= p.psnr >= minPsnr;
      line += `; object PSNR against shrefract-render ${p.psnr.toFixed(2)} dB over ${p.pixels} px, threshold ${minPsnr} dB [${backend}]`;
    }
    if (page.problems.length) { ok = false; line += `; the page reported ${page.problems.join('; ')}`; }
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${line}`);
    await page.context().close();
  }
  return failed;
});
