/* ----------------------------------------------------------------------
   LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator
   https://www.lammps.org/, Sandia National Laboratories
   LAMMPS development team: developers@lammps.org

   This file is part of the GRANULAR-CHARGED package, distributed under
   the GNU General Public License (same terms as LAMMPS).
------------------------------------------------------------------------- */

// Compiled with -ffp-contract=off -fno-math-errno -fno-trapping-math (CMakeLists.txt): every
// path must give the scalar instantiation's result bit for bit, so no fused multiply-adds;
// without errno the square root of a vector is one vector instruction.
#include "marshall_lanes.h"

#include "gcsimd/simd.hpp"
#include "gcsimd/simd_paths.hpp"


namespace {

using namespace LAMMPS_NS::MarshallLanes;

template <bool HISTORY_UPDATE>
GCSIMD_ALWAYS_INLINE void lanes_blocks(std::size_t nblocks, const double *__restrict in,
                                       double *__restrict out)
{
  for (std::size_t b = 0; b < nblocks; ++b) {
    // the block read and written in place, one vector per input and output
    const auto *block_in = reinterpret_cast<const LanesInMemory *>(in + b * N_INPUT * WIDTH);
    auto *block_out = reinterpret_cast<LanesInMemory *>(out + b * N_OUTPUT * WIDTH);
    marshall_contact<LanesInMemory, Lanes>(block_in, block_out, HISTORY_UPDATE);
  }
}

// history_update as a constant: each path has one straight body per value
GCSIMD_ALWAYS_INLINE void lanes_body(std::size_t nblocks, const double *in, double *out,
                                     bool history_update)
{
  if (history_update)
    lanes_blocks<true>(nblocks, in, out);
  else
    lanes_blocks<false>(nblocks, in, out);
}

#define GC_LANES_PARAMS (std::size_t nblocks, const double *in, double *out, bool history_update)
#define GC_LANES_ARGS (nblocks, in, out, history_update)
GCSIMD_DEFINE_PATHS(void, lanes_kernel, GC_LANES_PARAMS, lanes_body, GC_LANES_ARGS)

}    // namespace

namespace LAMMPS_NS {
namespace MarshallLanes {

void contacts_in_lanes(std::size_t nblocks, const double *in, double *out, bool history_update,
                       gcsimd::SimdPath path)
{
  if (!gcsimd::simd_path_available(path)) path = gcsimd::SimdPath::Generic;
  lanes_kernel_for(path)(nblocks, in, out, history_update);
}

void contacts_in_lanes(std::size_t nblocks, const double *in, double *out, bool history_update)
{
  static const gcsimd::SimdPath path = gcsimd::default_simd_path();
  lanes_kernel_for(path)(nblocks, in, out, history_update);
}

}    // namespace MarshallLanes
}    // namespace LAMMPS_NS
