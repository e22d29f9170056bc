// GRANULAR-CHARGED FMM benchmarks: small helpers shared by the benchmark programs.
#ifndef GCFMM_BENCH_UTIL_HPP
#define GCFMM_BENCH_UTIL_HPP

#include <cstdlib>
#include <string>
#include <vector>

namespace gcfmm_bench {

// a comma-separated list of numbers ("2000,20000") as a vector
template <class T>
std::vector<T> list(const char *s) {
  std::vector<T> v;
  std::string str(s);
  std::size_t a = 0;
  while (a <= str.size()) {
    std::size_t b = str.find(',', a);
    if (b == std::string::npos) b = str.size();
    v.push_back(static_cast<T>(std::atof(str.substr(a, b - a).c_str())));
    a = b + 1;
  }
  return v;
}

}  // namespace gcfmm_bench

#endif
