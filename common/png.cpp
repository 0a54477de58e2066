#include "common/png.h"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <functional>

#include "common/error.h"
#include "common/output.h"

namespace shrefract {

namespace {

// libpng reports a failed fwrite as png_error("Write Error") and longjmps: keep the OS's reason
// (errno of the failed write) for the message.
struct PngSink {
    FILE* file = nullptr;
    int err = 0;
};

void writeData(png_structp png, png_bytep data, png_size_t length) {
    auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fwrite(data, 1, length, sink->file) != length) {
        sink->err = errno != 0 ? errno : EIO;
        png_error(png, "write failed");
    }
}

void flushData(png_structp png) {
    auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
    if (std::fflush(sink->file) != 0) {
        sink->err = errno != 0 ? errno : EIO;
        png_error(png, "write failed");
    }
}

// Encodes width x height 8-bit pixels of `channels` channels (3: RGB, 4: RGBA) through `write`
// (libpng's write callback and its flush). sRGB: the sRGB chunk (colour); without it the PNG
// carries no colour information at all (data a reader must take as it is).
void encode(png_rw_ptr write, png_flush_ptr flush, void* sinkPtr, int width, int height,
            int channels, const uint8_t* pixels, bool srgb, const std::function<void()>& onError) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info || setjmp(png_jmpbuf(png))) {  // libpng reports errors by longjmp here
        png_destroy_write_struct(&png, &info);
        onError();
        throw IoError("libpng failed");
    }
    png_set_write_fn(png, sinkPtr, write, flush);
    png_set_IHDR(png, info, width, height, 8, channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (srgb) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y)
        png_write_row(png, const_cast<uint8_t*>(pixels + static_cast<size_t>(y) * width * channels));
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
}

void appendData(png_structp png, png_bytep data, png_size_t length) {
    auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + length);
}

void noFlush(png_structp) {}

}  // namespace

void writePngRgb8(const std::string& path, int width, int height, const uint8_t* rgb) {
    writeAtomically(path, [&](const std::string& staged) {
        const std::string target = outputName(staged);
        PngSink sink;
        sink.file = std::fopen(staged.c_str(), "wb");
        if (!sink.file) throw ioError(target, "cannot write", errno);
        encode(writeData, flushData, &sink, width, height, 3, rgb, true, [&] {
            std::fclose(sink.file);
            if (sink.err != 0) throw ioError(target, "cannot write", sink.err);
            throw IoError(target + ": cannot write: libpng failed");
        });
        errno = 0;
        if (std::fclose(sink.file) != 0) throw ioError(target, "cannot write", errno ? errno : EIO);
    });
}

std::vector<uint8_t> encodePngRgba8(int width, int height, const uint8_t* rgba) {
    std::vector<uint8_t> out;
    encode(appendData, noFlush, &out, width, height, 4, rgba, false, [] {});
    return out;
}

}  // namespace shrefract
