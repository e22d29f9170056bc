// GRANULAR-CHARGED shared SIMD layer (gcsimd) alone: the default path and the environment
// variable that caps it (GCSIMD_MAX_PATH, with GCFMM_SIMD its deprecated alias).
#include "gcsimd/simd.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <tuple>
#include <vector>

using gcsimd::SimdPath;

namespace {

// the best path of this build and CPU, by the same availability test the layer uses
SimdPath best_available()
{
  for (SimdPath p : {SimdPath::AVX512, SimdPath::AVX2})
    if (gcsimd::simd_path_available(p)) return p;
  return SimdPath::Generic;
}

// the default path's name (readable in a failure message)
const char *chosen()
{
  return gcsimd::simd_path_name(gcsimd::default_simd_path());
}

// sets (or, with nullptr, unsets) both variables for one test and restores them after it
class MaxPathVariables : public ::testing::Test {
 protected:
  void SetUp() override
  {
    for (const char *name : {gcsimd::kMaxPathVariable, gcsimd::kMaxPathVariableAlias}) {
      const char *v = std::getenv(name);
      saved.emplace_back(name, v ? std::string(v) : std::string(), v != nullptr);
      ::unsetenv(name);
    }
  }
  void TearDown() override
  {
    for (const auto &[name, value, was_set] : saved) {
      if (was_set) ::setenv(name, value.c_str(), 1);
      else ::unsetenv(name);
    }
  }
  static void set(const char *max_path, const char *alias)
  {
    if (max_path) ::setenv(gcsimd::kMaxPathVariable, max_path, 1);
    else ::unsetenv(gcsimd::kMaxPathVariable);
    if (alias) ::setenv(gcsimd::kMaxPathVariableAlias, alias, 1);
    else ::unsetenv(gcsimd::kMaxPathVariableAlias);
  }
  std::vector<std::tuple<const char *, std::string, bool>> saved;
};

}    // namespace

TEST_F(MaxPathVariables, NamesAreThoseOfTheManual)
{
  EXPECT_STREQ(gcsimd::kMaxPathVariable, "GCSIMD_MAX_PATH");
  EXPECT_STREQ(gcsimd::kMaxPathVariableAlias, "GCFMM_SIMD");
}

TEST_F(MaxPathVariables, UnsetGivesTheBestPathTheCpuHas)
{
  set(nullptr, nullptr);
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(best_available()));
}

TEST_F(MaxPathVariables, EachNameAloneCapsThePath)
{
  set("generic", nullptr);
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(SimdPath::Generic));
  set(nullptr, "generic");
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(SimdPath::Generic))
      << "the alias GCFMM_SIMD is not read";
  // a cap above the CPU's best path gives the best path
  set("avx512", nullptr);
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(best_available()));
  set(nullptr, "avx512");
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(best_available()));
}

TEST_F(MaxPathVariables, TheNewNameWinsWhenBothAreSet)
{
  // on a CPU with the generic path only, every cap gives the same path: nothing to tell apart
  if (best_available() == SimdPath::Generic) GTEST_SKIP() << "the CPU has the generic path only";
  set("generic", "avx512");
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(SimdPath::Generic));
  set("avx512", "generic");
  EXPECT_STREQ(chosen(), gcsimd::simd_path_name(best_available()));
}
