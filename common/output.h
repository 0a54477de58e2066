// Outputs that never clobber and never half-exist (docs/testing.md "Outputs").
//
//   OutputSet outputs;                                  // before the work starts:
//   const std::string png = outputs.add("a.png");       //   each target checked, a file staged
//   const std::string exr = outputs.add("a.exr");       //   beside it (throws now, not later)
//   ... the work ...
//   writePng(png, ...);                                 // any shrefract writer, given the staged
//   writeExr(exr, ...);                                 //   path, writes the staged file
//   outputs.commit();                                   // all complete: renamed into place
//
// Leaving the scope without commit() (an exception, a cancel) removes every staged file and leaves
// every target as it was.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/error.h"

namespace shrefract {

class OutputSet {
public:
    OutputSet() = default;
    ~OutputSet();  // removes whatever was staged and not committed
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;

    // Checks `path` and stages a new, empty file for it in the same folder; returns the path to
    // write instead of `path` (every shrefract writer accepts it: isStagedOutput). Refuses with an
    // InputError naming `path`: an empty name, a folder that does not exist, a target that exists
    // and is not a regular file (a symbolic link, folder, FIFO, device or socket is never
    // replaced), a target already in this set. Throws IoError with the OS's reason when the
    // folder refuses a new file (read-only, no permission, full). The staged file has no name in
    // the folder (Linux O_TMPFILE), so a process killed outright leaves nothing behind; where the
    // file system cannot do that it is PATH.shrefract-tmp.PID.N, which add() removes once PID is
    // gone.
    std::string add(const std::string& path);

    // Flushes every staged file to disk, then renames them all onto their targets (each rename
    // atomic: a reader sees the old file or the new one, never a part). Throws IoError with the
    // OS's reason if that fails; nothing is renamed unless every file is complete.
    void commit();

    // Drops every staged file now, as the destructor would.
    void discard();

    bool empty() const { return entries_.empty(); }

private:
    struct Entry {
        std::string target;  // as given
        std::string folder;  // the target's folder, "." when none was given
        std::string staged;  // what writers write: /proc/self/fd/N or the named temporary
        std::string named;   // the temporary's name in the folder, once it has one
        int fd = -1;
        bool unnamed = false;  // O_TMPFILE
    };
    std::vector<Entry> entries_;
};

// Whether `path` is a file an OutputSet staged: writers write such a path directly.
bool isStagedOutput(const std::string& path);
// The target a staged path stands for (for messages); other paths unchanged.
std::string outputName(const std::string& path);

// "TARGET: cannot write: DETAIL" for a writer that failed on a staged path, with the staged
// path in DETAIL (libraries quote the name they opened) replaced by the target's.
IoError outputError(const std::string& staged, const std::string& detail);

// Writes one output through `write(staged)` and commits it; an error leaves `path` as it was.
// Called with a path an OutputSet already staged, writes it directly (that set commits it).
void writeAtomically(const std::string& path,
                     const std::function<void(const std::string& staged)>& write);

// `bytes` (text or binary) to `path` through writeAtomically; IoError with the OS's reason.
void writeFile(const std::string& path, const std::string& bytes);

}  // namespace shrefract
