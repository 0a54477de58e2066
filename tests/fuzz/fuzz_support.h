// What the fuzz targets share (docs/testing.md "Fuzzing"): the readers take paths, so each input
// is written to a file in a scratch folder of this process (in /dev/shm when there is one), which
// goes when the process exits. Each target accepts InputError as the answer to bad input; any other
// exception escaping the library is a bug and ends the run, as a crash, leak or UB report does.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace shrefract::fuzz {

inline const std::filesystem::path& scratchFolder() {
    static const std::filesystem::path dir = [] {
        std::error_code ec;
        const std::filesystem::path base =
            std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
        std::filesystem::path d = base / ("shrefract-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d, ec);
        std::atexit([] {
            std::error_code e;
            std::filesystem::remove_all(scratchFolder(), e);
        });
        return d;
    }();
    return dir;
}

// Writes the input to scratchFolder()/name and returns the path.
inline std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
    const std::filesystem::path p = scratchFolder() / name;
    std::ofstream(p, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return p.string();
}

}  // namespace shrefract::fuzz
