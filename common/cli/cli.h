// What every shrefract command-line tool shares: one table of exit codes, --version, one way of
// reporting errors, and stopping on Ctrl-C (README "Exit codes"). Tools are thin shells:
//
//   int main(int argc, char** argv) {
//       CLI::App app{"..."};
//       ... options ...
//       return cli::run(app, "shrefract-foo", argc, argv, [&] { ...; return cli::kOk; });
//   }
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "shrefract/enum_names.h"

namespace shrefract::cli {

// The same for every tool.
enum Exit : int {
    kOk = 0,             // done (also --help and --version)
    kFailed = 1,         // a runtime failure: an I/O error (disk full, permission), the GL driver,
                         // anything unexpected
    kBadInput = 2,       // bad input: a usage error (CLI11's), an argument out of range, a file
                         // that is missing, malformed, corrupt or refused as an output
    kInterrupted = 130,  // SIGINT or SIGTERM: stopped, nothing written
};

// "TOOL VERSION (bake format N)": what --version prints.
std::string versionLine(const std::string& tool);

// Adds --version, parses argv and runs `body`, mapping every outcome to the table above: --help and
// --version print and give 0; a CLI11 usage error prints CLI11's message and gives 2; `body`'s
// return value, or for what it throws one line "TOOL: error: MESSAGE" on stderr and InputError or
// std::invalid_argument -> 2, Cancelled -> 130, anything else -> 1.
int run(CLI::App& app, const std::string& tool, int argc, char** argv,
        const std::function<int()>& body);

// Installs SIGINT and SIGTERM handlers that set the returned flag, for work that polls it and
// stops cleanly (throwing Cancelled); a second signal ends the process at once with 130.
const std::atomic<bool>* cancelOnSignals();

// "note: MESSAGE" on stderr: the tool chose something the user did not ask for literally (a
// value rounded or clamped). Say what you do.
void note(const std::string& tool, const std::string& message);

// An option whose value is one of an enumeration's names (shrefract/enum_names.h): the help
// lists the names and shows the default by name, and any other word is a usage error.
template <class E>
CLI::Option* addEnumOption(CLI::App& app, const std::string& flags, E& value, const std::string& help) {
    std::map<std::string, E> names;
    for (const NamedValue<E>& v : EnumNames<E>::table) names.emplace(v.name, v.value);
    return app.add_option(flags, value, help)
        ->transform(CLI::CheckedTransformer(names))
        ->default_str(nameOf(value));
}

}  // namespace shrefract::cli
