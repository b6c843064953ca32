#pragma once
// Stage 1 of the pipeline: a per-pixel temporal median over the last N organized frames
// (the paper's noise reduction before segmentation).

#include <cstdint>
#include <span>
#include <vector>

#include "camera/rgbd.h"
#include "perception/cloud.h"

namespace costar::perception {

/// The per-pixel median of `frames` (same intrinsics, same camera pose, in capture order).
/// A pixel is valid in the result only if more than half of its samples are valid; its
/// point is the valid sample of median depth (the lower median for an even count), so the
/// result stays in the optical frame of the inputs. Colour, pose and stamp come from the last
/// frame. Only pixels inside `region` are filtered (the rest are invalid); an empty region
/// means the whole image. Runs on up to `threads` threads (the result does not depend on it).
/// @throws std::invalid_argument if `frames` is empty or the frames differ in size.
camera::RgbdFrame medianFrame(std::span<const camera::RgbdFrame> frames, PixelRect region = {}, int threads = 1);

/// The same, for the pixels where `mask` (one byte per pixel, row-major) is non-zero only.
/// @throws std::invalid_argument as above, or if the mask has the wrong size.
camera::RgbdFrame medianFrame(std::span<const camera::RgbdFrame> frames, const std::vector<std::uint8_t>& mask,
                              int threads = 1);

}  // namespace costar::perception
