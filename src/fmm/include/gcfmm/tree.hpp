// GRANULAR-CHARGED FMM core library (gcfmm).
// Adaptive octree by recursive bisection of cubes: a node is split into its (non-empty)
// octants only when it holds more than `leaf` particles, so a dense bed and a few sparse
// particles far above both stay cheap. Particles are stored sorted (depth-first octant
// order), so every node owns a contiguous range [begin, end) of the sorted arrays.
#ifndef GCFMM_TREE_HPP
#define GCFMM_TREE_HPP

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gcfmm/types.hpp"

namespace gcfmm {

//! One node (cube) of the octree.
struct Node {
  Vec3 center;            //!< expansion centre: centre of the bounding box of its particles
  double radius = 0.0;    //!< max distance of its particles from `center`
  std::uint32_t begin = 0;  //!< first particle (sorted order)
  std::uint32_t end = 0;    //!< one past the last particle
  std::int32_t child = -1;  //!< index of the first child (children are contiguous), -1 for a leaf
  std::int32_t nchild = 0;  //!< number of (non-empty) children
  std::int32_t parent = -1; //!< parent index, -1 for the root
  std::int32_t level = 0;   //!< depth, root = 0
  bool leaf() const { return nchild == 0; }
  std::uint32_t count() const { return end - begin; }
};

//! The geometric cube of a node: the octants are split about its centre (not the expansion
//! centre Node::center, which is the centre of the particles' bounding box).
struct Cube {
  Vec3 center;         //!< centre of the cube
  double half = 0.0;   //!< half side
};

//! Adaptive octree over a set of points.
class Tree {
 public:
  /** @brief Build the tree.
   *  @param n number of particles; x, y, z their positions (already wrapped if periodic)
   *  @param leaf split a node only when it holds more than `leaf` particles
   *  Children always have larger indices than their parent (node 0 is the root). */
  void build(std::size_t n, const double *x, const double *y, const double *z, int leaf);

  std::vector<Node> nodes;          //!< all nodes, root first, children contiguous
  std::vector<Cube> cubes;          //!< geometric cube of each node (parallel to nodes)
  std::vector<std::uint32_t> perm;  //!< sorted position k holds original particle perm[k]
  std::vector<double> xs, ys, zs;   //!< sorted positions
  std::vector<std::int32_t> leaves; //!< leaf node indices in particle order
  int levels = 0;                   //!< number of levels (max depth + 1)

 private:
  void split(std::int32_t node, int leaf, std::vector<std::uint32_t> &scratch);
};

}  // namespace gcfmm

#endif
