// 8-bit PNG output, the one writer the tools share (renders, heat maps, montages, screenshots).
#pragma once

#include <cstdint>
#include <string>

namespace shrefract {

// Writes width x height 8-bit sRGB RGB pixels (rows top-down, 3 bytes each) as PNG, through a
// temporary name and a rename: a failure leaves no file at `path` and throws InputError
// naming it.
void writePngRgb8(const std::string& path, int width, int height, const uint8_t* rgb);

}  // namespace shrefract
