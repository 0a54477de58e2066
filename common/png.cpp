#include "common/png.h"

#include <png.h>

#include <cerrno>
#include <cstdio>

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

}  // namespace

void writePngRgb8(const std::string& path, int width, int height, const uint8_t* rgb) {
    writeAtomically(path, [&](const std::string& staged) {
        const std::string target = outputName(staged);
        PngSink sink;
        sink.file = std::fopen(staged.c_str(), "wb");
        if (!sink.file) throw ioError(target, "cannot write", errno);
        png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
        png_infop info = png ? png_create_info_struct(png) : nullptr;
        if (!png || !info || setjmp(png_jmpbuf(png))) {  // libpng reports errors by longjmp here
            png_destroy_write_struct(&png, &info);
            std::fclose(sink.file);
            if (sink.err != 0) throw ioError(target, "cannot write", sink.err);
            throw IoError(target + ": cannot write: libpng failed");
        }
        png_set_write_fn(png, &sink, writeData, flushData);
        png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                     PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
        png_write_info(png, info);
        for (int y = 0; y < height; ++y)
            png_write_row(png, const_cast<uint8_t*>(rgb + static_cast<size_t>(y) * width * 3));
        png_write_end(png, nullptr);
        png_destroy_write_struct(&png, &info);
        errno = 0;
        if (std::fclose(sink.file) != 0) throw ioError(target, "cannot write", errno ? errno : EIO);
    });
}

}  // namespace shrefract
