#include "common/output.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>

#include "common/error.h"

namespace shrefract {

namespace {

namespace fs = std::filesystem;

constexpr const char* kTempInfix = ".shrefract-tmp.";

// Staged path -> target, for isStagedOutput and outputName. Every OutputSet of the process.
std::mutex gRegistryMutex;
std::map<std::string, std::string>& registry() {
    static std::map<std::string, std::string> r;
    return r;
}

std::atomic<unsigned> gCounter{0};

std::string tempName(const std::string& folder, const std::string& name) {
    return folder + "/" + name + kTempInfix + std::to_string(::getpid()) + "." +
           std::to_string(gCounter.fetch_add(1));
}

// What an existing non-regular target is, for the refusal; "" for a regular file.
std::string kindOf(mode_t mode) {
    if (S_ISREG(mode)) return "";
    if (S_ISLNK(mode)) return "a symbolic link";
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

// Refuses a target that exists and is not a regular file: replacing it by a rename would
// destroy a link, a pipe someone reads or a device node.
void checkTarget(const std::string& path) {
    struct stat st;
    if (::lstat(path.c_str(), &st) != 0) {
        if (errno == ENOENT) return;
        throw ioError(path, "cannot inspect the output", errno);
    }
    const std::string kind = kindOf(st.st_mode);
    if (!kind.empty())
        throw inputError(path, "exists and is " + kind +
                                   ", not a regular file: refusing to replace it (name a regular "
                                   "file or a new path)");
}

// Temporaries PATH.shrefract-tmp.PID.N whose process is gone (killed before it could clean
// up): removed, so that a killed run leaves nothing behind once the next one starts.
void removeStaleTemporaries(const std::string& folder, const std::string& name) {
    DIR* dir = ::opendir(folder.c_str());
    if (!dir) return;
    const std::string prefix = name + kTempInfix;
    while (const dirent* e = ::readdir(dir)) {
        const std::string entry = e->d_name;
        if (entry.compare(0, prefix.size(), prefix) != 0) continue;
        char* end = nullptr;
        const long pid = std::strtol(entry.c_str() + prefix.size(), &end, 10);
        if (end == entry.c_str() + prefix.size() || *end != '.' || pid <= 0) continue;
        if (pid == ::getpid()) continue;
        if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) ::unlink((folder + "/" + entry).c_str());
    }
    ::closedir(dir);
}

void syncFolder(const std::string& folder) {
    const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

}  // namespace

std::string OutputSet::add(const std::string& path) {
    if (path.empty()) throw InputError("output path is empty");
    const fs::path p(path);
    const std::string name = p.filename().string();
    if (name.empty() || name == "." || name == "..")
        throw inputError(path, "is not a file name");
    Entry e;
    e.target = path;
    e.folder = p.has_parent_path() ? p.parent_path().string() : ".";
    struct stat st;
    if (::stat(e.folder.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR)
            throw inputError(path, "folder " + e.folder + " does not exist");
        throw ioError(path, "cannot reach folder " + e.folder, errno);
    }
    if (!S_ISDIR(st.st_mode)) throw inputError(path, e.folder + " is not a folder");
    checkTarget(path);
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(p, ec), ec);
    for (const Entry& other : entries_) {
        if (fs::weakly_canonical(fs::absolute(other.target, ec), ec) == canonical)
            throw inputError(path, "is named twice as an output");
    }
    removeStaleTemporaries(e.folder, name);

    // An unnamed file in the target's folder: it vanishes with the process if never linked.
    e.fd = ::open(e.folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (e.fd >= 0) {
        e.unnamed = true;
        e.staged = "/proc/self/fd/" + std::to_string(e.fd);
    } else if (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL) {
        // The file system has no O_TMPFILE: a named temporary, removed on every way out but
        // SIGKILL, and by the next add() for the same target after that.
        e.named = tempName(e.folder, name);
        e.fd = ::open(e.named.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0666);
        if (e.fd < 0) {
            const int err = errno;
            e.named.clear();
            throw ioError(path, "cannot create a file in folder " + e.folder, err);
        }
        e.staged = e.named;
    } else {
        throw ioError(path, "cannot create a file in folder " + e.folder, errno);
    }
    {
        std::lock_guard<std::mutex> lock(gRegistryMutex);
        registry()[e.staged] = e.target;
    }
    entries_.push_back(e);
    return e.staged;
}

void OutputSet::commit() {
    // Every file complete, on disk and named in its folder before any target is replaced.
    for (Entry& e : entries_) {
        if (::fsync(e.fd) != 0) throw ioError(e.target, "cannot write", errno);
        if (e.unnamed && e.named.empty()) {
            const std::string name = tempName(e.folder, fs::path(e.target).filename().string());
            if (::linkat(AT_FDCWD, e.staged.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) != 0)
                throw ioError(e.target, "cannot create a file in folder " + e.folder, errno);
            e.named = name;
        }
    }
    for (Entry& e : entries_) {
        checkTarget(e.target);  // it may have become a link or a pipe since add()
        if (::rename(e.named.c_str(), e.target.c_str()) != 0)
            throw ioError(e.target, "cannot rename " + e.named + " onto it", errno);
        e.named.clear();
        syncFolder(e.folder);
    }
    discard();
}

void OutputSet::discard() {
    for (Entry& e : entries_) {
        if (!e.named.empty()) ::unlink(e.named.c_str());
        if (e.fd >= 0) ::close(e.fd);
        std::lock_guard<std::mutex> lock(gRegistryMutex);
        registry().erase(e.staged);
    }
    entries_.clear();
}

OutputSet::~OutputSet() { discard(); }

bool isStagedOutput(const std::string& path) {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    return registry().count(path) > 0;
}

std::string outputName(const std::string& path) {
    std::lock_guard<std::mutex> lock(gRegistryMutex);
    auto it = registry().find(path);
    return it == registry().end() ? path : it->second;
}

IoError outputError(const std::string& staged, const std::string& detail) {
    const std::string target = outputName(staged);
    std::string text = detail;
    for (size_t at = text.find(staged); !staged.empty() && at != std::string::npos;
         at = text.find(staged, at + target.size()))
        text.replace(at, staged.size(), target);
    return IoError(target + ": cannot write: " + text);
}

void writeAtomically(const std::string& path,
                     const std::function<void(const std::string& staged)>& write) {
    if (isStagedOutput(path)) {
        write(path);
        return;
    }
    OutputSet outputs;
    const std::string staged = outputs.add(path);
    write(staged);
    outputs.commit();
}

void writeFile(const std::string& path, const std::string& bytes) {
    writeAtomically(path, [&](const std::string& staged) {
        const int fd = ::open(staged.c_str(), O_WRONLY | O_TRUNC | O_CREAT | O_CLOEXEC, 0666);
        if (fd < 0) throw ioError(outputName(staged), "cannot write", errno);
        size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                const int err = n < 0 ? errno : EIO;
                ::close(fd);
                throw ioError(outputName(staged), "cannot write", err);
            }
            done += size_t(n);
        }
        if (::close(fd) != 0) throw ioError(outputName(staged), "cannot write", errno);
    });
}

}  // namespace shrefract
