// GRANULAR-CHARGED FMM core library (gcfmm).
// Dual-tree traversal (target tree against the source tree shifted by each periodic image
// shift) producing the M2L and P2P interaction lists.
//
// Multipole acceptance criterion (MAC) for target node A and source node B shifted by s:
//     r_A + r_B < theta |c_A - (c_B + s)|
// (r: radius of the node's particles about its expansion centre c). Accepted pairs become
// M2L, unless n_A n_B <= pair_limit, where the direct sum is cheaper (then P2P). Rejected
// pairs split the node with the larger radius (a leaf is never split); two rejected leaves
// become P2P. Every (target particle, source particle, shift) triple is covered exactly once.
// Optionally some source nodes are "multipole only" (in a local essential tree,
// doc/fmm-distributed.md: a truncated node, whose multipole is known but not its particles, or
// a node with a truncated descendant, whose particle range is incomplete): an accepted pair
// with such a source is always M2L, a rejected pair (target leaf, such a source leaf) is M2P,
// and such an internal source is split as any other.
#ifndef GCFMM_INTERACTION_LISTS_HPP
#define GCFMM_INTERACTION_LISTS_HPP

#include <cstdint>
#include <vector>

#include "gcfmm/tree.hpp"
#include "gcfmm/types.hpp"

namespace gcfmm {

//! One interaction: the particles/expansion of `source` shifted by shifts[shift] act on `target`.
struct Interaction {
  std::int32_t target;  //!< target node
  std::int32_t source;  //!< source node
  std::int32_t shift;   //!< index into InteractionLists::shifts
};

//! Interaction lists sorted by target node, with CSR offsets.
struct InteractionLists {
  std::vector<Vec3> shifts;               //!< image shifts of the source tree
  std::vector<Interaction> m2l;           //!< multipole-to-local interactions
  std::vector<Interaction> p2p;           //!< direct interactions (node ranges)
  std::vector<std::uint32_t> m2l_offset;  //!< entries of node i: m2l[m2l_offset[i] .. m2l_offset[i+1])
  std::vector<std::uint32_t> p2p_offset;  //!< entries of node i: p2p[p2p_offset[i] .. p2p_offset[i+1])
  std::vector<Interaction> m2p;           //!< multipole evaluated at each particle of a target leaf
                                          //!< (only with multipole-only sources, else empty)
  std::vector<std::uint32_t> m2p_offset;  //!< entries of node i: m2p[m2p_offset[i] .. m2p_offset[i+1])
  std::size_t p2p_pairs = 0;              //!< number of particle pairs in the P2P list
};

/** @brief Build the lists by dual-tree traversal for every shift (targets and sources are the
 *  same particles: the tree against itself, as build_lists(tree, tree, ...)).
 *  @param tree built tree
 *  @param shifts image shifts of the sources (the free-space case is the single shift 0)
 *  @param theta MAC opening angle, 0 < theta < 1
 *  @param pair_limit accepted pairs with n_A n_B <= pair_limit go to P2P instead of M2L
 *  @param lists output */
void build_lists(const Tree &tree, const std::vector<Vec3> &shifts, double theta, double pair_limit,
                 InteractionLists &lists);

/** @brief The same traversal between two trees: the targets' tree against the sources' tree
 *  shifted by each shift (StaticSourceField, DistributedSolver). Interaction::target indexes
 *  `targets`' nodes, Interaction::source `sources`' nodes; the offsets are over the target
 *  nodes. Nothing is assumed about where the targets lie relative to the sources. Either tree
 *  may be empty (no entries).
 *  @param multipole_only null (every source node has all its particles: the lists are
 *         exactly those of the two-tree traversal above, m2p empty) or one flag per source
 *         node, set where the node's particle range lacks some of its particles (its multipole
 *         is complete). Accepted pairs with a flagged source go to M2L whatever pair_limit
 *         says; rejected ones are split as usual, and a rejected pair of a target leaf and a
 *         flagged source leaf goes to the M2P list. The caller must make sure the multipole
 *         converges at those target particles (point MAC r_B < theta |x - c_B - s|, guaranteed
 *         by the LET criterion of doc/fmm-distributed.md) and flag every ancestor of a flagged
 *         node too. */
void build_lists(const Tree &targets, const Tree &sources, const std::vector<Vec3> &shifts, double theta,
                 double pair_limit, InteractionLists &lists, const std::vector<char> *multipole_only = nullptr);

}  // namespace gcfmm

#endif
