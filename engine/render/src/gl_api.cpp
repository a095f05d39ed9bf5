// gl_api.cpp — the two tables of OpenGL functions (see gl_api.hpp). The only source of
// sph2d::render that names gl* symbols: the linked table takes their addresses.
#define SPH2D_GL_API_NO_MACROS 1
#include "gl_api.hpp"

#include <stdexcept>
#include <string>
#include <type_traits>

namespace sph2d::gl {
namespace {

// Constant-initialised: valid before any constructor runs, on every thread.
const Api kLinked = {
#define SPH2D_GL_LINKED(name) &::gl##name,
    SPH2D_GL_FUNCTIONS(SPH2D_GL_LINKED)
#undef SPH2D_GL_LINKED
        "linked"};

Api resolveOsmesa() {
  Api a{};
  auto get = [](auto& slot, const char* name) {
    const OSMESAproc p = OSMesaGetProcAddress(name);
    if (!p)
      throw std::runtime_error(std::string("OSMesa has no ") + name +
                               " (OSMesaGetProcAddress): sph2d's renderer needs Mesa's OSMesa with OpenGL 3.3");
    slot = reinterpret_cast<std::remove_reference_t<decltype(slot)>>(p);
  };
#define SPH2D_GL_RESOLVE(name) get(a.name, "gl" #name);
  SPH2D_GL_FUNCTIONS(SPH2D_GL_RESOLVE)
#undef SPH2D_GL_RESOLVE
  a.source = "OSMesaGetProcAddress";
  return a;
}

}  // namespace

namespace detail {
thread_local const Api* current = &kLinked;
}  // namespace detail

const Api& linkedApi() { return kLinked; }

const Api& osmesaApi() {
  static const Api a = resolveOsmesa();  // a throw leaves it unmade: the next call tries again
  return a;
}

}  // namespace sph2d::gl
