// GRANULAR-CHARGED shared SIMD layer (gcsimd), below both the FMM library (src/fmm) and the
// contact kernels (src/GRANULAR-CHARGED/jkr_scaled.cpp).
// Runtime choice of the instruction set of the hot kernels, so that a portable build (no
// -march=native) runs the best code the CPU has: each hot kernel is written once as an
// always-inlined body and compiled three times, for the baseline ISA, for AVX2 + FMA and for
// AVX-512 (GCC/Clang function target attributes); the path is chosen once from the CPU
// (__builtin_cpu_supports); gcsimd/simd_paths.hpp has the macros.
#ifndef GCSIMD_SIMD_HPP
#define GCSIMD_SIMD_HPP

namespace gcsimd {

//! Instruction-set paths of the hot kernels, slowest first.
enum class SimdPath { Generic = 0, AVX2 = 1, AVX512 = 2 };

/** @brief true if this build has the path and the CPU runs it (Generic always). */
bool simd_path_available(SimdPath path);

/** @brief The path used by default: the best available one, capped by the environment
 *  variable GCFMM_SIMD (generic, avx2 or avx512; for benchmarks and tests; the name the
 *  FMM library's documentation gives it). */
SimdPath default_simd_path();

/** @brief Name of a path ("generic", "avx2", "avx512"). */
const char *simd_path_name(SimdPath path);

}  // namespace gcsimd

#endif
