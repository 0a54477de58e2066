// STAND-IN, compiled only while common/bakefile.cpp does not exist (branch h-format not merged
// yet): the reader reports that it is missing, so the runtime links and its error paths work.
#include <filesystem>

#include "common/bakefile.h"
#include "common/error.h"
#include "common/sh.h"

namespace shrefract {

const char* ToString(Precision p) {
    return p == Precision::F32 ? "f32" : p == Precision::F16 ? "f16" : "u8";
}

int BakeData::coefficientCount() const { return shEvenCount(order); }

BakeData readBake(const std::string& path) {
    if (!std::filesystem::exists(path)) throw inputError(path, "not found");
    throw inputError(path, "cannot read bakes yet (common/bakefile.cpp not merged)");
}

}  // namespace shrefract
