// GL timer queries around the stages of a frame, off unless an app asks for them. A measured
// stage ends with a glFinish and a blocking read of its query (software rasterizers such as
// llvmpipe defer the work to a flush, so without the finish only the submission is timed): each
// one stalls the pipeline. Frame wall times (shrefract/render.h frameWallMs) are always taken
// with the timers off.
#pragma once

#include <vector>

#include "gl.h"

namespace shrefract {

class GpuStageTimer {
public:
    explicit GpuStageTimer(int stages);  // in the current context
    ~GpuStageTimer();
    GpuStageTimer(const GpuStageTimer&) = delete;
    GpuStageTimer& operator=(const GpuStageTimer&) = delete;

    void setEnabled(bool on) { enabled_ = on; }
    bool enabled() const { return enabled_; }
    // Around one stage; both do nothing while disabled. end() waits for the GPU and writes the
    // stage's time in milliseconds to `ms`.
    void begin(int stage);
    void end(int stage, double* ms);

private:
    std::vector<GLuint> queries_;
    bool enabled_ = false;
};

}  // namespace shrefract
