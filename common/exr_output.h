// Writing an OpenEXR file so that every failure is seen: OpenEXR writes its offset tables in
// destructors, which swallow errors, so a disk that fills at the end would otherwise leave a
// cut-off file that looks written.
#pragma once

#include <functional>
#include <string>

#include <ImfIO.h>

namespace shrefract {

// Opens `path` (typically a path an OutputSet staged), runs `write` on an OpenEXR stream over it
// (construct the Imf output file on that stream inside `write`, so its destructor runs there),
// then checks that every byte reached the file. Throws IoError naming the output (outputName)
// with the OS's reason.
void writeExrFile(const std::string& path, const std::function<void(Imf::OStream&)>& write);

}  // namespace shrefract
