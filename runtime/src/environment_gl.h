// Binding an Environment for the programs that include shaders/shading.glsl.
#pragma once

#include "shrefract/runtime.h"

namespace shrefract {

// On the current program: uEnvironment on texture unit `unit` (bound there), and the face size
// and mip level count that shading.glsl's lobe lookups need.
void useEnvironment(unsigned program, const Environment& environment, int unit);

}  // namespace shrefract
