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

// a block as WIDTH / W vectors of W lanes: vectors wider than the path's registers would be
// split into register pairs or quadruples by the compiler and spilled to the stack; the lanes
// are independent, so every width gives the same bits
template <int W, bool HISTORY_UPDATE>
GCSIMD_ALWAYS_INLINE void lanes_blocks(std::size_t nblocks, const double *__restrict in,
                                       double *__restrict out)
{
  static_assert(WIDTH % W == 0, "a block holds whole vectors");
  using Vector = typename LanesOf<W>::T;
  using InMemory = typename LanesOf<W>::InMemory;
  constexpr int PARTS = WIDTH / W;
  for (std::size_t b = 0; b < nblocks; ++b)
    for (int part = 0; part < PARTS; ++part) {
      // input q of this part's lanes at [q * WIDTH + part * W]: every PARTS-th vector
      const auto *block_in =
          reinterpret_cast<const InMemory *>(in + b * N_INPUT * WIDTH + part * W);
      auto *block_out = reinterpret_cast<InMemory *>(out + b * N_OUTPUT * WIDTH + part * W);
      marshall_contact<InMemory, Vector, PARTS>(block_in, block_out, HISTORY_UPDATE);
    }
}

// history_update as a constant: each path has one straight body per value
template <int W>
GCSIMD_ALWAYS_INLINE void lanes_body(std::size_t nblocks, const double *in, double *out,
                                     bool history_update)
{
  if (history_update)
    lanes_blocks<W, true>(nblocks, in, out);
  else
    lanes_blocks<W, false>(nblocks, in, out);
}

// each path at its register width: SSE2 2 doubles, AVX2 4, AVX-512 8
#define GC_LANES_PARAMS (std::size_t nblocks, const double *in, double *out, bool history_update)
void lanes_kernel_generic GC_LANES_PARAMS { lanes_body<2>(nblocks, in, out, history_update); }
#if GCSIMD_X86_DISPATCH
GCSIMD_TARGET_AVX2 void lanes_kernel_avx2 GC_LANES_PARAMS
{
  lanes_body<4>(nblocks, in, out, history_update);
}
GCSIMD_TARGET_AVX512 void lanes_kernel_avx512 GC_LANES_PARAMS
{
  lanes_body<8>(nblocks, in, out, history_update);
}
#endif
#undef GC_LANES_PARAMS
using lanes_kernel_fn = void (*)(std::size_t, const double *, double *, bool);
lanes_kernel_fn lanes_kernel_for(gcsimd::SimdPath path)
{
#if GCSIMD_X86_DISPATCH
  if (path == gcsimd::SimdPath::AVX512) return lanes_kernel_avx512;
  if (path == gcsimd::SimdPath::AVX2) return lanes_kernel_avx2;
#endif
  (void) path;
  return lanes_kernel_generic;
}

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
