// drei's MeshRefractionMaterial, which the peer benchmark compares with, loads in the same
// browser from vanilla three: its materials/ module through an import map (three, three-mesh-bvh),
// no react; the material compiles and draws a frame (with one shim: three 0.187 dropped a shader
// chunk drei includes, see test/pages/drei.html).
//   node drei.test.js
import { withBrowser, openPage } from './browser.js';

await withBrowser('.', {}, async (browser, base) => {
  const page = await openPage(browser, `${base}/test/pages/drei.html`);
  await page.waitForFunction(() => window.result, null, { timeout: 60000 });
  const result = await page.evaluate(() => window.result);
  const ok = result.ok && result.react === 'undefined' && !page.problems.length;
  console.log(`${ok ? 'ok  ' : 'FAIL'} drei MeshRefractionMaterial without react: ${JSON.stringify(result)}` +
              `${page.problems.length ? `; page: ${page.problems.join('; ')}` : ''}`);
  return !ok;
});
