// A phone-like WebGL 2: no EXT_color_buffer_float (hidden by an init script that wraps the
// context's getExtension and getSupportedExtensions) and MAX_TEXTURE_SIZE (and the cube size)
// reported as 4096. The material renders to the canvas only and its pages are at most 4096
// texels, so the frame must be drawn and equal the unrestricted one.
//   node phone-limits.test.js --assets DIR
import { basename } from 'node:path';
import { sameFrameAs, withBrowser } from './browser.js';
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
    const limits = (page) => page.evaluate(() => shrefract.renderer && ({
      maxTextureSize: shrefract.renderer.capabilities.maxTextureSize,
      colorBufferFloat: shrefract.renderer.extensions.has('EXT_color_buffer_float'),
    }));
    const r = await sameFrameAs(browser, base, params, { options: { initScript: phone } }, limits);
    const seen = r.probed || {};
    // Measured: identical pixels; 60 dB still fails a blank or broken frame (below 15 dB).
    const ok = r.ready && seen.maxTextureSize === 4096 && !seen.colorBufferFloat && r.psnr >= 60 && r.pixels > 100 &&
               !r.problems.length;
    failed ||= !ok;
    console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: MAX_TEXTURE_SIZE ${seen.maxTextureSize}, EXT_color_buffer_float ` +
                `${seen.colorBufferFloat ? 'present' : 'hidden'}; ${r.ready ? `vs unrestricted: PSNR ${r.psnr} dB over ${r.pixels} px` : `page error: ${r.error}`}` +
                `${r.problems.length ? `; page: ${r.problems.join('; ')}` : ''}`);
  }
  return failed;
});
