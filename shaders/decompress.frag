#version 330 core
// One SH decompression pass (paper §5.1, Figure 3) over the mu layout: the partial sum of the
// passes before it, plus weight x y_k(w) for each function k of this pass, at the sample's local
// view direction w. The generator (runtime/src/shadergen.cpp) sets the #version, defines
// SHREFRACT_FIRST_PASS for the first pass and puts the weight samplers and shPass() in place of
// the marker line below.
uniform sampler2D uLocalView;  // local view direction per mu sample (xyz)
#ifndef SHREFRACT_FIRST_PASS
uniform sampler2D uPartialSum;  // the sum of the passes before this one
#endif
layout(location = 0) out vec4 oSum;

#pragma shrefract_generated

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 w = texelFetch(uLocalView, p, 0).xyz;
#ifdef SHREFRACT_FIRST_PASS
    vec4 s = vec4(0.0);
#else
    vec4 s = texelFetch(uPartialSum, p, 0);
#endif
    oSum = shPass(p, w, s);
}
