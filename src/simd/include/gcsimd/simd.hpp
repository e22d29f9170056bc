// GRANULAR-CHARGED shared SIMD layer (gcsimd), below both the FMM library (src/fmm) and the
// contact kernels (src/GRANULAR-CHARGED/jkr_scaled.cpp).
// Runtime choice of the instruction set of the hot kernels, so that a portable build (no
// -march=native) runs the best code the CPU has: each hot kernel is written once as an
// always-inlined body and compiled three times, for the baseline ISA, for AVX2 + FMA and for
// AVX-512 (GCC/Clang function target attributes); the path is chosen once from the CPU
// (__builtin_cpu_supports); gcsimd/simd_paths.hpp has the macros.
#ifndef GCSIMD_SIMD_HPP
#define GCSIMD_SIMD_HPP

// 1 where this build has the x86 paths (GCC/Clang function target attributes), 0 where it
// has the generic path only
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define GCSIMD_X86_DISPATCH 1
#else
#define GCSIMD_X86_DISPATCH 0
#endif

namespace gcsimd {

//! The environment variable that caps the path (generic, avx2 or avx512), and its deprecated
//! alias, read only when the first is unset.
constexpr const char *kMaxPathVariable = "GCSIMD_MAX_PATH";
constexpr const char *kMaxPathVariableAlias = "GCFMM_SIMD";

//! Instruction-set paths of the hot kernels, slowest first.
enum class SimdPath { Generic = 0, AVX2 = 1, AVX512 = 2 };

/** @brief true if this build has the path and the CPU runs it (Generic always). */
bool simd_path_available(SimdPath path);

/** @brief The path used by default: the best available one, capped by the environment
 *  variable GCSIMD_MAX_PATH (generic, avx2 or avx512; for benchmarks and tests), or by
 *  GCFMM_SIMD when GCSIMD_MAX_PATH is unset. */
SimdPath default_simd_path();

/** @brief Name of a path ("generic", "avx2", "avx512"). */
const char *simd_path_name(SimdPath path);

}  // namespace gcsimd

#endif
