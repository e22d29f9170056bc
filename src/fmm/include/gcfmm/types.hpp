// GRANULAR-CHARGED FMM core library (gcfmm).
// Basic types shared by all layers. No LAMMPS headers.
#ifndef GCFMM_TYPES_HPP
#define GCFMM_TYPES_HPP

#include <cstddef>
#include <functional>

namespace gcfmm {

//! pi, for every source file of the library (one definition)
inline constexpr double kPi = 3.14159265358979323846;

/// Sums `count` doubles element by element over all work partitions, in place, the same result
/// on every partition (an MPI_Allreduce with MPI_SUM, for example). Given to evaluate(), it
/// lets the partitions split work each would otherwise repeat; every element it sums is
/// nonzero on at most one partition, so the sum is exact and the results stay bit-identical
/// to one partition.
using PartSum = std::function<void(double *data, std::size_t count)>;

//! A point or vector in 3D.
struct Vec3 {
  double x = 0.0;  //!< x component
  double y = 0.0;  //!< y component
  double z = 0.0;  //!< z component
};

inline Vec3 operator+(const Vec3 &a, const Vec3 &b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3 &a, const Vec3 &b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, const Vec3 &a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const Vec3 &a, const Vec3 &b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double norm2(const Vec3 &a) { return dot(a, a); }

}  // namespace gcfmm

#endif
