// Bad files: a truncated GLB, a weight page that names a missing texture, a wrong extension
// version, a grid basis without its grid, a grid basis in a version 1 file. Each must put a clear message in the page's error element and raise no uncaught
// exception, also with the live render loop running (no static=1).
//   node bad-assets.test.js --assets DIR
import { basename, join } from 'node:path';
import { readFileSync, writeFileSync } from 'node:fs';
import { openExample, withBrowser } from './browser.js';
import { readAssets } from './assets.js';
import { readGlb, writeGlb } from './glb.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };
const dir = arg('--assets');
const assets = readAssets(dir);
const good = Object.values(assets.objects)[0].glb;

const whole = readFileSync(good);
writeFileSync(join(dir, 'bad-truncated.glb'), whole.subarray(0, Math.floor(whole.length / 2)));
const missing = readGlb(good);
missing.json.extensions.SHREFRACT_sh_refraction.refractions[0].weights[0] = 99;
writeGlb(join(dir, 'bad-missing-texture.glb'), missing);
const version = readGlb(good);
version.json.extensions.SHREFRACT_sh_refraction.version = 3;
writeGlb(join(dir, 'bad-version.glb'), version);
const gridGlb = Object.values(assets.objects).find((o) => readGlb(o.glb).json.extensions.SHREFRACT_sh_refraction
  .refractions[0].basis === 'grid').glb;
const noGrid = readGlb(gridGlb);
delete noGrid.json.extensions.SHREFRACT_sh_refraction.refractions[0].grid;
writeGlb(join(dir, 'bad-no-grid.glb'), noGrid);
const gridInOne = readGlb(gridGlb);
gridInOne.json.extensions.SHREFRACT_sh_refraction.version = 1;
writeGlb(join(dir, 'bad-grid-in-version-1.glb'), gridInOne);

const cases = [
  ['bad-truncated.glb', /truncated/],
  ['bad-missing-texture.glb', /weights\[0\] names texture 99, which the file lacks/],
  ['bad-version.glb', /SHREFRACT_sh_refraction: version 3; this loader reads versions 1 and 2/],
  ['bad-no-grid.glb', /a grid basis needs "grid": \[nTheta, nPhi\].*it has undefined/],
  ['bad-grid-in-version-1.glb', /basis "grid" \(version 1 knows "sh"\)/],
];
await withBrowser(dir, {}, async (browser, base) => {
  let failed = false;
  for (const [file, expected] of cases) {
    const page = await openExample(browser, base, {
      glb: `/files/${file}`, env: `/files/${basename(assets.env)}`, size: '64x64', static: null,
    });
    await page.waitForTimeout(500);  // frames of the live loop, had it started
    const shown = await page.locator('#error').innerText();
    const visible = await page.locator('#error').isVisible();
    const ok = page.state.state === 'error' && visible && expected.test(shown) && !page.problems.length;
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${file}: the page shows "${shown}"${visible ? '' : ' (not visible)'}` +
                `${page.problems.length ? `; page: ${page.problems.join('; ')}` : ''}`);
    await page.context().close();
  }
  return failed;
});
