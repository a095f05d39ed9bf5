// sph2d/render/render_env.hpp — the process environment that llvmpipe's pixels depend on:
// the Mesa settings sph2d pins before the first OSMesa context, and the CPU features that
// llvmpipe generates code for. Both are recorded in manifests so that `sph2d check` can say
// why a frame differs. (Included by renderer.hpp.)
#pragma once

#include <string>
#include <vector>

namespace sph2d {

/// One environment variable that can affect llvmpipe, as the renderer found or set it.
struct EnvSetting {
  std::string name;    ///< e.g. "LP_NUM_THREADS"
  std::string value;   ///< "" when unset
  std::string source;  ///< "user" (set before sph2d ran), "sph2d" (pinned by pinRenderEnvironment) or "unset"
};

/// Pins, before the first OSMesa context of the process, the Mesa settings that can change
/// pixels or make runs depend on the user's home (GALLIUM_DRIVER=llvmpipe, no shader cache),
/// unless the user set them; returns every setting that matters, pinned or not, for the
/// manifest. Called by the Renderer constructor; later calls only report.
std::vector<EnvSetting> pinRenderEnvironment();

/// The names of the settings pinRenderEnvironment() records, without pinning anything
/// (what `sph2d check` accepts from a manifest's environment).
std::vector<std::string> recordedEnvironmentNames();

/// The CPU features that llvmpipe's code generation depends on (from /proc/cpuinfo),
/// e.g. "AMD EPYC; avx avx2 fma f16c avx512f".
std::string cpuSummary();

}  // namespace sph2d
