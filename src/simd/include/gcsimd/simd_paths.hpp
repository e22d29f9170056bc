// GRANULAR-CHARGED shared SIMD layer (gcsimd): macros that compile one kernel body for each
// instruction-set path of gcsimd/simd.hpp (used by the FMM library's kernels and by the
// package's batched JKR root, src/GRANULAR-CHARGED/jkr_scaled.cpp).
#ifndef GCSIMD_SIMD_PATHS_HPP
#define GCSIMD_SIMD_PATHS_HPP

#include "gcsimd/simd.hpp"

#if GCSIMD_X86_DISPATCH
#define GCSIMD_TARGET_AVX2 __attribute__((target("avx2,fma")))
#define GCSIMD_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx2,fma")))
#else
#define GCSIMD_TARGET_AVX2
#define GCSIMD_TARGET_AVX512
#endif
#if defined(__GNUC__)
#define GCSIMD_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GCSIMD_ALWAYS_INLINE inline
#endif

// Defines `ret name##_generic(params)`, `name##_avx2`, `name##_avx512` (the latter two only on
// x86 with GCC/Clang), each calling its always-inlined body (generic, avx2, avx512) with `args`,
// compiled for its ISA, and `name##_for(SimdPath)` returning the function of a path (Generic
// where a path is missing).
#if GCSIMD_X86_DISPATCH
#define GCSIMD_DEFINE_PATH_BODIES(ret, name, params, generic, avx2, avx512, args) \
  ret name##_generic params { return generic args; }                           \
  GCSIMD_TARGET_AVX2 ret name##_avx2 params { return avx2 args; }               \
  GCSIMD_TARGET_AVX512 ret name##_avx512 params { return avx512 args; }         \
  using name##_fn = ret(*) params;                                             \
  inline name##_fn name##_for(::gcsimd::SimdPath p) {                           \
    return p == ::gcsimd::SimdPath::AVX512 ? name##_avx512                      \
           : p == ::gcsimd::SimdPath::AVX2 ? name##_avx2 : name##_generic;      \
  }
#else
#define GCSIMD_DEFINE_PATH_BODIES(ret, name, params, generic, avx2, avx512, args) \
  ret name##_generic params { return generic args; }                           \
  using name##_fn = ret(*) params;                                             \
  inline name##_fn name##_for(::gcsimd::SimdPath) { return name##_generic; }
#endif

// one body for every path
#define GCSIMD_DEFINE_PATHS(ret, name, params, body, args)                 \
  GCSIMD_DEFINE_PATH_BODIES(ret, name, params, body, body, body, args)

// a body template over the width W of the path's registers in doubles (2 generic, 4 AVX2, 8
// AVX-512): kernels whose lanes are GCC/Clang vector-extension types of W doubles, which a
// narrower ISA would split and spill
#define GCSIMD_DEFINE_WIDTH_PATHS(ret, name, params, body, args)           \
  GCSIMD_DEFINE_PATH_BODIES(ret, name, params, body<2>, body<4>, body<8>, args)

#endif
