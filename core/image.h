#pragma once
// Plain 8-bit RGB images, and writing them as PNG (libpng) for people to look at.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace costar {

struct RgbImage {
  int width = 0;
  int height = 0;
  /// Row-major, top row first, 3 bytes (R, G, B) per pixel.
  std::vector<std::uint8_t> pixels;

  RgbImage() = default;
  RgbImage(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 3, 0) {}
  std::uint8_t* at(int x, int y) { return &pixels[(static_cast<std::size_t>(y) * width + x) * 3]; }
  const std::uint8_t* at(int x, int y) const { return &pixels[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

/// Writes `image` as a PNG file. @throws std::runtime_error naming the file on failure.
void writePng(const std::filesystem::path& path, const RgbImage& image);

/// Reads an 8-bit RGB or RGBA PNG (alpha dropped). @throws std::runtime_error on failure.
RgbImage readPng(const std::filesystem::path& path);

}  // namespace costar
