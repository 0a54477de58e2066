#include "bake_data.h"
#include "rho_pipeline.h"

#include "ior.h"

namespace shrefract {

using namespace gl;

RhoPipeline::RhoPipeline(const PipelineInputs& in)
    : settings_(in.settings),
      grid_(bakeData(in.bake).layout, in.memory),
      decompression_(bakeData(in.bake), in.options, in.maxOrder, in.limits, in.form, grid_, in.memory),
      map_(bakeData(in.bake).layout, in.memory),
      mesh_(in.bake, in.memory) {
    prepare();
}

int RhoPipeline::passCount() {
    return static_cast<int>(decompression_.compiled(settings_.order).programs.size());
}

void RhoPipeline::update(glm::vec3 eyeObject, bool, const StageClock& clock) {
    const GLuint d = decompression_.run(eyeObject, settings_.order, settings_.smoothing, clock);
    map_.unpack(d, settings_.correction, clock);
    ready_ = true;
}

GLuint RhoPipeline::shadingProgram(IorShading* ior) {
    return ior ? ior->program(false, decompression_.muWidth()) : mesh_.program();
}

void RhoPipeline::draw(GLuint, bool, glm::vec3) { mesh_.draw(map_.texture()); }

GLuint RhoPipeline::refractionMap() {
    if (!ready_) {  // before the first update(): whatever D_mu holds
        map_.unpack(decompression_.result(), settings_.correction, {});
        ready_ = true;
    }
    return map_.texture();
}

}  // namespace shrefract
