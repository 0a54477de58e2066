#include "common/gltf_scene.h"
#include "common/gltf_model.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <set>

#include "common/error.h"

namespace shrefract {

namespace {

namespace fs = std::filesystem;

constexpr const char* kTransmission = "KHR_materials_transmission";
constexpr const char* kIor = "KHR_materials_ior";
constexpr const char* kVolume = "KHR_materials_volume";
// Compressed geometry this reader cannot decode (Debian's tinygltf is built without Draco).
constexpr const char* kCompressions[] = {"KHR_draco_mesh_compression", "EXT_meshopt_compression"};

std::string lowercaseExtension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

// Images are never decoded: the bake reads geometry and media only.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
               const unsigned char*, int, void*) {
    return true;
}

// Images kept as the file holds them, never decoded (shrefract-export --into writes them back).
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
}

// tinygltf's file callbacks, for regular files only: a buffer URI naming a FIFO would block in
// tinygltf's own existence check (an fopen), a device such as /dev/zero read forever.
bool regularFileExists(const std::string& path, void*) {
    std::error_code ec;
    return fs::is_regular_file(path, ec);
}

bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* user) {
    if (!regularFileExists(path, user)) {
        if (err) *err += "'" + path + "' is not a regular file\n";
        return false;
    }
    return tinygltf::ReadWholeFile(out, err, path, user);
}

// One accessor's elements, checked to lie inside their buffer.
struct ElementView {
    const unsigned char* base = nullptr;
    size_t stride = 0;
    size_t count = 0;
    int componentType = 0;
};

class GltfReader {
public:
    GltfReader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

    Scene read(std::vector<GltfPlace>* places);

private:
    struct Found {
        Part part;
        GltfPlace place;
        bool explicitPriority = false;
    };

    [[noreturn]] void fail(const std::string& what) const { throw inputError(path_, what); }

    std::string nodeName(int n) const {
        const std::string& name = m_.nodes[size_t(n)].name;
        return name.empty() ? str("node", n) : name;
    }
    std::string materialName(int i) const {
        if (i < 0) return "(none)";
        const std::string& name = m_.materials[size_t(i)].name;
        return name.empty() ? str("material", i) : name;
    }

    void checkCompression() const;
    std::vector<int> roots() const;
    glm::dmat4 localMatrix(int n) const;
    double number(const tinygltf::Value& obj, const char* key, double fallback,
                  const std::string& where) const;
    const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) const;
    bool transmissive(int material) const;
    Medium medium(int material) const;
    bool extrasPriority(const tinygltf::Value& extras, const std::string& where, int* out) const;
    ElementView elements(int accessor, const std::string& what, int type,
                         std::initializer_list<int> componentTypes) const;
    Found part(int node, int primitive, const glm::dmat4& world, const std::string& name) const;
    void assignPriorities(std::vector<Found>& found, std::vector<std::string>& notes) const;

    const std::string& path_;
    const tinygltf::Model& m_;
};

void GltfReader::checkCompression() const {
    auto refuse = [&](const std::string& ext, const std::string& where) {
        fail(str(where, " uses ", ext, ": compressed geometry is not supported (export without ",
                 ext == kCompressions[0] ? "Draco" : "meshopt", " compression)"));
    };
    for (const char* ext : kCompressions) {
        for (const auto* list : {&m_.extensionsRequired, &m_.extensionsUsed})
            if (std::find(list->begin(), list->end(), ext) != list->end()) refuse(ext, "the file");
        for (size_t i = 0; i < m_.meshes.size(); ++i)
            for (size_t k = 0; k < m_.meshes[i].primitives.size(); ++k)
                if (m_.meshes[i].primitives[k].extensions.count(ext))
                    refuse(ext, str("mesh ", i, " primitive ", k));
        for (size_t i = 0; i < m_.bufferViews.size(); ++i)
            if (m_.bufferViews[i].extensions.count(ext)) refuse(ext, str("bufferView ", i));
    }
}

// The default scene's root nodes; without one the first scene's; without scenes every node that is
// no other node's child. Each node has at most one parent, and a root none (glTF 2.0 §3.5.3), so
// the walk below meets every node once and cannot loop.
std::vector<int> GltfReader::roots() const {
    const int count = int(m_.nodes.size());
    std::vector<int> parent(m_.nodes.size(), -1);
    for (int n = 0; n < count; ++n) {
        for (int c : m_.nodes[size_t(n)].children) {
            if (c < 0 || c >= count)
                fail(str("node ", n, " ('", nodeName(n), "') names child ", c, ", but there are ",
                         count, " nodes"));
            if (parent[size_t(c)] >= 0)
                fail(str("node ", c, " ('", nodeName(c), "') has two parents (nodes ",
                         parent[size_t(c)], " and ", n, "): a node hierarchy must be a tree"));
            parent[size_t(c)] = n;
        }
    }
    std::vector<int> out;
    if (m_.defaultScene >= int(m_.scenes.size()))
        fail(str("the default scene is ", m_.defaultScene, ", but there are ", m_.scenes.size(),
                 " scenes"));
    if (!m_.scenes.empty()) {
        const int s = std::max(0, m_.defaultScene);
        out = m_.scenes[size_t(s)].nodes;
        std::set<int> seen;
        for (int n : out) {
            if (n < 0 || n >= count)
                fail(str("scene ", s, " names node ", n, ", but there are ", count, " nodes"));
            if (parent[size_t(n)] >= 0)
                fail(str("scene ", s, " names node ", n, " ('", nodeName(n),
                         "') as a root, but it is a child of node ", parent[size_t(n)]));
            if (!seen.insert(n).second) fail(str("scene ", s, " names node ", n, " twice"));
        }
    } else {
        for (int n = 0; n < count; ++n)
            if (parent[size_t(n)] < 0) out.push_back(n);
    }
    return out;
}

glm::dmat4 GltfReader::localMatrix(int n) const {
    const tinygltf::Node& node = m_.nodes[size_t(n)];
    auto check = [&](const std::vector<double>& v, size_t size, const char* key) {
        if (!v.empty() && v.size() != size)
            fail(str("node ", n, " ('", nodeName(n), "'): '", key, "' must have ", size,
                     " numbers, has ", v.size()));
        for (double x : v)
            if (!std::isfinite(x))
                fail(str("node ", n, " ('", nodeName(n), "'): '", key, "' is not finite"));
    };
    check(node.matrix, 16, "matrix");
    check(node.translation, 3, "translation");
    check(node.rotation, 4, "rotation");
    check(node.scale, 3, "scale");
    if (!node.matrix.empty()) return glm::make_mat4(node.matrix.data());  // both column-major
    glm::dmat4 m(1.0);
    if (!node.translation.empty())
        m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    if (!node.rotation.empty()) {
        // glTF stores (x, y, z, w); glm's constructor takes w first.
        const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        m = m * glm::mat4_cast(q);
    }
    if (!node.scale.empty())
        m = m * glm::dmat4(glm::dvec4(node.scale[0], 0, 0, 0), glm::dvec4(0, node.scale[1], 0, 0),
                           glm::dvec4(0, 0, node.scale[2], 0), glm::dvec4(0, 0, 0, 1));
    return m;
}

const tinygltf::Value* GltfReader::extension(const tinygltf::ExtensionMap& map,
                                             const char* name) const {
    auto it = map.find(name);
    return it == map.end() ? nullptr : &it->second;
}

double GltfReader::number(const tinygltf::Value& obj, const char* key, double fallback,
                          const std::string& where) const {
    if (!obj.IsObject()) fail(str(where, " must be an object"));
    if (!obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        fail(str(where, ": '", key, "' must be a finite number"));
    return v.GetNumberAsDouble();
}

bool GltfReader::transmissive(int material) const {
    if (material < 0) return false;
    const tinygltf::Material& mat = m_.materials[size_t(material)];
    const tinygltf::Value* t = extension(mat.extensions, kTransmission);
    if (!t) return false;
    // transmissionFactor defaults to 0 (KHR_materials_transmission): the extension alone is opaque.
    return number(*t, "transmissionFactor", 0.0,
                  str("material '", materialName(material), "': ", kTransmission)) > 0.0;
}

Medium GltfReader::medium(int material) const {
    const tinygltf::Material& mat = m_.materials[size_t(material)];
    const std::string where = str("material '", materialName(material), "'");
    Medium m;
    if (const tinygltf::Value* ior = extension(mat.extensions, kIor))
        m.ior = number(*ior, "ior", 1.5, str(where, ": ", kIor));
    if (const tinygltf::Value* vol = extension(mat.extensions, kVolume)) {
        const std::string at = str(where, ": ", kVolume);
        const double distance =
            number(*vol, "attenuationDistance", std::numeric_limits<double>::infinity(), at);
        if (!(distance > 0.0)) fail(str(at, ": 'attenuationDistance' must be > 0"));
        glm::dvec3 color(1.0);
        if (vol->Has("attenuationColor")) {
            const tinygltf::Value& c = vol->Get("attenuationColor");
            if (!c.IsArray() || c.ArrayLen() != 3)
                fail(str(at, ": 'attenuationColor' must be 3 numbers"));
            for (int i = 0; i < 3; ++i) {
                const tinygltf::Value& x = c.Get(i);
                if (!x.IsNumber() || !(x.GetNumberAsDouble() > 0.0 && x.GetNumberAsDouble() <= 1.0))
                    fail(str(at, ": each 'attenuationColor' channel must be a number in (0, 1] "
                                 "(0 would absorb everything: an infinite κ)"));
                color[i] = x.GetNumberAsDouble();
            }
        }
        // κ per unit length such that exp(−κ·attenuationDistance) = attenuationColor; a white
        // channel (or no distance: infinite) absorbs nothing, and is +0, never −0.
        for (int i = 0; i < 3; ++i)
            m.absorption[i] =
                color[i] == 1.0 || std::isinf(distance) ? 0.0 : -std::log(color[i]) / distance;
    }
    const std::string problem = mediumProblem(m);
    if (!problem.empty()) fail(str(where, ": ", problem));
    return m;
}

bool GltfReader::extrasPriority(const tinygltf::Value& extras, const std::string& where,
                                int* out) const {
    if (!extras.IsObject() || !extras.Has(kGltfPriorityKey)) return false;
    const tinygltf::Value& v = extras.Get(kGltfPriorityKey);
    if (!v.IsInt()) fail(str(where, ": extras.", kGltfPriorityKey, " must be an integer"));
    *out = v.GetNumberAsInt();
    return true;
}

ElementView GltfReader::elements(int accessor, const std::string& what, int type,
                                 std::initializer_list<int> componentTypes) const {
    if (accessor < 0 || size_t(accessor) >= m_.accessors.size())
        fail(str(what, ": accessor ", accessor, " does not exist (there are ", m_.accessors.size(),
                 ")"));
    const tinygltf::Accessor& a = m_.accessors[size_t(accessor)];
    const std::string at = str(what, " (accessor ", accessor, ")");
    if (a.type != type ||
        std::find(componentTypes.begin(), componentTypes.end(), a.componentType) ==
            componentTypes.end() ||
        (a.normalized && a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT))
        fail(str(at, ": unexpected type ", a.type, " / componentType ", a.componentType,
                 type == TINYGLTF_TYPE_VEC3 ? " (expected FLOAT VEC3; KHR_mesh_quantization is not "
                                              "supported)"
                                            : " (expected an unsigned SCALAR)"));
    if (a.sparse.isSparse) fail(str(at, ": sparse accessors are not supported"));
    if (a.bufferView < 0 || size_t(a.bufferView) >= m_.bufferViews.size())
        fail(str(at, ": no data (bufferView ", a.bufferView, " of ", m_.bufferViews.size(), ")"));
    const tinygltf::BufferView& bv = m_.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= m_.buffers.size())
        fail(str(at, ": bufferView ", a.bufferView, " names buffer ", bv.buffer, " of ",
                 m_.buffers.size()));
    const std::vector<unsigned char>& data = m_.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
        fail(str(at, ": bufferView ", a.bufferView, " (bytes ", bv.byteOffset, " + ", bv.byteLength,
                 ") reaches past the end of buffer ", bv.buffer, " (", data.size(),
                 " bytes): the buffer is truncated"));
    const size_t elem = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType))) *
                        size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    const size_t stride = bv.byteStride ? bv.byteStride : elem;
    if (stride < elem)
        fail(str(at, ": bufferView ", a.bufferView, " byteStride ", stride,
                 " is smaller than one element (", elem, " bytes)"));
    // The last element must end inside the view: offset + (count - 1) * stride + elem.
    if (a.count > 0 && (a.byteOffset > bv.byteLength || elem > bv.byteLength - a.byteOffset ||
                        (a.count - 1) > (bv.byteLength - a.byteOffset - elem) / stride))
        fail(str(at, ": ", a.count, " elements from byte ", a.byteOffset,
                 " reach past the end of bufferView ", a.bufferView, " (", bv.byteLength,
                 " bytes)"));
    ElementView v;
    v.base = data.data() + bv.byteOffset + a.byteOffset;
    v.stride = stride;
    v.count = a.count;
    v.componentType = a.componentType;
    return v;
}

glm::vec3 readVec3(const ElementView& v, size_t i) {
    glm::vec3 p;
    std::memcpy(&p[0], v.base + i * v.stride, sizeof p);
    return p;
}

uint32_t readIndex(const ElementView& v, size_t i) {
    const unsigned char* at = v.base + i * v.stride;
    switch (v.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return *at;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t x;
            std::memcpy(&x, at, sizeof x);
            return x;
        }
        default: {
            uint32_t x;
            std::memcpy(&x, at, sizeof x);
            return x;
        }
    }
}

GltfReader::Found GltfReader::part(int node, int primitive, const glm::dmat4& world,
                                   const std::string& name) const {
    const tinygltf::Primitive& prim = m_.meshes[size_t(m_.nodes[size_t(node)].mesh)].primitives[size_t(primitive)];
    const std::string where = str("node '", nodeName(node), "' primitive ", primitive);
    if (prim.mode != TINYGLTF_MODE_TRIANGLES)
        fail(str(where, ": mode ", prim.mode, " is not supported (glass must be TRIANGLES, mode 4)"));
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail(str(where, ": no POSITION attribute"));
    const ElementView positions =
        elements(pos->second, where + " POSITION", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});

    MeshArrays a;
    a.positions.resize(positions.count);
    for (size_t i = 0; i < positions.count; ++i) a.positions[i] = readVec3(positions, i);
    if (auto nrm = prim.attributes.find("NORMAL"); nrm != prim.attributes.end()) {
        const ElementView normals = elements(nrm->second, where + " NORMAL", TINYGLTF_TYPE_VEC3,
                                             {TINYGLTF_COMPONENT_TYPE_FLOAT});
        if (normals.count != positions.count)
            fail(str(where, ": NORMAL has ", normals.count, " elements but POSITION has ",
                     positions.count, ": attribute counts must agree"));
        a.normals.resize(normals.count);
        for (size_t i = 0; i < normals.count; ++i) a.normals[i] = readVec3(normals, i);
    }

    std::vector<uint32_t> corners;
    if (prim.indices >= 0) {
        const ElementView idx = elements(prim.indices, where + " indices", TINYGLTF_TYPE_SCALAR,
                                         {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
        corners.resize(idx.count);
        for (size_t i = 0; i < idx.count; ++i) {
            corners[i] = readIndex(idx, i);
            if (corners[i] >= positions.count)
                fail(str(where, ": index ", corners[i], " (element ", i,
                         " of the indices) is out of range: POSITION has ", positions.count,
                         " vertices"));
        }
    } else {
        corners.resize(positions.count);
        for (size_t i = 0; i < corners.size(); ++i) corners[i] = uint32_t(i);
    }
    if (corners.size() % 3 != 0)
        fail(str(where, ": ", corners.size(), prim.indices >= 0 ? " indices" : " vertices",
                 " do not make whole triangles (count must be a multiple of 3)"));

    // Node transforms. An exact identity leaves the file's floats untouched, bit for bit.
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    if (glm::determinant(glm::dmat3(world)) == 0.0)
        fail(str(where, ": its node transform is singular (a zero scale flattens the glass)"));
    for (size_t t = 0; t < corners.size(); t += 3) {
        // A mirroring transform reverses the winding (glTF 2.0 §3.7.4): swap two corners back.
        a.triangles.emplace_back(corners[t], corners[t + (mirrored ? 2 : 1)],
                                 corners[t + (mirrored ? 1 : 2)]);
    }
    if (world != glm::dmat4(1.0)) {
        for (glm::vec3& p : a.positions) p = glm::vec3(world * glm::dvec4(glm::dvec3(p), 1.0));
        const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(world)));
        for (glm::vec3& n : a.normals) n = glm::vec3(normalMatrix * glm::dvec3(n));
    }

    Found f;
    f.part.name = name;
    f.part.meshPath = str(path_, "#", name);
    f.part.medium = medium(prim.material);
    f.part.medium.name = name;
    f.part.mesh = finishMesh(str(path_, ": ", where), a, &f.part.report);
    int priority = 0;
    if (extrasPriority(m_.nodes[size_t(node)].extras, str("node '", nodeName(node), "'"), &priority) ||
        extrasPriority(m_.materials[size_t(prim.material)].extras,
                       str("material '", materialName(prim.material), "'"), &priority)) {
        f.part.medium.priority = priority;
        f.explicitPriority = true;
    }
    return f;
}

// Containment of bounds gives nesting: a part whose box lies inside another's (and is not the same
// box) gets one more than it, so water in a glass gets 2 and the glass 1, and ice in that water 3.
// Parts whose boxes overlap without one holding the other, with different media and the same
// priority, are ambiguous: say so, and name the extras key that settles it.
void GltfReader::assignPriorities(std::vector<Found>& found, std::vector<std::string>& notes) const {
    struct Box {
        glm::vec3 lo, hi;
    };
    std::vector<Box> box;
    for (const Found& f : found) box.push_back({f.part.mesh.boundsMin(), f.part.mesh.boundsMax()});
    auto holds = [&](size_t outer, size_t inner) {
        return glm::all(glm::lessThanEqual(box[outer].lo, box[inner].lo)) &&
               glm::all(glm::greaterThanEqual(box[outer].hi, box[inner].hi)) &&
               (box[outer].lo != box[inner].lo || box[outer].hi != box[inner].hi);
    };
    for (size_t i = 0; i < found.size(); ++i) {
        if (found[i].explicitPriority) continue;
        int depth = 1;
        for (size_t j = 0; j < found.size(); ++j) depth += j != i && holds(j, i);
        found[i].part.medium.priority = depth;
    }
    for (size_t i = 0; i < found.size(); ++i) {
        for (size_t j = i + 1; j < found.size(); ++j) {
            const Medium &a = found[i].part.medium, &b = found[j].part.medium;
            const bool overlap = glm::all(glm::lessThanEqual(box[i].lo, box[j].hi)) &&
                                 glm::all(glm::lessThanEqual(box[j].lo, box[i].hi));
            if (overlap && a.priority == b.priority && !holds(i, j) && !holds(j, i) &&
                (a.ior != b.ior || a.absorption != b.absorption))
                notes.push_back(str(path_, ": parts '", a.name, "' and '", b.name,
                                    "' overlap, neither's bounds hold the other's, and both have "
                                    "priority ", a.priority, ": set extras.", kGltfPriorityKey,
                                    " on a node or material to say which medium wins"));
        }
    }
}

Scene GltfReader::read(std::vector<GltfPlace>* places) {
    checkCompression();
    Scene scene;
    scene.path = path_;
    std::vector<Found> found;
    std::set<std::string> names;
    std::vector<std::pair<int, glm::dmat4>> stack;
    std::vector<int> rootList = roots();
    for (auto it = rootList.rbegin(); it != rootList.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
        const auto [n, parentWorld] = stack.back();
        stack.pop_back();
        const tinygltf::Node& node = m_.nodes[size_t(n)];
        const glm::dmat4 local = localMatrix(n);
        // Skip the product for identity matrices: exact identities keep exact floats.
        const glm::dmat4 world = local == glm::dmat4(1.0) ? parentWorld
                                 : parentWorld == glm::dmat4(1.0) ? local
                                                                  : parentWorld * local;
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.emplace_back(*c, world);
        if (node.mesh < 0) continue;
        if (size_t(node.mesh) >= m_.meshes.size())
            fail(str("node ", n, " ('", nodeName(n), "') names mesh ", node.mesh, ", but there are ",
                     m_.meshes.size(), " meshes"));
        const tinygltf::Mesh& mesh = m_.meshes[size_t(node.mesh)];
        size_t glassCount = 0;
        for (const tinygltf::Primitive& p : mesh.primitives) {
            if (p.material >= int(m_.materials.size()))
                fail(str("node '", nodeName(n), "' names material ", p.material, ", but there are ",
                         m_.materials.size(), " materials"));
            glassCount += transmissive(p.material);
        }
        for (size_t k = 0; k < mesh.primitives.size(); ++k) {
            const tinygltf::Primitive& p = mesh.primitives[k];
            if (!transmissive(p.material)) {
                scene.notes.push_back(str(path_, ": left out node '", nodeName(n), "' primitive ", k,
                                          " (material '", materialName(p.material),
                                          "'): not transmissive, and the bake models dielectrics only"));
                continue;
            }
            std::string name = nodeName(n);
            if (glassCount > 1) name += "/" + materialName(p.material);
            for (int dup = 2; names.count(name); ++dup) {
                name = str(nodeName(n), glassCount > 1 ? "/" + materialName(p.material) : "", "#", dup);
            }
            names.insert(name);
            found.push_back(part(n, int(k), world, name));
            found.back().place = {n, node.mesh, int(k), world};
        }
    }
    if (found.empty()) {
        std::vector<std::string> glassy;
        for (int i = 0; i < int(m_.materials.size()); ++i)
            if (transmissive(i)) glassy.push_back("'" + materialName(i) + "'");
        if (!glassy.empty())
            fail(str("has transmissive materials (", glassy.front(),
                     glassy.size() > 1 ? " and others" : "",
                     ") but no glass triangles: no primitive of the scene's nodes uses them"));
        fail(str("no glass: no primitive of the scene's nodes has a material with ", kTransmission,
                 " and transmissionFactor > 0"));
    }
    assignPriorities(found, scene.notes);
    for (Found& f : found) {
        scene.parts.push_back(std::move(f.part));
        if (places) places->push_back(f.place);
    }
    return scene;
}

}  // namespace

bool isGltfPath(const std::string& path) {
    const std::string ext = lowercaseExtension(path);
    return ext == ".gltf" || ext == ".glb";
}

void readGltfModel(const std::string& path, tinygltf::Model& model, bool keepImages) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw inputError(path, "file not found");
    if (fs::file_size(path, ec) == 0) throw inputError(path, "file is empty");
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keepImages ? keepEncodedImage : skipImage, nullptr);
    loader.SetFsCallbacks({&regularFileExists, &tinygltf::ExpandFilePath, &readRegularFile,
                           &tinygltf::WriteWholeFile, nullptr});
    std::string err, warn;
    const bool ok = lowercaseExtension(path) == ".glb"
                        ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                        : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    if (!ok) {
        while (!err.empty() && std::isspace(static_cast<unsigned char>(err.back()))) err.pop_back();
        throw inputError(path, "could not read glTF: " + (err.empty() ? std::string("unknown error") : err));
    }
}

Scene gltfSceneOf(const std::string& path, const tinygltf::Model& model, std::vector<GltfPlace>* places) {
    return GltfReader(path, model).read(places);
}

Scene loadGltfScene(const std::string& path, std::vector<GltfPlace>* places) {
    tinygltf::Model model;
    readGltfModel(path, model, false);
    return gltfSceneOf(path, model, places);
}

}  // namespace shrefract
