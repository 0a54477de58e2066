#include "gpu_timer.h"

namespace shrefract {

using namespace gl;

GpuStageTimer::GpuStageTimer(int stages) : queries_(static_cast<size_t>(stages), 0) {
    glGenQueries(stages, queries_.data());
}

GpuStageTimer::~GpuStageTimer() {
    glDeleteQueries(static_cast<GLsizei>(queries_.size()), queries_.data());
}

void GpuStageTimer::begin(int stage) {
    if (enabled_) glBeginQuery(GL_TIME_ELAPSED, queries_.at(static_cast<size_t>(stage)));
}

void GpuStageTimer::end(int stage, double* ms) {
    if (!enabled_) return;
    glFinish();  // inside the query: the stage's work, not only its submission
    glEndQuery(GL_TIME_ELAPSED);
    GLuint64 ns = 0;
    glGetQueryObjectui64v(queries_.at(static_cast<size_t>(stage)), GL_QUERY_RESULT, &ns);
    *ms = ns * 1e-6;
}

}  // namespace shrefract
