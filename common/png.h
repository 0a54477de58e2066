// 8-bit PNG output, the one writer the tools share (renders, heat maps, montages, screenshots).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace shrefract {

// Writes width x height 8-bit sRGB RGB pixels (rows top-down, 3 bytes each) as PNG through
// writeAtomically (common/output.h): a refused target is an InputError, a failed write an
// IoError with the OS's reason, and either leaves `path` as it was.
void writePngRgb8(const std::string& path, int width, int height, const uint8_t* rgb);

// The PNG file of width x height 8-bit RGBA pixels (rows top-down, 4 bytes each), in memory,
// without colour information (no sRGB, gAMA or iCCP chunk): data such as the glTF export's SH
// weight codes, which a reader must take exactly as they are.
std::vector<uint8_t> encodePngRgba8(int width, int height, const uint8_t* rgba);

}  // namespace shrefract
