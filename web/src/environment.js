// The uniforms shaders/shading.glsl reads for its environment (runtime/src/environment.cpp
// useEnvironment): the cube map, its level-0 face size and its mip level count.
export function environmentUniforms() {
  return { uEnvironment: { value: null }, uEnvironmentFaceSize: { value: 1 }, uEnvironmentLevels: { value: 1 } };
}

// env: what SHRefractionLoaderPlugin read ({ texture, faceSize, levels }), or null.
export function setEnvironmentUniforms(uniforms, env) {
  uniforms.uEnvironment.value = env ? env.texture : null;
  uniforms.uEnvironmentFaceSize.value = env ? env.faceSize : 1;
  uniforms.uEnvironmentLevels.value = env ? env.levels : 1;
}

// three prepends "#version 300 es" itself (glslVersion GLSL3): the generated sources without it.
export function withoutVersion(source) {
  return source.slice(source.indexOf('\n') + 1);
}
