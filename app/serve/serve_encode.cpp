// app/serve/serve_encode.cpp — JPEG (TurboJPEG) and PNG (libpng) encoding of live frames; see serve_encode.hpp.
#include "serve/serve_encode.hpp"

#include <turbojpeg.h>

#include <stdexcept>
#include <vector>

#include "sph2d/render/png_io.hpp"

namespace sph2d::cli {

const char* imageFormatName(ImageFormat f) { return f == ImageFormat::Jpeg ? "jpeg" : "png"; }

void appendJpeg(int width, int height, const std::uint8_t* rgba, int quality, std::string& out) {
  // One compressor per thread: TurboJPEG handles are not shared between threads.
  struct Handle {
    tjhandle h = tjInitCompress();
    ~Handle() {
      if (h) tjDestroy(h);
    }
  };
  thread_local Handle handle;
  if (!handle.h) throw std::runtime_error("TurboJPEG: cannot create a compressor");
  unsigned char* buf = nullptr;
  unsigned long size = 0;
  if (tjCompress2(handle.h, rgba, width, 0, height, TJPF_RGBA, &buf, &size, TJSAMP_420, quality, TJFLAG_FASTDCT) != 0) {
    const std::string why = tjGetErrorStr2(handle.h);
    if (buf) tjFree(buf);
    throw std::runtime_error("TurboJPEG: " + why);
  }
  out.append(reinterpret_cast<const char*>(buf), size);
  tjFree(buf);
}

void appendPng(int width, int height, const std::uint8_t* rgba, std::string& out) {
  thread_local std::vector<std::uint8_t> png;
  encodePng(width, height, rgba, pngSettings(1), png);
  out.append(reinterpret_cast<const char*>(png.data()), png.size());
}

void appendImage(ImageFormat format, int width, int height, const std::uint8_t* rgba, int quality, std::string& out) {
  if (format == ImageFormat::Jpeg)
    appendJpeg(width, height, rgba, quality, out);
  else
    appendPng(width, height, rgba, out);
}

}  // namespace sph2d::cli
