// GRANULAR-CHARGED shared SIMD layer (gcsimd): choice of the instruction-set path
// (include/gcsimd/simd.hpp).
#include "gcsimd/simd.hpp"

#include <cstdlib>
#include <cstring>

namespace gcsimd {

bool simd_path_available(SimdPath path) {
  switch (path) {
    case SimdPath::Generic:
      return true;
#if GCSIMD_X86_DISPATCH
    case SimdPath::AVX2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case SimdPath::AVX512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
    default:
      return false;
  }
}

SimdPath default_simd_path() {
  SimdPath cap = SimdPath::AVX512;
  const char *e = std::getenv(kMaxPathVariable);
  if (!e) e = std::getenv(kMaxPathVariableAlias);
  if (e) {
    if (!std::strcmp(e, "generic")) cap = SimdPath::Generic;
    else if (!std::strcmp(e, "avx2")) cap = SimdPath::AVX2;
  }
  for (int p = static_cast<int>(cap); p > 0; --p)
    if (simd_path_available(static_cast<SimdPath>(p))) return static_cast<SimdPath>(p);
  return SimdPath::Generic;
}

const char *simd_path_name(SimdPath path) {
  switch (path) {
    case SimdPath::AVX2: return "avx2";
    case SimdPath::AVX512: return "avx512";
    default: return "generic";
  }
}

}  // namespace gcsimd
