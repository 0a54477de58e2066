// Test assets: small u8 bakes (identical codes on both sides), shrefract-render's PNGs of them at
// a few views, and their GLBs from shrefract-export, plus an environment-only GLB. Run as
//   node assets.js --bin BUILD_DIR --out DIR [--full]
// (the browser tests' ctest fixture; scripts/web-compare passes --full for the issue's sizes).
// DIR/assets.json lists what is there.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, writeFileSync, readFileSync, rmSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { readGlb } from './glb.js';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');

export const ENV = 'studio';
export const SIZE = 256;
// shrefract-render's orbit: azimuth, elevation (degrees), distance.
export const VIEWS = [[30, 20, 3], [150, -10, 3], [270, 45, 2.5]];

// CI: a few thousand samples each, seconds to bake; two SH bakes and a grid-basis one. Full: the
// issue's objects at the paper's settings (35k samples, 2048 directions, order 8), and the bunny
// in the grid basis.
const SMALL = {
  knot1: ['data/meshes/knot1.off', '--rate', '1', '--order', '4', '--grid', '8x16'],
  teapot: ['data/scenes/teapot.json', '--rate', '2', '--order', '4', '--grid', '8x16'],
  // The grid basis (version 2 of the extension): the traced 8 x 16 exits, its error model.
  knot1_grid: ['data/meshes/knot1.off', '--rate', '1', '--basis', 'grid', '--grid', '8x16'],
};
const FULL = {
  bunny00: ['data/meshes/bunny00.off', '--samples', '35000', '--order', '8', '--grid', '32x64'],
  knot1: ['data/meshes/knot1.off', '--samples', '35000', '--order', '8', '--grid', '32x64'],
  teapot: ['data/scenes/teapot.json', '--samples', '35000', '--order', '8', '--grid', '32x64'],
  // The grid basis the chart prefers (docs/bake.md "The grid basis"): 2048 bytes a sample.
  bunny00_grid: ['data/meshes/bunny00.off', '--samples', '35000', '--basis', 'grid', '--grid', '16x32'],
};

// The glTF round trip (issue 20): scenes the bake reads as glTF, written back with
// shrefract-export --into. glass: primitives that get the material; others: primitives that keep
// their own; compare: glass-only scenes, drawn by shrefract-render too.
// camera: an orbit (azimuth, elevation, distance) around target, framing the glass (the Blender-
// style scenes are in metres, away from the origin). bake: options instead of ROUND_TRIP_BAKE.
const ROUND_TRIPS = {
  mug_water: { input: 'data/scenes/mug_water.gltf', glass: 2, others: 0, compare: true,
               camera: [30, 20, 3], target: [0, 0, 0] },
  mug_water_grid: { input: 'data/scenes/mug_water.gltf', glass: 2, others: 0, compare: true,
                    camera: [30, 20, 3], target: [0, 0, 0], bake: ['--rate', '1', '--basis', 'grid', '--grid', '8x16'] },
  blender_tumbler: { input: 'data/scenes/blender_tumbler.glb', glass: 2, others: 0, compare: true,
                     camera: [30, 20, 0.45], target: [0.2, 0.85, -0.1] },
  blender_glass_on_table: { input: 'data/scenes/blender_glass_on_table.gltf', glass: 1, others: 1,
                            compare: false, camera: [30, 25, 1.2], target: [0, 0.75, 0] },
};

// The eye of shrefract-render's orbit (runtime/src/render.cpp Camera::orbit) around target.
function orbitEye([az, el, dist], target) {
  const a = (az * Math.PI) / 180, e = (el * Math.PI) / 180;
  return [dist * Math.cos(e) * Math.sin(a), dist * Math.sin(e), dist * Math.cos(e) * Math.cos(a)].map((v, i) => v + target[i]);
}
const ROUND_TRIP_BAKE = ['--rate', '1', '--order', '4', '--grid', '8x16'];

function tool(bin, name) {
  for (const sub of ['bake', 'eval', 'common', 'bin', '.']) {
    const p = join(bin, sub, name);
    if (existsSync(p)) return p;
  }
  throw new Error(`${name}: not found under ${bin}`);
}

function run(exe, args) {
  return execFileSync(exe, args, { stdio: ['ignore', 'pipe', 'pipe'], encoding: 'utf8' });
}

// fresh: start from an empty folder (the ctest fixture: a rebuilt tool must not meet old files);
// otherwise what is there is kept (scripts/web-compare's full-size bakes take minutes).
export function makeAssets({ bin, out, full = false, fresh = false, log = () => {} }) {
  if (fresh) rmSync(out, { recursive: true, force: true });
  mkdirSync(out, { recursive: true });
  const bake = tool(bin, 'shrefract-bake'), render = tool(bin, 'shrefract-render');
  const exporter = tool(bin, 'shrefract-export');
  const envExr = join(root, 'data', 'envmaps', `${ENV}.exr`);
  const envGlb = join(out, `${ENV}.glb`);
  if (!existsSync(envGlb)) run(exporter, ['--environment', envExr, '-o', envGlb]);
  const objects = {};
  for (const [name, [input, ...options]] of Object.entries(full ? FULL : SMALL)) {
    const exr = join(out, `${name}.shrefract.exr`), glb = join(out, `${name}.glb`);
    if (!existsSync(exr)) {
      log(`baking ${name}`);
      run(bake, [join(root, input), '-o', exr, ...options, '--precision', 'u8', '-q', '--cache', join(out, 'cache')]);
    }
    if (!existsSync(glb)) run(exporter, [exr, '-o', glb]);
    // The same bake in pages of one tile each (--max-texture at the tile's side): one page per
    // coefficient, far past the four that the material once read (pages.test.js).
    let paged = null;
    if (!full) {
      paged = join(out, `${name}_paged.glb`);
      const [W, H] = readGlb(glb).json.extensions.SHREFRACT_sh_refraction.refractions[0].tileSize;
      if (!existsSync(paged)) run(exporter, [exr, '-o', paged, '--max-texture', String(Math.max(W, H, 16))]);
    }
    const views = [];
    for (const [v, [az, el, dist]] of VIEWS.entries()) {
      const png = join(out, `${name}-view${v}.png`), json = join(out, `${name}-view${v}.json`);
      if (!existsSync(png))
        run(render, [exr, '--env', envExr, '--size', `${SIZE}x${SIZE}`, '--camera', `orbit:${az},${el},${dist}`,
                     '--frames', '1', '--out', png, '--json', json]);
      views.push({ camera: [az, el, dist], png, json });
    }
    objects[name] = { exr, glb, paged, views };
  }
  const roundTrips = {};
  if (!full) for (const [name, r] of Object.entries(ROUND_TRIPS)) {
    const exr = join(out, `${name}.shrefract.exr`), glb = join(out, `${name}_baked.glb`);
    if (!existsSync(exr)) {
      log(`baking ${name}`);
      run(bake, [join(root, r.input), '-o', exr, ...(r.bake ?? ROUND_TRIP_BAKE), '--precision', 'u8', '-q', '--cache', join(out, 'cache')]);
    }
    if (!existsSync(glb)) run(exporter, [exr, '--into', join(root, r.input), '-o', glb]);
    const view = { camera: r.camera, target: r.target, png: join(out, `${name}-view0.png`) };
    if (r.compare && !existsSync(view.png))
      run(render, [exr, '--env', envExr, '--size', `${SIZE}x${SIZE}`, '--eye', orbitEye(r.camera, r.target).join(','),
                   '--target', r.target.join(','), '--frames', '1', '--out', view.png]);
    roundTrips[name] = { ...r, exr, glb, view: r.compare ? view : null };
  }
  const assets = { size: SIZE, env: envGlb, envExr, objects, roundTrips };
  writeFileSync(join(out, 'assets.json'), JSON.stringify(assets, null, 2));
  return assets;
}

export function readAssets(dir) {
  return JSON.parse(readFileSync(join(dir, 'assets.json'), 'utf8'));
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const arg = (k) => { const i = process.argv.indexOf(k); return i > 0 ? process.argv[i + 1] : undefined; };
    makeAssets({ bin: arg('--bin'), out: arg('--out'), full: process.argv.includes('--full'),
               fresh: process.argv.includes('--fresh'), log: console.log });
}
