// Fuzz target: the CSV of `shrefract-eval query` (parseQueries).
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/error.h"
#include "common/query.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        shrefract::parseQueries(std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv");
    } catch (const shrefract::InputError&) {
    }
    return 0;
}
