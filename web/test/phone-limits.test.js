// A phone-like WebGL 2: no EXT_color_buffer_float (hidden by an init script that wraps the
// context's getExtension and getSupportedExtensions) and MAX_TEXTURE_SIZE (and the cube size)
// reported as 4096. The material renders to the canvas only and its pages are at most 4096
// texels, so the frame must be drawn and equal the unrestricted one.
//   node phone-limits.test.js --assets DIR
import { basename } from 'node:path';
import { openExample, grab, withBrowser } from './browser.js';
import { objectPsnr } from './images.js';
import { readAssets } from './assets.js';

const arg = (k, d) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : d; };

function phone() {
  const original = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
    const gl = original.call(this, type, ...rest);
    if (!gl || type !== 'webgl2' || gl.__phone) return gl;
    gl.__phone = true;
    const getExtension = gl.getExtension.bind(gl), supported = gl.getSupportedExtensions.bind(gl);
    const getParameter = gl.getParameter.bind(gl);
    gl.getExtension = (name) => (name === 'EXT_color_buffer_float' ? null : getExtension(name));
    gl.getSupportedExtensions = () => supported().filter((n) => n !== 'EXT_color_buffer_float');
    gl.getParameter = (p) => {
      if (p === gl.MAX_TEXTURE_SIZE || p === gl.MAX_CUBE_MAP_TEXTURE_SIZE) return Math.min(getParameter(p), 4096);
      return getParameter(p);
    };
    return gl;
  };
}

const dir = arg('--assets');
const assets = readAssets(dir);
await withBrowser(dir, {}, async (browser, base) => {
  let failed = false;
  for (const [name, object] of Object.entries(assets.objects)) {
    const params = { glb: `/files/${basename(object.glb)}`, env: `/files/${basename(assets.env)}`, size: '128x128' };
    const plain = await openExample(browser, base, params);
    const reference = await grab(plain);
    await plain.context().close();
    const page = await openExample(browser, base, params, { initScript: phone });
    const seen = await page.evaluate(() => ({
      maxTextureSize: shrefract.renderer.capabilities.maxTextureSize,
      colorBufferFloat: shrefract.renderer.extensions.has('EXT_color_buffer_float'),
    }));
    const ready = page.state.state === 'ready';
    const r = ready ? objectPsnr((await grab(page)).color, reference.color, reference.mask) : { psnr: 0, pixels: 0 };
    // Measured: identical pixels; 60 dB still fails a blank or broken frame (below 15 dB).
    const ok = ready && seen.maxTextureSize === 4096 && !seen.colorBufferFloat && r.psnr >= 60 && r.pixels > 100 &&
               !page.problems.length;
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: MAX_TEXTURE_SIZE ${seen.maxTextureSize}, EXT_color_buffer_float ` +
                `${seen.colorBufferFloat ? 'present' : 'hidden'}; ${ready ? `vs unrestricted: PSNR ${r.psnr} dB over ${r.pixels} px` : `page error: ${page.state.error}`}` +
                `${page.problems.length ? `; page: ${page.problems.join('; ')}` : ''}`);
    await page.context().close();
  }
  return failed;
});
