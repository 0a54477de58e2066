// A loaded bake's data, for the runtime and the project's own tools and tests: the installed
// headers keep it opaque (Bake::Impl), as an app has no common/bakefile.h.
#pragma once

#include "common/bakefile.h"
#include "shrefract/runtime.h"

namespace shrefract {

struct Bake::Impl {
    BakeData data;
};

inline const BakeData& bakeData(const Bake& bake) { return bake.impl().data; }

// Wraps bake data already in memory (tests, tools that bake and render in one process).
Bake makeBake(BakeData data);

}  // namespace shrefract
