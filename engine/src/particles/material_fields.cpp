// material_fields.cpp — see material_fields.hpp.
#include "particles/material_fields.hpp"

#include <algorithm>
#include <cmath>

namespace sph2d {

bool mixes(const std::vector<MaterialDef>& m, std::size_t a, std::size_t b) {
  if (a == b) return true;
  auto lists = [&](std::size_t x, std::size_t y) {
    return std::find(m[x].miscibleWith.begin(), m[x].miscibleWith.end(), m[y].name) != m[x].miscibleWith.end();
  };
  return lists(a, b) || lists(b, a);
}

double tensionBetween(const std::vector<MaterialDef>& m, std::size_t a, std::size_t b) {
  if (a == b) return 0;
  for (const auto& [name, sigma] : m[a].tensionWith)
    if (name == m[b].name) return sigma;
  for (const auto& [name, sigma] : m[b].tensionWith)
    if (name == m[a].name) return sigma;
  return 0;
}

bool anyMiscible(const std::vector<MaterialDef>& m) {
  for (std::size_t a = 0; a < m.size(); ++a)
    for (std::size_t b = a + 1; b < m.size(); ++b)
      if (mixes(m, a, b)) return true;
  return false;
}

void deriveFromConcentrations(ParticleStore& P, const std::vector<MaterialDef>& materials, std::size_t from) {
  const std::size_t K = materials.size();
  std::vector<std::uint32_t>* color = P.findU32(ParticleStore::kMixedColor);
  std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);
  if (!color || !P.findD(ParticleStore::concentration(0))) return;
  std::vector<const double*> conc(K);
  for (std::size_t k = 0; k < K; ++k) conc[k] = P.findD(ParticleStore::concentration(k))->data();
  const double rho0 = materials.front().density;
  for (std::size_t i = from; i < P.size(); ++i) {
    double rgb[3] = {0, 0, 0}, r = 0, total = 0;
    for (std::size_t k = 0; k < K; ++k) {
      const double ck = std::clamp(conc[k][i], 0.0, 1.0);
      for (int ch = 0; ch < 3; ++ch) rgb[ch] += ck * materials[k].color[std::size_t(ch)];
      r += ck * materials[k].density / rho0;
      total += ck;
    }
    if (!(total > 0)) continue;
    std::uint32_t packed = 0;
    for (const double v : rgb)
      packed = (packed << 8) | std::uint32_t(std::lround(std::clamp(v / total, 0.0, 1.0) * 255));
    (*color)[i] = packed;
    if (ratio) (*ratio)[i] = Real(r / total);
  }
}

}  // namespace sph2d
