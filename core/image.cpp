#include "core/image.h"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace costar {

namespace {

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

}  // namespace

void writePng(const std::filesystem::path& path, const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw std::runtime_error("cannot write '" + path.string() + "': the image is empty or inconsistent");
  }
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
  if (!file) {
    throw std::runtime_error("cannot write '" + path.string() + "': " + std::strerror(errno));
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng could not start writing '" + path.string() + "'");
  }
  errno = 0;
  if (setjmp(png_jmpbuf(png))) {
    // libpng stops at a failed fwrite ("Write Error"): errno says why.
    const int error = errno;
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("cannot write '" + path.string() +
                             "': " + (error != 0 ? std::strerror(error) : "libpng failed"));
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png, const_cast<png_bytep>(image.at(0, y)));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  // The stream's buffer holds the end of the image: a full disk shows only when it is written.
  const bool flushed = std::fflush(file.get()) == 0 && std::ferror(file.get()) == 0;
  const int error = errno;
  if (std::fclose(file.release()) != 0 || !flushed) {
    throw std::runtime_error("cannot write '" + path.string() + "': " + std::strerror(flushed ? errno : error));
  }
}

RgbImage readPng(const std::filesystem::path& path) {
  png_image reader{};
  reader.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&reader, path.c_str()) == 0) {
    throw std::runtime_error("cannot read PNG '" + path.string() + "': " + reader.message);
  }
  reader.format = PNG_FORMAT_RGB;
  RgbImage image(static_cast<int>(reader.width), static_cast<int>(reader.height));
  if (png_image_finish_read(&reader, nullptr, image.pixels.data(), 0, nullptr) == 0) {
    png_image_free(&reader);
    throw std::runtime_error("cannot decode PNG '" + path.string() + "': " + reader.message);
  }
  return image;
}

}  // namespace costar
