#include "common/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/gltf_scene.h"

namespace shrefract {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The keys a part may have; anything else is most likely a typo that would silently fall back
// to a default, so it is rejected.
const char* const kPartKeys[] = {"name",     "mesh",  "ior",      "absorption",
                                 "priority", "scale", "translate"};

std::string allowedPartKeys() {
    std::string s;
    for (const char* k : kPartKeys) s += (s.empty() ? "" : ", ") + std::string(k);
    return s;
}

bool endsWithJson(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".json";
}

// nlohmann::json stores non-finite doubles as numbers when built in code but never parses
// them; still, a huge literal like 1e999 parses to inf, so every number is checked.
bool finiteNumber(const json& j) { return j.is_number() && std::isfinite(j.get<double>()); }

glm::dvec3 threeNumbers(const json& j, const std::string& key, const std::string& where,
                        const std::string& scenePath) {
    if (!j.is_array() || j.size() != 3 ||
        !std::all_of(j.begin(), j.end(), [](const json& x) { return finiteNumber(x); }))
        throw inputError(scenePath,
                         where + ": '" + key + "' must be 3 finite numbers, got " + j.dump());
    return glm::dvec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

Part loadPart(const json& jp, size_t index, const std::string& scenePath,
              const Medium& defaultMedium) {
    std::string where = "parts[" + std::to_string(index) + "]";
    if (!jp.is_object()) throw inputError(scenePath, where + ": must be an object");

    Part part;
    if (jp.contains("name")) {
        if (!jp["name"].is_string())
            throw inputError(scenePath, where + ": 'name' must be a string");
        part.name = jp["name"].get<std::string>();
        where += " ('" + part.name + "')";
    }
    for (const auto& item : jp.items()) {
        if (std::find(std::begin(kPartKeys), std::end(kPartKeys), item.key()) ==
            std::end(kPartKeys))
            throw inputError(scenePath, where + ": unknown key '" + item.key() +
                                            "' (allowed: " + allowedPartKeys() + ")");
    }

    if (!jp.contains("mesh")) throw inputError(scenePath, where + ": missing 'mesh'");
    if (!jp["mesh"].is_string() || jp["mesh"].get<std::string>().empty())
        throw inputError(scenePath, where + ": 'mesh' must be a non-empty file name");
    // Relative mesh paths are relative to the scene file, so a scene folder can be moved.
    fs::path meshPath = jp["mesh"].get<std::string>();
    if (meshPath.is_relative()) meshPath = fs::path(scenePath).parent_path() / meshPath;
    part.meshPath = meshPath.lexically_normal().string();
    if (part.name.empty()) part.name = meshPath.stem().string();

    Medium& m = part.medium;
    m = defaultMedium;
    m.name = part.name;
    if (jp.contains("ior")) {
        if (!finiteNumber(jp["ior"]))
            throw inputError(scenePath,
                             where + ": 'ior' must be a finite number, got " + jp["ior"].dump());
        m.ior = jp["ior"].get<double>();
    }
    if (jp.contains("absorption"))
        m.absorption = threeNumbers(jp["absorption"], "absorption", where, scenePath);
    if (jp.contains("priority")) {
        const json& p = jp["priority"];
        if (!p.is_number_integer() || p.get<long long>() < std::numeric_limits<int>::min() ||
            p.get<long long>() > std::numeric_limits<int>::max())
            throw inputError(scenePath, where + ": 'priority' must be an integer, got " + p.dump());
        m.priority = p.get<int>();
    }
    std::string problem = mediumProblem(m);
    if (!problem.empty()) throw inputError(scenePath, where + ": " + problem);

    double scale = 1.0;
    if (jp.contains("scale")) {
        if (!finiteNumber(jp["scale"]) || jp["scale"].get<double>() <= 0.0)
            throw inputError(scenePath, where + ": 'scale' must be a finite number > 0, got " +
                                            jp["scale"].dump());
        scale = jp["scale"].get<double>();
    }
    glm::dvec3 translate(0.0);
    if (jp.contains("translate"))
        translate = threeNumbers(jp["translate"], "translate", where, scenePath);

    try {
        part.mesh = loadMesh(part.meshPath, &part.report);
    } catch (const InputError& e) {
        // The mesh's own message names the mesh file; prefix the scene and part it came from.
        throw inputError(scenePath, where + ": " + e.what());
    }
    // Scale and translation are applied once here, so every later stage sees scene space.
    // A positive uniform scale keeps normals and winding as they are.
    if (scale != 1.0 || translate != glm::dvec3(0.0)) {
        for (glm::vec3& p : part.mesh.positions) p = glm::vec3(glm::dvec3(p) * scale + translate);
    }
    return part;
}

Scene loadJsonScene(const std::string& path, const Medium& defaultMedium) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw inputError(path, "file not found");
    std::stringstream text;
    text << in.rdbuf();

    json doc;
    try {
        doc = json::parse(text.str());
    } catch (const json::exception& e) {
        // what() reads "[json.exception.parse_error.101] parse error at line L, column C: ...";
        // keep the part after the bracketed id. Number overflow (1e999) lands here too.
        std::string what = e.what();
        size_t close = what.find("] ");
        throw inputError(
            path, "invalid JSON: " + (close == std::string::npos ? what : what.substr(close + 2)));
    }
    if (!doc.is_object()) throw inputError(path, "a scene must be a JSON object with \"parts\"");
    for (const auto& item : doc.items()) {
        if (item.key() != "parts")
            throw inputError(path, "unknown key '" + item.key() + "' (allowed: parts)");
    }
    if (!doc.contains("parts")) throw inputError(path, "missing 'parts'");
    const json& parts = doc["parts"];
    if (!parts.is_array()) throw inputError(path, "'parts' must be an array");
    if (parts.empty()) throw inputError(path, "'parts' is empty");

    Scene scene;
    scene.path = path;
    std::set<std::string> names;
    for (size_t i = 0; i < parts.size(); ++i) {
        scene.parts.push_back(loadPart(parts[i], i, path, defaultMedium));
        // Parts are told apart by name in the manifest and in messages.
        if (!names.insert(scene.parts.back().name).second)
            throw inputError(path, "parts[" + std::to_string(i) + "]: duplicate part name '" +
                                       scene.parts.back().name + "'");
    }
    return scene;
}

}  // namespace

Scene loadScene(const std::string& path, const Medium& defaultMedium) {
    if (endsWithJson(path)) return loadJsonScene(path, defaultMedium);
    if (isGltfPath(path)) return loadGltfScene(path);

    // A bare mesh: one part, its medium from the caller (the command line).
    std::string problem = mediumProblem(defaultMedium);
    if (!problem.empty()) throw inputError(path, problem);
    Scene scene;
    scene.path = path;
    Part part;
    part.meshPath = path;
    part.mesh = loadMesh(path, &part.report);
    part.medium = defaultMedium;
    part.name = defaultMedium.name;
    scene.parts.push_back(std::move(part));
    return scene;
}

}  // namespace shrefract
