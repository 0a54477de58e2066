// SHRefractionMaterial: the C++ runtime's direct path with vertex decompression and the error
// model folded per vertex (shaders/web_shade.vert), shaded by the C++ runtime's own fragment
// shader (shaders/shade.frag with SHREFRACT_DIRECT, shaders/shading.glsl). Options mirror
// RefractorOptions (runtime/include/shrefract/runtime.h); docs/web.md says what differs.
import * as THREE from 'three';
import { shaderSource } from './generated/shaders.js';
import { environmentUniforms, setEnvironmentUniforms, withoutVersion } from './environment.js';
import { pageLayers } from './pages.js';

const SHADINGS = ['auto', 'jitter', 'spread', 'blend', 'sharp'];

// Auto: the shading measured best for the bake's basis, as the C++ Refractor's (docs/runtime.md
// "Shading where the bake is unsure"): blend on a grid, jitter on SH.
export function resolveShading(shading, refraction) {
  if (shading !== 'auto') return shading;
  return refraction.basis === 'grid' ? 'blend' : 'jitter';
}

// Taps -1: the lookups per pixel measured best for the bake's basis, as the C++ Refractor's
// (docs/runtime.md "Four taps"): 4 on a grid, 1 on SH.
export function resolveTaps(taps, refraction) {
  if (taps === -1) return refraction.basis === 'grid' ? 4 : 1;
  if (taps !== 1 && taps !== 4) throw new Error(`SHRefractionMaterial: taps ${taps}: 1, 4 or -1 (by the bake's basis)`);
  return taps;
}

const _m3 = new THREE.Matrix3();
const _m4 = new THREE.Matrix4();
const _v3 = new THREE.Vector3();
const _model = new THREE.Matrix4();

// The atlas pages as the layers of one RGBA8 array texture, so that a bake may have as many pages
// as WebGL 2 has layers (256 at least; the loader checks). The pages are decoded images (exact:
// no premultiplication, no colour conversion), which three.js copies into the layers on the GPU
// (copyTextureToTexture) at the first draw: allocated here, filled by copyPagesOnce. One array per
// refraction, shared by the materials that draw it (a scene's primitives of one bake).
const _weightPages = new WeakMap();
function weightPages(refraction) {
  if (_weightPages.has(refraction)) return _weightPages.get(refraction);
  const { width, height, depth } = pageLayers(refraction.pages);
  const array = new THREE.DataArrayTexture(null, width, height, depth);
  array.format = THREE.RGBAFormat;
  array.type = THREE.UnsignedByteType;
  array.internalFormat = 'RGBA8';
  array.minFilter = array.magFilter = THREE.NearestFilter;
  array.generateMipmaps = false;
  array.source.dataReady = false;  // storage only: the layers come from the pages
  array.needsUpdate = true;
  array.name = 'weight pages';
  _weightPages.set(refraction, array);
  return array;
}

// Fills the array's layers from the pages, once per renderer and GL context. A lost and restored
// context allocates the array afresh (empty), so a renderer's 'webglcontextrestored' forgets what
// it had copied and the next draw copies again.
const _copied = new WeakMap();  // renderer -> the arrays whose layers its context holds
function copyPagesOnce(renderer, pages, array) {
  let copied = _copied.get(renderer);
  if (!copied) {
    copied = new WeakSet();
    _copied.set(renderer, copied);
    renderer.domElement.addEventListener?.('webglcontextrestored', () => _copied.delete(renderer));
  }
  if (copied.has(array)) return;
  const at = new THREE.Vector3();
  pages.forEach((page, p) => renderer.copyTextureToTexture(page, array, null, at.set(0, 0, p)));
  copied.add(array);
}

export class SHRefractionMaterial extends THREE.RawShaderMaterial {
  // refraction: what SHRefractionLoaderPlugin read (result.userData.shRefraction.refractions[i]);
  // environment: an environment it read (from this file or an environment-only one).
  constructor({
    refraction, environment = null, shading = 'auto', order = -1, spreadScale = 0.15,
    footprintScale = 0.15, taps = -1, jitterCell = 0.005, jitterGate = 0.05, blendSigma = 0.1,
    errorModel = true, toneMap = true, exposure = 1.0, absorption = null, bakeFromLocal = null,
  } = {}) {
    if (!refraction) throw new Error('SHRefractionMaterial: no refraction');
    const r = refraction;
    const useError = !!(errorModel && r.error);
    // Room for the SH through the weights' order and the error model's, whichever is larger.
    const maxOrder = Math.max(r.order, useError ? r.error.order : 0);
    const defines = { SHREFRACT_SH_MAX_ORDER: maxOrder };
    if (r.basis === 'grid') [defines.SHREFRACT_GRID_THETA, defines.SHREFRACT_GRID_PHI] = r.grid;
    if (useError) defines.SHREFRACT_ERROR_MODEL = '';
    const uniforms = {
      uBakeFromLocal: { value: new THREE.Matrix4() },
      uBakeNormal: { value: new THREE.Matrix3() },
      uModel: { value: new THREE.Matrix4() },
      uViewProjection: { value: new THREE.Matrix4() },
      uNormalMatrix: { value: new THREE.Matrix3() },
      uModelRotation: { value: new THREE.Matrix3() },
      uEyeObject: { value: new THREE.Vector3() },
      uEye: { value: new THREE.Vector3() },
      uOrder: { value: r.order },
      uTileSize: { value: new THREE.Vector2(r.tileSize[0], r.tileSize[1]) },
      uTilesPerRow: { value: r.tilesPerRow },
      uTilesPerPage: { value: r.tilesPerPage },
      uWeightRange: { value: r.weightRange },
      uWeightPages: { value: weightPages(r) },
      uErrors: { value: r.error ? r.error.texture : null },
      uErrorOrder: { value: r.error ? r.error.order : 0 },
      uErrorOffset: { value: r.error ? r.error.offset : 0.01 },
      uEta: { value: r.ior },
      uKappa: { value: new THREE.Vector3() },
      uToneMap: { value: true },
      uExposure: { value: 1 },
      uSpread: { value: true },
      uSpreadScale: { value: spreadScale },
      uBlendSigma: { value: 0 },
      uJitterCell: { value: 0 },
      uJitterGate: { value: jitterGate },
      uFootprintScale: { value: footprintScale },
      uTaps: { value: 1 },
      ...environmentUniforms(),
    };
    super({
      glslVersion: THREE.GLSL3,
      vertexShader: withoutVersion(shaderSource('web_shade.vert', defines)),
      fragmentShader: withoutVersion(shaderSource('shade.frag', { SHREFRACT_DIRECT: '', SHREFRACT_COLOR_ONLY: '' })),
      uniforms,
    });
    this.name = `SHRefractionMaterial (${r.name})`;
    this.refraction = r;
    this.errorModel = useError;
    this.shading = shading;
    this.order = order;
    this.spreadScale = spreadScale;
    this.footprintScale = footprintScale;
    this.taps = taps;
    this.jitterCell = jitterCell;
    this.jitterGate = jitterGate;  // radians; 0: ungated (docs/runtime.md "The gate")
    this.blendSigma = blendSigma;
    this.toneMap = toneMap;
    this.exposure = exposure;
    this.absorption = absorption;  // [r, g, b] kappa instead of the bake's, or null
    this.environment = environment;
    // The primitive's coordinates -> the bake's (docs/format.md "bakeFromLocal"); identity: null.
    this.bakeFromLocal = bakeFromLocal ? bakeFromLocal.clone() : new THREE.Matrix4();
  }

  // Per draw: the uniforms the C++ Refractor::draw and FrameUniforms set.
  onBeforeRender(renderer, scene, camera, geometry, object) {
    copyPagesOnce(renderer, this.refraction.pages, this.uniforms.uWeightPages.value);
    if (!SHADINGS.includes(this.shading)) throw new Error(`SHRefractionMaterial: shading "${this.shading}": ${SHADINGS.join(' | ')}`);
    if (!(this.jitterGate >= 0)) {
      throw new Error(`SHRefractionMaterial: jitterGate ${this.jitterGate}: 0 (ungated) or more radians`);
    }
    const u = this.uniforms, r = this.refraction;
    // The shader works in the bake's space: positions and normals go there by bakeFromLocal, and
    // from there to the world by matrixWorld * bakeFromLocal^-1.
    u.uBakeFromLocal.value.copy(this.bakeFromLocal);
    u.uBakeNormal.value.getNormalMatrix(this.bakeFromLocal);
    const model = _model.copy(object.matrixWorld).multiply(_m4.copy(this.bakeFromLocal).invert());
    u.uModel.value.copy(model);
    u.uViewProjection.value.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    u.uNormalMatrix.value.getNormalMatrix(model);
    u.uModelRotation.value.setFromMatrix4(model);
    _v3.setFromMatrixPosition(camera.matrixWorld);
    u.uEye.value.copy(_v3);
    u.uEyeObject.value.copy(_v3).applyMatrix4(_m4.copy(model).invert());
    u.uOrder.value = this.order < 0 ? r.order : Math.min(this.order, r.order);
    const kappa = this.absorption ?? r.absorption;
    u.uKappa.value.set(kappa[0], kappa[1], kappa[2]);
    u.uToneMap.value = !!this.toneMap;
    u.uExposure.value = this.exposure;
    u.uSpreadScale.value = this.spreadScale;
    const shading = resolveShading(this.shading, r);
    u.uSpread.value = shading !== 'sharp';
    u.uBlendSigma.value = shading === 'blend' ? this.blendSigma : 0;
    u.uJitterCell.value = shading === 'jitter' ? this.jitterCell * r.boundsDiagonal : 0;
    u.uJitterGate.value = this.jitterGate;
    u.uFootprintScale.value = this.footprintScale;
    u.uTaps.value = resolveTaps(this.taps, r);
    setEnvironmentUniforms(u, this.environment);
    this.uniformsNeedUpdate = true;
  }
}
