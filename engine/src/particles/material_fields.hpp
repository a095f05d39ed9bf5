// particles/material_fields.hpp (internal) — the per-particle fields that follow the
// materials (docs/SCENES.md, materials): which materials mix, and each particle's mixed colour
// and rest ratio from its concentrations. Shared by the World (making particles, load) and the
// mixing effect; outside the effect modules, so a build without them (SPH2D_NO_EFFECT_MODULES)
// still makes particles.
#pragma once

#include <cstddef>
#include <vector>

#include "particles/particle_store.hpp"
#include "sph2d/scene.hpp"

namespace sph2d {

/// True when materials a and b of `m` mix: the same material, or either lists the other in
/// miscible_with.
bool mixes(const std::vector<MaterialDef>& m, std::size_t a, std::size_t b);
/// True when two materials of `m` mix: the mixing effect and its particle fields exist.
bool anyMiscible(const std::vector<MaterialDef>& m);
/// The interface tension σ [N/m] between materials a and b of `m` (either's tension_with naming
/// the other; 0 for none, and for a material with itself).
double tensionBetween(const std::vector<MaterialDef>& m, std::size_t a, std::size_t b);
/// From each particle's concentrations (slots ≥ `from`): its mixed colour and, with a density
/// contrast, its rest ratio Σ_k c_k ρ0_k/ρ0 (nothing without the mixing fields).
void deriveFromConcentrations(ParticleStore& P, const std::vector<MaterialDef>& materials, std::size_t from);

}  // namespace sph2d
