// The example: ?glb=OBJECT.glb (a bake written by shrefract-export) &env=ENV.glb (an
// environment-only GLB, shrefract-export --environment ENV.exr -o ENV.glb) &envs=A.glb,B.glb
// (the choice offered); OrbitControls, the frame rate. The browser tests drive it too:
// &size=WxH fixes the canvas, &camera=AZ,EL,DIST (shrefract-render's orbit) &target=x,y,z, &fov=deg,
// &static=1 draws on demand only, &shading=, &order=, &errorModel=0, &exposure=.
// window.shrefract tells the state: 'loading' | 'ready' | 'error', and the first frame's time.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { SHRefractionLoaderPlugin, SHRefractionBackground, loadGlb, gpuBytes } from 'shrefract-web';

const params = new URLSearchParams(location.search);
const state = (window.shrefract = { state: 'loading', error: null, firstFrameMs: null, frames: 0 });
const errorBox = document.getElementById('error');
const statusBox = document.getElementById('status');

function showError(e) {
  const message = e && e.message ? e.message : String(e);
  state.state = 'error';
  state.error = message;
  errorBox.textContent = message;
  statusBox.textContent = 'error';
}
window.addEventListener('unhandledrejection', (event) => { showError(event.reason); event.preventDefault(); });

const canvas = document.getElementById('view');
const [width, height] = (params.get('size') || `${innerWidth}x${innerHeight}`).split('x').map(Number);
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: params.has('static') });
renderer.setPixelRatio(1);
renderer.setSize(width, height);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(Number(params.get('fov') || 45), width / height);
// shrefract-render's --camera orbit:AZ,EL,DIST around the origin (Camera::orbit), with its clip
// planes at distance / 100 and x 100 (projectionMatrix in runtime/src/render.cpp).
// &target=x,y,z orbits that point instead (shrefract-render --eye E --target T, E the orbit's eye).
const target = new THREE.Vector3(...(params.get('target') || '0,0,0').split(',').map(Number));
function orbit(az, el, distance) {
  const a = THREE.MathUtils.degToRad(az), e = THREE.MathUtils.degToRad(el);
  camera.position.set(distance * Math.cos(e) * Math.sin(a), distance * Math.sin(e), distance * Math.cos(e) * Math.cos(a));
  camera.position.add(target);
  camera.near = 1e-2 * distance;
  camera.far = 1e2 * distance;
  camera.updateProjectionMatrix();
  camera.lookAt(target);
  camera.updateMatrixWorld();
}
orbit(...(params.get('camera') || '30,20,3').split(',').map(Number));
const controls = params.has('static') ? null : new OrbitControls(camera, canvas);
const background = new SHRefractionBackground(null, { exposure: Number(params.get('exposure') || 1) });
scene.add(background);

const environments = new Map();  // url -> environment
let materials = [];

function loader() {
  const l = new GLTFLoader();
  l.register((parser) => new SHRefractionLoaderPlugin(parser, {
    maxTextureSize: renderer.capabilities.maxTextureSize,
    material: {
      shading: params.get('shading') || 'auto',
      order: params.has('order') ? Number(params.get('order')) : -1,
      errorModel: params.get('errorModel') !== '0',
      exposure: Number(params.get('exposure') || 1),
    },
  }));
  return l;
}

async function environment(url) {
  if (!environments.has(url)) {
    const gltf = await loadGlb(loader(), url);
    const env = gltf.userData.shRefraction?.environments?.[0];
    if (!env) throw new Error(`${url}: holds no SHREFRACT_sh_refraction environment`);
    environments.set(url, env);
  }
  return environments.get(url);
}

function useEnvironment(env) {
  background.environment = env;
  for (const m of materials) m.environment = env;
  // The scene's other objects (a glTF scene written back with shrefract-export --into) are lit by
  // the same environment, through three's own image-based lighting.
  scene.environment = env ? env.texture : null;
}

// Draws one frame; never throws (the loop must survive a bad frame): errors go to the page.
function frame() {
  try {
    controls?.update();
    renderer.render(scene, camera);
    state.frames += 1;
  } catch (e) {
    showError(e);
  }
}
state.render = frame;

let last = performance.now(), count = 0;
const fpsBox = document.getElementById('fps');
function loop() {
  frame();
  count += 1;
  const now = performance.now();
  if (now - last > 1000) {
    fpsBox.textContent = `${(count * 1000 / (now - last)).toFixed(1)} fps`;
    last = now;
    count = 0;
  }
}

async function main() {
  const envUrls = (params.get('envs') || params.get('env') || '').split(',').filter(Boolean);
  const select = document.getElementById('env');
  for (const url of envUrls) select.append(new Option(url.split('/').pop().replace(/\.glb$/, ''), url));
  if (params.get('env')) select.value = params.get('env');
  select.onchange = () => environment(select.value).then(useEnvironment).catch(showError);
  const shading = document.getElementById('shading');
  shading.value = params.get('shading') || 'auto';
  shading.onchange = () => { for (const m of materials) m.shading = shading.value; };

  const [gltf, env] = await Promise.all([
    params.get('glb') ? loadGlb(loader(), params.get('glb')) : null,
    select.value ? environment(select.value) : null,
  ]);
  if (gltf) {
    scene.add(gltf.scene);
    materials = gltf.userData.shRefraction?.materials || [];
    if (!materials.length) throw new Error(`${params.get('glb')}: no primitive names a SHREFRACT_sh_refraction refraction`);
    const { meshes } = gltf.userData.shRefraction;
    state.gpuBytes = gpuBytes(materials[0].refraction, meshes[0]);
  }
  useEnvironment(env ?? gltf?.userData.shRefraction?.environments?.[0] ?? null);
  if (!background.environment) throw new Error('no environment: give &env=ENV.glb');
  // The first frame, finished: shaders compiled, textures uploaded, pixels drawn.
  frame();
  const gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the frame
  state.firstFrameMs = performance.now();  // since navigation started
  state.state = 'ready';
  statusBox.textContent = `first frame ${state.firstFrameMs.toFixed(0)} ms`;
  if (!params.has('static')) renderer.setAnimationLoop(loop);
}
// For the tests: the pixels of the last frame (RGBA, row 0 at the top, base64), and which of
// them the glass covers (a frame drawn with the glass white on black, then the scene as it was).
function readPixels() {
  const gl = renderer.getContext();
  const pixels = new Uint8Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const rows = new Uint8Array(pixels.length);
  for (let y = 0; y < height; ++y) rows.set(pixels.subarray((height - 1 - y) * width * 4, (height - y) * width * 4), y * width * 4);
  let s = '';
  for (let i = 0; i < rows.length; i += 0x8000) s += String.fromCharCode(...rows.subarray(i, i + 0x8000));
  return btoa(s);
}
function coverage() {
  const white = new THREE.MeshBasicMaterial({ color: 0xffffff });
  const meshes = [];
  scene.traverse((o) => { if (o.isMesh && o !== background) meshes.push([o, o.material]); });
  for (const [o] of meshes) o.material = white;
  background.visible = false;
  renderer.setClearColor(0x000000, 1);
  renderer.render(scene, camera);
  const mask = readPixels();
  for (const [o, m] of meshes) o.material = m;
  background.visible = true;
  white.dispose();
  frame();
  return mask;
}
Object.assign(state, { THREE, renderer, scene, camera, background, readPixels, coverage, orbit, size: [width, height] });
// A getter of its own: Object.assign would copy the empty list the page starts with.
Object.defineProperty(state, 'materials', { get: () => materials, enumerable: true });
main().catch(showError);
