// Image helpers for the browser tests: PNG decoding (pngjs) and the object PSNR, the PSNR over
// the pixels the glass covers (eval/image_eval.h's measure, for 8-bit display images).
import { readFileSync } from 'node:fs';
import pngjs from 'pngjs';

// { width, height, data: RGBA bytes, row 0 at the top }
export function readPng(path) {
  return pngjs.PNG.sync.read(readFileSync(path));
}

export function fromBase64(b64, width, height) {
  return { width, height, data: new Uint8Array(Buffer.from(b64, 'base64')) };
}

export function writePng(path, image) {
  const png = new pngjs.PNG({ width: image.width, height: image.height });
  png.data = Buffer.from(image.data);
  return import('node:fs').then((fs) => fs.writeFileSync(path, pngjs.PNG.sync.write(png)));
}

// PSNR (dB) of RGB over the pixels where mask's red is above 127; also how many there are and
// the largest channel difference.
export function objectPsnr(a, b, mask) {
  if (a.width !== b.width || a.height !== b.height) throw new Error(`sizes differ: ${a.width}x${a.height} vs ${b.width}x${b.height}`);
  let sum = 0, n = 0, worst = 0;
  for (let i = 0; i < a.width * a.height; ++i) {
    if (mask && mask.data[4 * i] <= 127) continue;
    for (let c = 0; c < 3; ++c) {
      const d = a.data[4 * i + c] - b.data[4 * i + c];
      sum += d * d;
      worst = Math.max(worst, Math.abs(d));
    }
    n += 1;
  }
  const mse = sum / (3 * Math.max(n, 1));
  return { psnr: mse === 0 ? Infinity : 10 * Math.log10((255 * 255) / mse), pixels: n, worst };
}
