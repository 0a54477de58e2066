// Reading OpenEXR files that may be damaged or hostile: a scan of the file's headers before
// OpenEXR parses them. OpenEXR 3.1 allocates whatever an attribute's size field claims before it
// finds the file too short (a flipped byte can ask for gigabytes), so every size is checked
// against the bytes the file holds first. Used by readBake, loadLatLong and readEvalBuffer.
#pragma once

#include <string>

namespace shrefract {

// Throws InputError naming `path` ("truncated or corrupt: ...") unless the file starts with
// OpenEXR's magic number and every header attribute (of every part) fits in the file, with names
// no longer than OpenEXR allows and at most 1024 parts of 4096 attributes.
void checkExrHeaders(const std::string& path);

}  // namespace shrefract
