// 8-bit PNG output, the one writer the tools share (renders, heat maps, montages, screenshots).
#pragma once

#include <cstdint>
#include <string>

namespace shrefract {

// Writes width x height 8-bit sRGB RGB pixels (rows top-down, 3 bytes each) as PNG through
// writeAtomically (common/output.h): a refused target is an InputError, a failed write an
// IoError with the OS's reason, and either leaves `path` as it was.
void writePngRgb8(const std::string& path, int width, int height, const uint8_t* rgb);

}  // namespace shrefract
