// The test page of scripts/bench-web: one glass mesh (from a GLB written by shrefract-export) drawn
// by SHRefractionMaterial, drei's MeshRefractionMaterial (vanilla three.js, no React) and three's
// MeshPhysicalMaterial with transmission, under one camera and one environment, into one float
// render target. The driver (web/bench/run.js) calls window.bench: load, use, view, time, capture.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshBVH, MeshBVHUniformStruct, SAH } from 'three-mesh-bvh';
import { MeshRefractionMaterial } from 'drei/materials/MeshRefractionMaterial.js';
import { SHRefractionLoaderPlugin, SHRefractionBackground, loadGlb } from 'shrefract-web';

// drei 10.7.9's MeshRefractionMaterial includes <cube_uv_reflection_fragment>, a chunk three 0.187
// no longer has (its PMREM is a cube map now). Its cube-map path (ENVMAP_TYPE_CUBEM, used here)
// calls nothing from it, so an empty chunk lets the shader compile unchanged.
if (THREE.ShaderChunk.cube_uv_reflection_fragment === undefined) THREE.ShaderChunk.cube_uv_reflection_fragment = '';

const state = { renderer: null, scene: null, camera: null, target: null, mesh: null, materials: {} };

function loader() {
  const l = new GLTFLoader();
  l.register((parser) => new SHRefractionLoaderPlugin(parser, {
    maxTextureSize: state.renderer.capabilities.maxTextureSize,
    // Linear output: every method is tone mapped alike from the float target (capture()).
    material: { toneMap: false },
  }));
  return l;
}

// Mean chord length of a closed mesh, 4 V / S (Cauchy): the thickness MeshPhysicalMaterial's
// single-interface model is given.
function meanChord(geometry) {
  const p = geometry.attributes.position, index = geometry.index;
  const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3(), n = new THREE.Vector3();
  let volume = 0, area = 0;
  for (let t = 0; t < index.count; t += 3) {
    a.fromBufferAttribute(p, index.getX(t));
    b.fromBufferAttribute(p, index.getX(t + 1));
    c.fromBufferAttribute(p, index.getX(t + 2));
    volume += a.dot(n.copy(b).cross(c)) / 6;
    area += n.copy(b).sub(a).cross(c.clone().sub(a)).length() / 2;
  }
  return { volume: Math.abs(volume), area, chord: 4 * Math.abs(volume) / area };
}

// Loads the object (and environment) GLBs and makes the three materials. size: [w, h].
async function load({ glb, env, size, exposure = 1 }) {
  const [width, height] = size;
  const canvas = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height);
  state.renderer = renderer;
  state.size = size;
  state.target = new THREE.WebGLRenderTarget(width, height, { type: THREE.FloatType, depthBuffer: true });
  state.scene = new THREE.Scene();
  state.camera = new THREE.PerspectiveCamera(45, width / height, 0.01, 100);
  // The environment: the object GLB's own (shrefract-export --environment), or a second GLB's.
  const gltf = await loadGlb(loader(), glb);
  const environment = env ? (await loadGlb(loader(), env)).userData.shRefraction.environments[0]
                          : gltf.userData.shRefraction.environments[0];
  if (!environment) throw new Error(`${glb}: no environment (export it with --environment ENV.exr)`);
  const sh = gltf.userData.shRefraction.materials[0];
  sh.environment = environment;
  const mesh = gltf.userData.shRefraction.meshes[0];
  state.background = new SHRefractionBackground(environment, { toneMap: false, exposure });
  state.scene.add(state.background);
  state.scene.add(gltf.scene);
  state.mesh = mesh;
  state.exposure = exposure;

  // drei: what its React wrapper (core/MeshRefractionMaterial.js) does, without React: the BVH of
  // the non-indexed geometry (SAH), the cube-map defines, the camera matrices every frame.
  const cube = environment.texture;
  const faceWidth = cube.image[0].width, lodMax = Math.floor(Math.log2(faceWidth / 4));
  const drei = new MeshRefractionMaterial();
  drei.defines = {
    ENVMAP_TYPE_CUBEM: '',
    CUBEUV_TEXEL_WIDTH: `${1 / (3 * Math.max(2 ** lodMax, 112))}`,
    CUBEUV_TEXEL_HEIGHT: `${1 / (4 * 2 ** lodMax)}`,
    CUBEUV_MAX_MIP: `${lodMax}.0`,
  };
  drei.bvh = new MeshBVHUniformStruct();
  drei.bvh.updateFrom(new MeshBVH(mesh.geometry.clone().toNonIndexed(), { strategy: SAH }));
  drei.envMap = cube;
  drei.ior = sh.refraction.ior;
  drei.fresnel = 0;
  drei.aberrationStrength = 0;
  drei.resolution = new THREE.Vector2(width, height);
  drei.onBeforeRender = (r, s, camera) => {
    drei.viewMatrixInverse = camera.matrixWorld;
    drei.projectionMatrixInverse = camera.projectionMatrixInverse;
  };

  // MeshPhysicalMaterial: the environment as three's PMREM of the same cube map. three mirrors x
  // when it reads a cube texture that is no render target (the skybox convention); this one holds
  // GL-order faces as the runtime samples them, so it is flagged as one for the conversion only.
  const pmrem = new THREE.PMREMGenerator(renderer);
  cube.isRenderTargetTexture = true;
  const envMap = pmrem.fromCubemap(cube).texture;
  cube.isRenderTargetTexture = false;
  const shape = meanChord(mesh.geometry);
  const physical = new THREE.MeshPhysicalMaterial({
    color: 0xffffff, metalness: 0, roughness: 0, transmission: 1, ior: sh.refraction.ior,
    thickness: shape.chord, envMap, envMapIntensity: 1, specularIntensity: 1,
  });
  state.materials = { sh, drei, physical };
  return {
    vertices: mesh.geometry.attributes.position.count, triangles: mesh.geometry.index.count / 3,
    ior: sh.refraction.ior, order: sh.refraction.order, branch: sh.refraction.branch,
    thickness: shape.chord, volume: shape.volume, area: shape.area,
    renderer: renderer.getContext().getParameter(renderer.getContext().VERSION),
    gpu: (() => {
      const gl = renderer.getContext(), ext = gl.getExtension('WEBGL_debug_renderer_info');
      return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    })(),
  };
}

// method: {kind: 'sh', order, shading} | {kind: 'drei', bounces} | {kind: 'physical'}.
function use(method) {
  const m = state.materials;
  if (method.kind === 'sh') {
    m.sh.order = method.order;
    m.sh.shading = method.shading;
    state.mesh.material = m.sh;
  } else if (method.kind === 'drei') {
    m.drei.bounces = method.bounces;
    state.mesh.material = m.drei;
  } else if (method.kind === 'physical') {
    state.mesh.material = m.physical;
  } else {
    throw new Error(`unknown method ${JSON.stringify(method)}`);
  }
}

// shrefract-render's --camera orbit:AZ,EL,DIST (runtime/src/render.cpp Camera::orbit) and its
// projection: glm::perspective, 45 degrees vertical, clip planes at DIST / 100 and DIST x 100.
function view(az, el, dist) {
  const c = state.camera, a = THREE.MathUtils.degToRad(az), e = THREE.MathUtils.degToRad(el);
  c.near = dist / 100;
  c.far = dist * 100;
  c.updateProjectionMatrix();
  c.position.set(dist * Math.cos(e) * Math.sin(a), dist * Math.sin(e), dist * Math.cos(e) * Math.cos(a));
  c.up.set(0, 1, 0);
  c.lookAt(0, 0, 0);
  c.updateMatrixWorld();
}

const pixel = new Float32Array(4);

// One frame into the float target, finished: readPixels of one texel waits for every command
// before it (the GPU process answers only once the frame is drawn).
function frame() {
  const r = state.renderer;
  r.setRenderTarget(state.target);
  r.render(state.scene, state.camera);
  r.readRenderTargetPixels(state.target, 0, 0, 1, 1, pixel);
  r.setRenderTarget(null);
}

// The wall time of `count` frames, each in ms.
function time(count = 1) {
  const ms = [];
  for (let i = 0; i < count; ++i) {
    const t0 = performance.now();
    frame();
    ms.push(performance.now() - t0);
  }
  return ms;
}

// common/tonemap.h toneMapAces: exposure, the Narkowicz ACES fit clamped to [0, 1], sRGB.
function toneMap(x) {
  x *= state.exposure;
  const a = Math.min(1, Math.max(0, (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)));
  return a <= 0.0031308 ? 12.92 * a : 1.055 * Math.pow(a, 1 / 2.4) - 0.055;
}

// The frame tone mapped to 8-bit RGB, row 0 at the top, as a base64 string.
function capture() {
  frame();
  const [w, h] = state.size;
  const data = new Float32Array(w * h * 4);
  state.renderer.readRenderTargetPixels(state.target, 0, 0, w, h, data);
  const out = new Uint8Array(w * h * 3);
  for (let y = 0; y < h; ++y)
    for (let x = 0; x < w; ++x) {
      const s = 4 * ((h - 1 - y) * w + x), d = 3 * (y * w + x);
      for (let c = 0; c < 3; ++c) out[d + c] = Math.round(255 * toneMap(data[s + c]));
    }
  let text = '';
  for (let i = 0; i < out.length; i += 8192) text += String.fromCharCode(...out.subarray(i, i + 8192));
  return btoa(text);
}

window.bench = { load, use, view, time, capture, state };
window.benchReady = true;
