#version 330 core
// Local view direction per covered atlas texel (paper §5.2): the view vector eye - P and the
// normal are interpolated from the unfolded mesh's vertices (eye - P is linear, so exactly), the
// frame is taken per texel from the interpolated normal (frame.glsl). Interpolating the local
// coordinates themselves would mix vertices' frames, which jump where n.z changes sign.
#include "frame.glsl"
uniform vec3 uEye;  // object space
in vec3 vPosition;
in vec3 vNormal;
layout(location = 0) out vec4 oLocal;
void main() {
    vec3 omega = normalize(uEye - vPosition);
    oLocal = vec4(normalize(toLocalFrame(omega, normalize(vNormal))), 0.0);
}
