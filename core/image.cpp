#include "core/image.h"

#include <png.h>

#include <stdexcept>
#include <string>

#include "core/files.h"

namespace costar {

void writePng(const std::filesystem::path& path, const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw std::runtime_error("cannot write '" + path.string() + "': the image is empty or inconsistent");
  }
  // Encoded in memory, then written checked (writeOutputFile): a full disk, a missing folder or
  // a pipe nobody reads is named as such, and a regular file is replaced whole. libpng's errors
  // come back through setjmp below; its own handler would print "libpng error: ..." as well.
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, nullptr, [](png_structp failed, png_const_charp) { png_longjmp(failed, 1); },
      [](png_structp, png_const_charp) {});
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng could not start writing '" + path.string() + "'");
  }
  std::string encoded;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("cannot write '" + path.string() + "': libpng could not encode the image");
  }
  png_set_write_fn(
      png, &encoded,
      [](png_structp writer, png_bytep data, png_size_t length) {
        static_cast<std::string*>(png_get_io_ptr(writer))->append(reinterpret_cast<const char*>(data), length);
      },
      nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png, const_cast<png_bytep>(image.at(0, y)));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  writeOutputFile(path, encoded);
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
