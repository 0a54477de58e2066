#include "common/evalbuffer.h"

#include <cstdio>
#include <filesystem>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>

#include "common/error.h"
#include "common/exr_input.h"
#include "common/exr_output.h"
#include "common/output.h"

namespace shrefract {

namespace {

const char* const kChannels[7] = {"R", "G", "B", "A", "dir.X", "dir.Y", "dir.Z"};

// Slice of channel c: colour (vec4) for 0..3, direction (vec3) for 4..6.
Imf::Slice sliceOf(EvalBuffer& b, int c) {
    if (c < 4)
        return Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(&b.color[0][c]), sizeof(glm::vec4),
                          sizeof(glm::vec4) * b.width);
    return Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(&b.direction[0][c - 4]),
                      sizeof(glm::vec3), sizeof(glm::vec3) * b.width);
}

}  // namespace

EvalBuffer makeEvalBuffer(int width, int height, const std::vector<float>& colorRgba,
                          const std::vector<float>& directionRgba) {
    EvalBuffer b;
    b.width = width;
    b.height = height;
    const size_t n = b.pixelCount();
    SHREFRACT_CHECK(colorRgba.size() == 4 * n && directionRgba.size() == 4 * n);
    b.color.resize(n);
    b.direction.resize(n);
    for (size_t i = 0; i < n; ++i) {
        const bool covered = directionRgba[4 * i + 3] > 0.5f;
        b.color[i] = glm::vec4(colorRgba[4 * i], colorRgba[4 * i + 1], colorRgba[4 * i + 2],
                               covered ? 1.0f : 0.0f);
        b.direction[i] = covered ? glm::vec3(directionRgba[4 * i], directionRgba[4 * i + 1],
                                             directionRgba[4 * i + 2])
                                 : glm::vec3(0.0f);
    }
    return b;
}

void writeEvalBuffer(const std::string& path, const EvalBuffer& buffer) {
    SHREFRACT_CHECK(buffer.color.size() == buffer.pixelCount() &&
                    buffer.direction.size() == buffer.pixelCount());
    EvalBuffer& b = const_cast<EvalBuffer&>(buffer);  // OpenEXR slices take char*; only read
    Imf::Header header(b.width, b.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.insert("shrefractEval", Imf::IntAttribute(1));
    Imf::FrameBuffer fb;
    for (int c = 0; c < 7; ++c) {
        header.channels().insert(kChannels[c], Imf::Channel(Imf::FLOAT));
        fb.insert(kChannels[c], sliceOf(b, c));
    }
    writeAtomically(path, [&](const std::string& staged) {
        writeExrFile(staged, [&](Imf::OStream& stream) {
            Imf::OutputFile file(stream, header);
            file.setFrameBuffer(fb);
            file.writePixels(b.height);
        });
    });
}

EvalBuffer readEvalBuffer(const std::string& path) {
    EvalBuffer b;
    if (!std::filesystem::is_regular_file(path)) throw inputError(path, "file not found");
    checkExrHeaders(path);  // before OpenEXR allocates what a damaged header claims
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i dw = file.header().dataWindow();
        b.width = dw.max.x - dw.min.x + 1;
        b.height = dw.max.y - dw.min.y + 1;
        for (const char* c : kChannels)
            if (!file.header().channels().findChannel(c))
                throw std::runtime_error(std::string("no channel ") + c +
                                         " (not an evaluation buffer: docs/format.md)");
        b.color.assign(b.pixelCount(), glm::vec4(0.0f));
        b.direction.assign(b.pixelCount(), glm::vec3(0.0f));
        Imf::FrameBuffer fb;
        for (int c = 0; c < 7; ++c) {
            Imf::Slice s = sliceOf(b, c);
            // The data window may not start at (0, 0): slices address absolute pixel positions.
            s.base -= (dw.min.x + static_cast<ptrdiff_t>(dw.min.y) * b.width) * s.xStride;
            fb.insert(kChannels[c], s);
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
    } catch (const std::exception& e) {
        throw inputError(path, std::string("cannot read evaluation buffer: ") + e.what());
    }
    return b;
}

}  // namespace shrefract
