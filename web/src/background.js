// The environment behind everything, as shrefract-render draws it (runtime/src/environment.cpp
// Environment::drawBackground): a full-screen triangle (shaders/fullscreen.vert) whose pixels
// look the cube map up along their view ray (shaders/background.frag). Add it to the scene; it
// draws first, without depth.
import * as THREE from 'three';
import { shaderSource } from './generated/shaders.js';
import { environmentUniforms, setEnvironmentUniforms, withoutVersion } from './environment.js';


const _m4 = new THREE.Matrix4();
const _v4 = new THREE.Vector4();

export class SHRefractionBackground extends THREE.Mesh {
  constructor(environment = null, { toneMap = true, exposure = 1.0 } = {}) {
    const geometry = new THREE.BufferGeometry();
    // fullscreen.vert makes its triangle from gl_VertexID; three counts vertices by position.
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
    const material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3,
      vertexShader: withoutVersion(shaderSource('fullscreen.vert')),
      fragmentShader: withoutVersion(shaderSource('background.frag', { SHREFRACT_COLOR_ONLY: '' })),
      uniforms: {
        uInverseViewProjection: { value: new THREE.Matrix4() },
        uViewport: { value: new THREE.Vector2(1, 1) },
        uViewportOrigin: { value: new THREE.Vector2(0, 0) },
        uToneMap: { value: toneMap },
        uExposure: { value: exposure },
        ...environmentUniforms(),
      },
      depthTest: false,
      depthWrite: false,
    });
    super(geometry, material);
    this.frustumCulled = false;
    this.renderOrder = -1e9;
    this.environment = environment;
    this.toneMap = toneMap;
    this.exposure = exposure;
    material.onBeforeRender = (renderer, scene, camera) => {
      const u = material.uniforms;
      // The view's rotation only, as drawBackground's glm::mat3(view).
      _m4.extractRotation(camera.matrixWorldInverse);
      u.uInverseViewProjection.value.multiplyMatrices(camera.projectionMatrix, _m4).invert();
      renderer.getCurrentViewport(_v4);
      u.uViewport.value.set(_v4.z, _v4.w);
      u.uViewportOrigin.value.set(_v4.x, _v4.y);
      u.uToneMap.value = !!this.toneMap;
      u.uExposure.value = this.exposure;
      setEnvironmentUniforms(u, this.environment);
      material.uniformsNeedUpdate = true;
    };
    this.visible = true;
  }
}
