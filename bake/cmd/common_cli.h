// Small helpers the command-line tools share: terminal detection, cache folder, formatting.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace shrefract::cli {

inline bool stderrIsTerminal() { return isatty(fileno(stderr)) != 0; }

// $SHREFRACT_CACHE, else $XDG_CACHE_HOME/shrefract, else ~/.cache/shrefract.
inline std::string defaultCacheDir() {
    if (const char* c = std::getenv("SHREFRACT_CACHE")) return c;
    if (const char* x = std::getenv("XDG_CACHE_HOME")) return std::string(x) + "/shrefract";
    if (const char* h = std::getenv("HOME")) return std::string(h) + "/.cache/shrefract";
    return "";
}

inline std::string formatDuration(double s) {
    char buf[32];
    int t = static_cast<int>(s + 0.5);
    std::snprintf(buf, sizeof buf, "%d:%02d", t / 60, t % 60);
    return buf;
}

}  // namespace shrefract::cli
