#include "common/exr_output.h"

#include <Iex.h>
#include <ImfStdIO.h>

#include <cerrno>
#include <fstream>

#include "common/error.h"
#include "common/output.h"

namespace shrefract {

void writeExrFile(const std::string& path, const std::function<void(Imf::OStream&)>& write) {
    const std::string target = outputName(path);
    std::ofstream os(path, std::ios::binary | std::ios::trunc);
    if (!os) throw ioError(target, "cannot write", errno);
    try {
        Imf::StdOFStream stream(os, target.c_str());
        write(stream);
    } catch (const Iex::BaseExc& e) {
        // OpenEXR's messages carry the OS's reason (strerror) when there is one.
        throw outputError(path, e.what());
    }
    errno = 0;
    os.flush();
    const int err = errno;
    os.close();
    if (os.fail()) throw ioError(target, "cannot write", err != 0 ? err : errno != 0 ? errno : EIO);
}

}  // namespace shrefract
