// Reading OpenEXR files that may be damaged or hostile: a scan of the file's headers before
// OpenEXR parses them. OpenEXR 3.1 allocates whatever an attribute's size field claims before it
// finds the file too short (a flipped byte can ask for gigabytes), so every size is checked
// against the bytes the file holds first. Used by readBake, loadLatLong and readEvalBuffer.
#pragma once

#include <string>

namespace shrefract {

// Throws InputError naming `path` ("truncated or corrupt: ...") unless the file starts with
// OpenEXR's magic number and every header attribute (of every part) fits in the file, with names
// no longer than OpenEXR allows and at most 1024 parts of 4096 attributes. OpenEXR's typed readers
// read what their type holds, not what the size field says (a channel list up to its empty name),
// so every value must fill its size exactly the way OpenEXR reads it, or OpenEXR would read the
// rest of the header out of step and take whatever bytes it lands on for a size.
void checkExrHeaders(const std::string& path);

}  // namespace shrefract
