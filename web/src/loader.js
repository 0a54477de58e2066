// SHREFRACT_sh_refraction (docs/format.md "glTF export"): a GLTFLoader plugin that reads the
// extension's refractions and environments into three.js textures and gives each primitive that
// names a refraction an SHRefractionMaterial. Register it with
//   loader.register((parser) => new SHRefractionLoaderPlugin(parser));
// Everything the file gets wrong is an Error with a message (loadAsync rejects with it).
import * as THREE from 'three';
import { SHRefractionMaterial } from './material.js';
import { pageLayers } from './pages.js';

export const EXTENSION = 'SHREFRACT_sh_refraction';
// 2 names each refraction's basis ("sh" or "grid"); 1 is SH only, read as before.
export const VERSIONS = [1, 2];

function fail(message) {
  return new Error(`${EXTENSION}: ${message}`);
}

// A GLB's header and chunk lengths against the bytes there are: a truncated download is named
// as such instead of failing deep inside the loader. Returns the buffer.
export function checkGlb(buffer, what = 'GLB') {
  const bytes = buffer.byteLength;
  if (bytes < 20) throw new Error(`${what}: ${bytes} bytes, too short for a GLB (truncated?)`);
  const view = new DataView(buffer);
  if (view.getUint32(0, true) !== 0x46546c67) throw new Error(`${what}: not a GLB (no "glTF" magic)`);
  const length = view.getUint32(8, true);
  if (length > bytes)
    throw new Error(`${what}: truncated: its header says ${length} bytes, ${bytes} arrived`);
  for (let at = 12; at < length; ) {
    if (at + 8 > length) throw new Error(`${what}: truncated chunk header at byte ${at}`);
    const chunk = view.getUint32(at, true);
    if (at + 8 + chunk > length)
      throw new Error(`${what}: truncated: a chunk of ${chunk} bytes at byte ${at} runs past the end`);
    at += 8 + chunk;
  }
  return buffer;
}

// Fetches a GLB, checks it (checkGlb) and parses it with `loader` (a GLTFLoader with the plugin).
export async function loadGlb(loader, url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  const buffer = checkGlb(await response.arrayBuffer(), url);
  const base = new URL('./', new URL(url, globalThis.location?.href)).href;
  return loader.parseAsync(buffer, base);
}

// Coefficient k's decode as texels (k, 0) and (k, 1) of an RGBA32F texture: scale (times 255, as
// UNORM texels are code / 255) and offset, per channel.
function weightRangeTexture(r, K, name) {
  const range = new Float32Array(2 * 4 * K);
  for (let i = 0; i < 4 * K; ++i) {
    range[i] = r.scale[i] * 255;
    range[4 * K + i] = r.offset[i];
  }
  const tex = new THREE.DataTexture(range, K, 2, THREE.RGBAFormat, THREE.FloatType);
  tex.internalFormat = 'RGBA32F';
  tex.minFilter = tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.needsUpdate = true;
  tex.name = `${name} weight range`;
  return tex;
}

function halfView(buffer, byteOffset, count) {
  // Copies: a bufferView's offset need not be aligned to the element size.
  const out = new Uint16Array(count);
  new Uint8Array(out.buffer).set(new Uint8Array(buffer, byteOffset, count * 2));
  return out;
}

function floatView(buffer, byteOffset, count) {
  const out = new Float32Array(count);
  new Uint8Array(out.buffer).set(new Uint8Array(buffer, byteOffset, count * 4));
  return out;
}

// Bytes a refraction's textures take on the GPU at the formats they are uploaded in (the RGBA8
// weight pages as layers of the largest page's size, the RGBA32F weight range, R32F error layers),
// and its mesh's vertex and index buffers.
export function gpuBytes(refraction, mesh = null) {
  let textures = refraction.weightRange.image.width * refraction.weightRange.image.height * 16;
  const { width, height, depth } = pageLayers(refraction.pages);
  textures += width * height * depth * 4;
  if (refraction.error) {
    const e = refraction.error.texture.image;
    textures += e.width * e.height * e.depth * 4;
  }
  let buffers = 0;
  if (mesh) {
    for (const a of Object.values(mesh.geometry.attributes)) buffers += a.array.byteLength;
    if (mesh.geometry.index) buffers += mesh.geometry.index.array.byteLength;
  }
  return { textures, buffers, total: textures + buffers };
}

export class SHRefractionLoaderPlugin {
  constructor(parser, options = {}) {
    this.name = EXTENSION;
    this.parser = parser;
    this.options = options;  // { environment: the app's own, maxTextureSize }
  }

  // The bytes of bufferView `index`, checked against its buffer.
  async bufferView(index, what) {
    const json = this.parser.json;
    const view = (json.bufferViews || [])[index];
    if (!view) throw fail(`${what} names bufferView ${index}, which the file lacks`);
    const buffer = (json.buffers || [])[view.buffer];
    const body = this.parser.extensions.KHR_binary_glTF?.body;
    if (buffer && buffer.uri === undefined && body && body.byteLength < buffer.byteLength)
      throw fail(`the binary chunk holds ${body.byteLength} bytes, the buffer ${buffer.byteLength} (truncated file?)`);
    return this.parser.getDependency('bufferView', index);
  }

  // Texture index t as exact data: no colour space, no premultiplication, no flip, NEAREST.
  async weightPage(t, what) {
    const json = this.parser.json;
    const texture = (json.textures || [])[t];
    if (!texture) throw fail(`${what} names texture ${t}, which the file lacks`);
    const image = (json.images || [])[texture.source];
    if (!image) throw fail(`${what}: texture ${t} names image ${texture.source}, which the file lacks`);
    let blob;
    if (image.bufferView !== undefined) {
      const data = await this.bufferView(image.bufferView, `${what} (image ${texture.source})`);
      blob = new Blob([data], { type: image.mimeType || 'image/png' });
    } else if (image.uri !== undefined) {
      const url = THREE.LoaderUtils.resolveURL(image.uri, this.parser.options.path);
      const response = await fetch(url);
      if (!response.ok) throw fail(`${what}: image ${image.uri}: HTTP ${response.status}`);
      blob = await response.blob();
    } else {
      throw fail(`${what}: image ${texture.source} has neither bufferView nor uri`);
    }
    let bitmap;
    try {
      bitmap = await createImageBitmap(blob, {
        premultiplyAlpha: 'none', colorSpaceConversion: 'none', imageOrientation: 'from-image',
      });
    } catch (e) {
      throw fail(`${what}: image ${texture.source} does not decode (${e.message})`);
    }
    const tex = new THREE.Texture(bitmap);
    tex.flipY = false;
    tex.premultiplyAlpha = false;
    tex.colorSpace = THREE.NoColorSpace;
    tex.generateMipmaps = false;
    tex.minFilter = THREE.NearestFilter;
    tex.magFilter = THREE.NearestFilter;
    tex.wrapS = tex.wrapT = THREE.ClampToEdgeWrapping;
    tex.needsUpdate = true;
    tex.name = `${what} page`;
    return tex;
  }

  async refraction(r, index, version) {
    const what = `refraction ${index}${r.name ? ` ("${r.name}")` : ''}`;
    for (const key of ['order', 'coefficientCount', 'sampleCount', 'tileSize', 'tilesPerRow',
                       'tilesPerPage', 'weights', 'scale', 'offset', 'ior', 'absorption', 'boundsDiagonal'])
      if (r[key] === undefined) throw fail(`${what} lacks "${key}"`);
    const basis = r.basis ?? 'sh';
    if (basis !== 'sh' && (version < 2 || basis !== 'grid'))
      throw fail(`${what}: basis ${JSON.stringify(r.basis)} (version ${version} knows ${version < 2 ? '"sh"' : '"sh" and "grid"'})`);
    let K = (r.order + 1) * (r.order + 2) / 2, grid = null;
    if (basis === 'grid') {
      // [nTheta, nPhi]: nPhi even, as grid_eval.glsl crosses the pole at phi + pi.
      grid = r.grid;
      if (!Array.isArray(grid) || grid.length !== 2 || !grid.every(Number.isInteger) || !(grid[0] >= 2) ||
          !(grid[1] >= 2) || grid[1] % 2)
        throw fail(`${what}: a grid basis needs "grid": [nTheta, nPhi], integers >= 2, nPhi even; it has ${JSON.stringify(grid)}`);
      K = grid[0] * grid[1];
      if (r.coefficientCount !== K) throw fail(`${what}: coefficientCount ${r.coefficientCount}, grid ${grid.join('x')} has ${K}`);
    } else if (r.coefficientCount !== K) {
      throw fail(`${what}: coefficientCount ${r.coefficientCount}, order ${r.order} has ${K}`);
    }
    const [W, H] = r.tileSize;
    if (!(W * H >= r.sampleCount)) throw fail(`${what}: tiles of ${W} x ${H} cannot hold ${r.sampleCount} samples`);
    if (r.scale.length !== 4 * K || r.offset.length !== 4 * K)
      throw fail(`${what}: scale and offset need ${4 * K} numbers each`);
    const pages = Math.ceil(K / r.tilesPerPage);
    if (r.weights.length < pages) throw fail(`${what}: ${K} coefficients need ${pages} weight pages, it lists ${r.weights.length}`);
    // The material holds the pages as layers of one array texture: WebGL 2 guarantees 256.
    if (pages > 256) throw fail(`${what}: ${pages} weight pages, above the 256 array layers WebGL 2 guarantees`);
    const maxSize = this.options.maxTextureSize ?? 4096;
    const textures = await Promise.all(r.weights.slice(0, pages).map((t, p) => this.weightPage(t, `${what} weights[${p}]`)));
    for (const [p, tex] of textures.entries()) {
      const { width, height } = tex.image;
      if (width > maxSize || height > maxSize)
        throw fail(`${what}: weight page ${p} is ${width} x ${height}, above the texture size limit ${maxSize}`);
      const tiles = Math.min(r.tilesPerPage, K - p * r.tilesPerPage);
      const rows = Math.ceil(tiles / r.tilesPerRow), columns = Math.min(tiles, r.tilesPerRow);
      if (width < columns * W)
        throw fail(`${what}: weight page ${p} is ${width} texels wide, its tiles need ${columns * W}`);
      if (height < rows * H) throw fail(`${what}: weight page ${p} is ${height} texels high, its tiles need ${rows * H}`);
    }
    let error = null;
    if (r.error) {
      const e = r.error;
      const Ke = (e.order + 1) * (e.order + 2) / 2;
      if (e.coefficientCount !== Ke) throw fail(`${what}: error coefficientCount ${e.coefficientCount}, order ${e.order} has ${Ke}`);
      if (basis === 'sh' && e.order > r.order) throw fail(`${what}: error order ${e.order} above the weights' ${r.order}`);
      const data = await this.bufferView(e.bufferView, `${what} error`);
      const n = r.sampleCount;
      if (data.byteLength < Ke * n * 4)
        throw fail(`${what}: the error bufferView holds ${data.byteLength} bytes, ${Ke} x ${n} floats need ${Ke * n * 4}`);
      const values = floatView(data, 0, Ke * n);
      const layers = new Float32Array(W * H * Ke);  // one W x H layer per coefficient, the tile layout
      for (let k = 0; k < Ke; ++k) layers.set(values.subarray(k * n, (k + 1) * n), k * W * H);
      const tex = new THREE.DataArrayTexture(layers, W, H, Ke);
      tex.format = THREE.RedFormat;
      tex.type = THREE.FloatType;
      tex.internalFormat = 'R32F';
      tex.minFilter = tex.magFilter = THREE.NearestFilter;
      tex.generateMipmaps = false;
      tex.unpackAlignment = 1;
      tex.needsUpdate = true;
      error = { order: e.order, coefficientCount: Ke, offset: e.offset, texture: tex };
    }
    return {
      name: r.name ?? `refraction ${index}`, basis, grid,
      order: basis === 'grid' ? 0 : r.order, coefficientCount: K, sampleCount: r.sampleCount,
      tileSize: [W, H], tilesPerRow: r.tilesPerRow, tilesPerPage: r.tilesPerPage,
      pages: textures, scale: r.scale, offset: r.offset, weightRange: weightRangeTexture(r, K, what), error,
      ior: r.ior, absorption: r.absorption, boundsDiagonal: r.boundsDiagonal, branch: r.branch,
    };
  }

  async environment(e, index) {
    const what = `environment ${index}${e.name ? ` ("${e.name}")` : ''}`;
    for (const key of ['faceSize', 'levels', 'bufferView'])
      if (e[key] === undefined) throw fail(`${what} lacks "${key}"`);
    const data = await this.bufferView(e.bufferView, what);
    let halves = 0;
    for (let l = 0; l < e.levels; ++l) halves += 6 * 4 * Math.max(1, e.faceSize >> l) ** 2;
    if (data.byteLength < halves * 2)
      throw fail(`${what}: its bufferView holds ${data.byteLength} bytes, ${e.levels} levels of ${e.faceSize}^2 faces need ${halves * 2}`);
    const faces = [0, 1, 2, 3, 4, 5].map(() => ({ mipmaps: [], width: e.faceSize, height: e.faceSize }));
    let at = 0;
    for (let l = 0; l < e.levels; ++l) {
      const s = Math.max(1, e.faceSize >> l);
      for (let f = 0; f < 6; ++f) {
        faces[f].mipmaps.push({ data: halfView(data, at * 2, s * s * 4), width: s, height: s });
        at += s * s * 4;
      }
    }
    const tex = new THREE.CompressedCubeTexture(faces, THREE.RGBAFormat, THREE.HalfFloatType);
    tex.minFilter = THREE.LinearMipmapLinearFilter;
    tex.magFilter = THREE.LinearFilter;
    tex.generateMipmaps = false;
    tex.wrapS = tex.wrapT = THREE.ClampToEdgeWrapping;
    tex.colorSpace = THREE.NoColorSpace;
    tex.needsUpdate = true;
    tex.name = what;
    return { name: e.name ?? `environment ${index}`, faceSize: e.faceSize, levels: e.levels, texture: tex };
  }

  async afterRoot(result) {
    const root = this.parser.json.extensions?.[EXTENSION];
    const used = this.parser.json.extensionsUsed || [];
    if (!root) {
      if (used.includes(EXTENSION)) throw fail('listed in extensionsUsed but the root holds no extension object');
      return;
    }
    if (!VERSIONS.includes(root.version))
      throw fail(`version ${JSON.stringify(root.version)}; this loader reads versions ${VERSIONS.join(' and ')}`);
    const refractions = await Promise.all((root.refractions || []).map((r, i) => this.refraction(r, i, root.version)));
    const environments = await Promise.all((root.environments || []).map((e, i) => this.environment(e, i)));
    const environment = this.options.environment ?? environments[0] ?? null;
    const materials = [];
    const meshes = [];
    // An environment-only file has no scene.
    for (const scene of result.scenes || []) scene.traverse((object) => {
      if (!object.isMesh) return;
      const assoc = this.parser.associations.get(object);
      if (!assoc || assoc.meshes === undefined) return;
      const primitive = this.parser.json.meshes[assoc.meshes].primitives[assoc.primitives ?? 0];
      const ext = primitive?.extensions?.[EXTENSION];
      if (!ext) return;
      const refraction = refractions[ext.refraction];
      if (!refraction) throw fail(`mesh ${assoc.meshes} names refraction ${ext.refraction}, which the file lacks`);
      const samples = object.geometry.attributes._shrefract_sample;
      if (!samples) throw fail(`mesh ${assoc.meshes}: no _SHREFRACT_SAMPLE attribute (which sample each vertex is)`);
      for (let v = 0; v < samples.count; ++v) {
        const i = samples.getX(v);
        if (!(i >= 0 && i < refraction.sampleCount && Number.isInteger(i)))
          throw fail(`mesh ${assoc.meshes}: vertex ${v} names sample ${i}, refraction ${ext.refraction} has ${refraction.sampleCount}`);
      }
      let bakeFromLocal = null;
      if (ext.bakeFromLocal !== undefined) {
        if (!Array.isArray(ext.bakeFromLocal) || ext.bakeFromLocal.length !== 16 || !ext.bakeFromLocal.every(Number.isFinite))
          throw fail(`mesh ${assoc.meshes}: bakeFromLocal must be 16 numbers`);
        bakeFromLocal = new THREE.Matrix4().fromArray(ext.bakeFromLocal);  // column-major, as glTF
      }
      const material = new SHRefractionMaterial({ refraction, environment, bakeFromLocal, ...(this.options.material || {}) });
      object.material = material;
      object.frustumCulled = false;
      materials.push(material);
      meshes.push(object);
    });
    result.userData.shRefraction = { refractions, environments, materials, meshes };
  }
}
