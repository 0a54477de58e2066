// shrefract on the web: the SHREFRACT_sh_refraction GLTFLoader plugin, the material it puts on
// the glass and the environment background (docs/web.md).
export { SHRefractionLoaderPlugin, EXTENSION, VERSIONS, checkGlb, loadGlb, gpuBytes } from './loader.js';
export { SHRefractionMaterial } from './material.js';
export { SHRefractionBackground } from './background.js';
