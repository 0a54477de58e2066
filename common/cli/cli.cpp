#include "common/cli/cli.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <stdexcept>

#include "common/bakefile.h"
#include "common/error.h"

#ifndef SHREFRACT_VERSION
#error "SHREFRACT_VERSION is set by common/CMakeLists.txt from the project version"
#endif

namespace shrefract::cli {

namespace {

std::atomic<bool> gCancel{false};

void onSignal(int) {
    if (gCancel.exchange(true)) _exit(kInterrupted);  // the second Ctrl-C: stop now
}

int fail(const std::string& tool, const char* what, int code) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: %s\n", tool.c_str(), what);
    return code;
}

}  // namespace

std::string versionLine(const std::string& tool) {
    return tool + " " + SHREFRACT_VERSION + " (bake format " + std::to_string(kFormatVersion) + ")";
}

int run(CLI::App& app, const std::string& tool, int argc, char** argv,
        const std::function<int()>& body) {
    app.set_version_flag("--version", versionLine(tool), "print the version and exit");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints help, the version or CLI11's message
        return code == 0 ? kOk : kBadInput;
    }
    try {
        return body();
    } catch (const Cancelled&) {
        std::fflush(stdout);
        std::fprintf(stderr, "%s: cancelled; nothing written\n", tool.c_str());
        return kInterrupted;
    } catch (const InputError& e) {
        return fail(tool, e.what(), kBadInput);
    } catch (const std::invalid_argument& e) {
        return fail(tool, e.what(), kBadInput);
    } catch (const std::exception& e) {
        return fail(tool, e.what(), kFailed);
    }
}

const std::atomic<bool>* cancelOnSignals() {
    struct sigaction sa = {};
    sa.sa_handler = onSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    return &gCancel;
}

void note(const std::string& tool, const std::string& message) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: note: %s\n", tool.c_str(), message.c_str());
}

}  // namespace shrefract::cli
