// What "the same bake" means for shards, checkpoints and schedulers: the same weights and error
// model bit for bit and the same manifest but for its one timing field, stats.seconds.
#pragma once

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "common/bakefile.h"

namespace shrefract::test {

// "" when `a` and `b` are the same bake, else the first difference.
inline std::string bakeDifference(const BakeData& a, const BakeData& b) {
    if (a.weights.size() != b.weights.size())
        return std::to_string(a.weights.size()) + " vs " + std::to_string(b.weights.size()) + " weights";
    for (size_t i = 0; i < a.weights.size(); ++i) {
        if (std::memcmp(&a.weights[i], &b.weights[i], sizeof(float)) != 0) {
            char text[96];
            std::snprintf(text, sizeof text, "weights differ first at value %zu: %.9g vs %.9g", i,
                          a.weights[i], b.weights[i]);
            return text;
        }
    }
    if (a.errorOrder != b.errorOrder || a.errors.size() != b.errors.size())
        return "error models differ: order " + std::to_string(a.errorOrder) + " vs " + std::to_string(b.errorOrder);
    if (!a.errors.empty() && std::memcmp(a.errors.data(), b.errors.data(), a.errors.size() * sizeof(float)) != 0)
        return "error model values differ";
    nlohmann::json x = a.manifest, y = b.manifest;
    if (x.contains("stats")) x["stats"].erase("seconds");
    if (y.contains("stats")) y["stats"].erase("seconds");
    if (x != y) return "manifests differ:\n" + x.dump(1) + "\n" + y.dump(1);
    return "";
}

// Damages a file as a bad disk or a cut-off write might: flips `mask` in the byte `fromEnd`
// bytes before its end.
inline void flipByte(const std::string& path, long fromEnd, char mask) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(-fromEnd, std::ios::end);
    char c = 0;
    f.get(c);
    f.seekp(-fromEnd, std::ios::end);
    f.put(char(c ^ mask));
}

}  // namespace shrefract::test
