// The refraction map in the rho layout (paper §5.3.1) and the mesh that shades from it.
//   RhoMap:  which sample (or interpolation-correction texel) each rho texel shows, and the unpack
//            pass that fills the map from D_mu: the rho pipeline's every frame, the direct one's
//            when an app asks for the map.
//   MapMesh: the refraction map's mesh, three vertices per triangle with their map coordinates,
//            and the shading program that looks the map up bilinearly (rho and chart pipelines).
#pragma once

#include "common/bakefile.h"
#include "pipeline.h"

namespace shrefract {

class RhoMap {
public:
    RhoMap(const SurfaceLayout& layout, GpuMemory& memory);  // in the current context
    ~RhoMap();
    RhoMap(const RhoMap&) = delete;
    RhoMap& operator=(const RhoMap&) = delete;

    // D_mu -> the map, with or without the correction texels; leaves the map's framebuffer bound.
    void unpack(GLuint d, bool correction, const StageClock& clock);
    GLuint texture() const { return target_.texture; }
    glm::ivec2 size() const { return {width_, height_}; }

private:
    int width_ = 0, height_ = 0;
    GLuint index_ = 0, program_ = 0, emptyVao_ = 0;
    gl::Target target_;
};

class MapMesh {
public:
    MapMesh(const Bake& bake, GpuMemory& memory);  // in the current context
    ~MapMesh();
    MapMesh(const MapMesh&) = delete;
    MapMesh& operator=(const MapMesh&) = delete;

    GLuint program() const { return program_; }  // shade.vert + shade.frag, the map on unit 1
    GLuint vao() const { return vao_; }          // position, normal, map uv at attributes 0, 1, 2
    int vertexCount() const { return vertices_; }
    // Binds `map` to unit 1 and draws the mesh with the program in use.
    void draw(GLuint map) const;

private:
    GLuint program_ = 0, vao_ = 0, vbo_ = 0;
    int vertices_ = 0;
};

}  // namespace shrefract
