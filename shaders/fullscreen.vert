#version 330 core
// One triangle covering the viewport, from gl_VertexID (no attributes): every texture-space
// pass and the background draw it.
void main() {
    vec2 c = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);
}
