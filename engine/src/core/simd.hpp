// core/simd.hpp — which vector instructions a build may use, decided in one place for the pair
// loops that have them (the neighbour filter in step/stages.cpp, pbf's constraint, muller2003's
// pair sums). Every vector path does the scalar reference's operations in the same order, lane
// for lane, so the bits do not depend on it; -DSPH2D_NO_SIMD builds the scalar code alone.
//   SPH2D_SIMD_SSE2          SSE2 intrinsics (the x86-64 baseline): used unconditionally.
//   SPH2D_SIMD_X86_DISPATCH  GCC or Clang on x86-64: wider paths (AVX2, AVX-512) compiled with
//                            __attribute__((target(...))) and chosen at run time by
//                            __builtin_cpu_supports; setBaselineSimdOnly (stages.hpp) turns
//                            them off to compare.
#pragma once

#if defined(__SSE2__) && !defined(SPH2D_NO_SIMD)
#include <emmintrin.h>
#define SPH2D_SIMD_SSE2 1
#endif
#if defined(__GNUC__) && defined(__x86_64__) && !defined(SPH2D_NO_SIMD)
#include <immintrin.h>
#define SPH2D_SIMD_X86_DISPATCH 1
#endif
