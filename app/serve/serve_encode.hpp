// app/serve/serve_encode.hpp — how `sph2d serve` compresses a frame for the browser.
//
// Design: the live frames go out as JPEG (libjpeg-turbo's TurboJPEG API, 4:2:0,
// fast DCT) or as PNG (the renderer's libpng writer at level 1); JPEG is the
// default because it keeps pace at 960×540 (docs/PERFORMANCE.md "sph2d serve").
// GET /snapshot.png is always PNG (lossless, what `sph2d run` writes). Built into
// the sph2d executable, linked with libturbojpeg.
#pragma once

#include <cstdint>
#include <string>

namespace sph2d::cli {

/// The image format of the live frames.
enum class ImageFormat { Jpeg, Png };

/// "jpeg" or "png".
const char* imageFormatName(ImageFormat f);

/// Encodes RGBA8 pixels (rows top-down) as a baseline JPEG of `quality` 1..100 (4:2:0),
/// appending it to `out`. Throws std::runtime_error with TurboJPEG's message.
void appendJpeg(int width, int height, const std::uint8_t* rgba, int quality, std::string& out);

/// Encodes RGBA8 pixels as an RGB PNG (zlib level 1, no filter), appending it to `out`.
/// Throws std::runtime_error.
void appendPng(int width, int height, const std::uint8_t* rgba, std::string& out);

/// Appends the frame in `format` (`quality` for JPEG).
void appendImage(ImageFormat format, int width, int height, const std::uint8_t* rgba, int quality, std::string& out);

}  // namespace sph2d::cli
