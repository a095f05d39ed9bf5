// render_options.cpp — the names of the particles mode's colour fields (renderer.hpp).
// Kept apart from the GL passes so that code reading a manifest's render options (the
// manifest reader, its fuzz target) needs no GL.
#include <string>

#include "sph2d/render/renderer.hpp"

namespace sph2d {

bool parseColorField(const std::string& s, ColorField& out) {
  if (s == "speed")
    out = ColorField::Speed;
  else if (s == "pressure")
    out = ColorField::Pressure;
  else if (s == "density")
    out = ColorField::Density;
  else if (s == "age")
    out = ColorField::Age;
  else if (s == "color")
    out = ColorField::Color;
  else if (s == "material")
    out = ColorField::Material;
  else
    return false;
  return true;
}

std::string colorFieldName(ColorField f) {
  switch (f) {
    case ColorField::Speed:
      return "speed";
    case ColorField::Pressure:
      return "pressure";
    case ColorField::Density:
      return "density";
    case ColorField::Age:
      return "age";
    case ColorField::Color:
      return "color";
    case ColorField::Material:
      return "material";
  }
  return "?";
}

bool parseSplatPath(const std::string& s, SplatPath& out) {
  if (s == "auto")
    out = SplatPath::Auto;
  else if (s == "gl")
    out = SplatPath::Gl;
  else if (s == "cpu")
    out = SplatPath::Cpu;
  else
    return false;
  return true;
}

std::string splatPathName(SplatPath p) {
  switch (p) {
    case SplatPath::Gl:
      return "gl";
    case SplatPath::Cpu:
      return "cpu";
    case SplatPath::Auto:
      break;
  }
  return "auto";
}

}  // namespace sph2d
