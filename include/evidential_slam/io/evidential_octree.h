// EvidentialOcTree: an OctoMap tree type whose voxels hold the evidential masses of a cell and its
// anomaly, saved as an OctoMap ".ot" file, and a reader that turns any bad file into an error
// message.
//
// A node keeps OctoMap's own occupancy value (a float log-odds) as the log-odds of BetP(o), so
// generic OctoMap code (ray casting, isNodeOccupied, iterators, bounding boxes) works on the tree
// unchanged, and adds the cell's stored belief: m̃(o), m̃(e) and λ = -ln(1 - m(∅)), the same three
// floats as evidential_slam::Cell (core/mass.h), so a file holds exactly what the grid held, also
// for heavily conflicted cells whose explicit masses would round away; and the cell's anomaly
// (core/anomaly.h, bits). Two node layouts exist, told apart by the tree type id in the file's
// header, which OctoMap's factory (AbstractOcTree::read) dispatches on (docs/octomap.md):
//   id EvidentialOcTree          (layout 1, files written before the anomaly was exported)
//     float32 log-odds of BetP(o) | float32 m̃(o) | float32 m̃(e) | float32 λ | uint8 child bits
//   id EvidentialAnomalyOcTree   (layout 2, written now)
//     the same four floats | float32 anomaly (bits) | uint8 child bits
// Host byte order (little-endian on x86/ARM), like every OctoMap file; the child byte is
// OctoMap's: bit i set = child i follows, depth first.
//
// Both types register themselves with OctoMap's tree factory (AbstractOcTree::read / createTree
// find them by their id) when this library is loaded. Debian links with --as-needed, which
// drops a library used only for that self-registration: the tree's destructor is its key function
// (defined in the .cpp), so a program that names the type at all — a dynamic_cast to
// EvidentialOcTree* after AbstractOcTree::read is enough — keeps the library and its registration.
#pragma once

#include <octomap/OcTreeNode.h>
#include <octomap/OccupancyOcTreeBase.h>

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>

#include "evidential_slam/core/mass.h"

namespace evidential_slam {
namespace io {

// OctoMap occupancy value of a cell: ln(BetP / (1 - BetP)), BetP clamped to [1e-6, 1 - 1e-6] so
// the value stays finite (|value| <= 13.82). A vacuous cell gives 0 (BetP = 0.5).
float occupancyLogOdds(const Cell& cell);

// True when a belief read from a file is one a grid can hold: finite, m̃(o) and m̃(e) in
// [0, 1], m̃(o) + m̃(e) <= 1 (up to float rounding), λ >= 0. (The cell then rounds it to its
// storage; the file holds floats.)
bool isValidStoredCell(float occupied, float free, float lambda);

// Node layout of a file (the comment at the top of this file). One C++ tree type reads and
// writes both; a tree writes its own layout.
enum class EvidentialLayout : int {
  kMasses = 1,         // value, m̃(o), m̃(e), λ
  kMassesAnomaly = 2,  // ... and the anomaly; what exportOctomap writes
};
constexpr EvidentialLayout kLatestEvidentialLayout = EvidentialLayout::kMassesAnomaly;

class EvidentialOcTreeNode : public octomap::OcTreeNode {
 public:
  // Bytes of one node's payload in a file of that layout (without OctoMap's child byte).
  static constexpr size_t payloadBytes(EvidentialLayout layout) {
    return layout == EvidentialLayout::kMasses ? 16 : 20;
  }

  EvidentialOcTreeNode() = default;

  // The belief as a grid cell (rounded to the grid's storage; exact for a node the export wrote).
  Cell cell() const { return Cell::fromStored(occupied_, free_, lambda_); }
  // Sets the belief and the OctoMap value (occupancyLogOdds) together.
  void setCell(const Cell& cell) {
    occupied_ = cell.occupied();
    free_ = cell.free();
    lambda_ = cell.lambda();
    setLogOdds(occupancyLogOdds(cell));
  }
  // m(∅), m(o), m(e), m(Θ) from the node's own floats (as read from a file, not rounded).
  Mass mass() const;
  // The cell's anomaly in bits (0 when none, and in a layout-1 file); finite and >= 0.
  float anomaly() const { return anomaly_; }
  void setAnomaly(float bits) { anomaly_ = bits; }

  // Pruning merges children only when this is true for all of them: equal value, masses and
  // anomaly.
  bool operator==(const EvidentialOcTreeNode& rhs) const {
    return value == rhs.value && occupied_ == rhs.occupied_ && free_ == rhs.free_ &&
           lambda_ == rhs.lambda_ && anomaly_ == rhs.anomaly_;
  }
  void copyData(const EvidentialOcTreeNode& from) {
    OcTreeNode::copyData(from);
    occupied_ = from.occupied_;
    free_ = from.free_;
    lambda_ = from.lambda_;
    anomaly_ = from.anomaly_;
  }

  // File I/O of the payload in `layout` (the top of this file; layout 1 neither reads nor writes
  // the anomaly, which reads as 0). readData sets failbit on a short read and on values no grid
  // can hold (a non-finite value, !isValidStoredCell, an anomaly not finite or below 0).
  std::istream& readData(std::istream& s, EvidentialLayout layout = kLatestEvidentialLayout);
  std::ostream& writeData(std::ostream& s, EvidentialLayout layout = kLatestEvidentialLayout) const;

 private:
  // Floats, as in the file: a node reads and writes any valid payload bit for bit.
  float occupied_ = 0.0f;  // m̃(o)
  float free_ = 0.0f;      // m̃(e)
  float lambda_ = 0.0f;    // λ
  float anomaly_ = 0.0f;   // bits
};

class EvidentialOcTree : public octomap::OccupancyOcTreeBase<EvidentialOcTreeNode> {
 public:
  static const std::string kTreeType;         // "EvidentialOcTree": layout 1's id
  static const std::string kAnomalyTreeType;  // "EvidentialAnomalyOcTree": layout 2's id
  // The id in the file header of a layout, and the layout of an id (false: not ours).
  static const std::string& treeTypeOf(EvidentialLayout layout);
  static bool layoutOf(const std::string& tree_type, EvidentialLayout* layout);

  explicit EvidentialOcTree(double resolution, EvidentialLayout layout = kLatestEvidentialLayout);
  ~EvidentialOcTree() override;  // key function: keep it out of line (see the top of this file)
  // OctoMap's tree copy constructor copies nodes as its own base node type and would lose the
  // masses; no copies.
  EvidentialOcTree(const EvidentialOcTree&) = delete;
  EvidentialOcTree& operator=(const EvidentialOcTree&) = delete;

  EvidentialOcTree* create() const override;  // same layout
  std::string getTreeType() const override;   // treeTypeOf(layout())
  EvidentialLayout layout() const { return layout_; }

  // Creates (or overwrites) the finest-level voxel at `key` with `cell` and `anomaly` (bits);
  // inner nodes are not updated (call updateInnerNodes() once after the last voxel, then prune()).
  EvidentialOcTreeNode* setNodeCell(const octomap::OcTreeKey& key, const Cell& cell,
                                    float anomaly = 0.0f);

  // Every inner node takes the value and masses of its most occupied child, recursively (OctoMap's
  // convention that an inner node carries the maximum occupancy below it, extended to the masses
  // so a node's value is always the log-odds of its own BetP), and the maximum anomaly of its
  // children: the largest change anywhere below, whatever the depth or the slab's height (a sum
  // would grow with both). Pruning merges only equal children, so a pruned leaf keeps the
  // anomaly of each voxel it stands for.
  void updateInnerNodes();

  // Reads the node data after the header (the AbstractOcTree::read path). Unlike OctoMap's own
  // reader it never goes deeper than the tree depth, stops at the first short read or invalid
  // node, and then leaves the tree empty with failbit set on `s` (and a message on stderr, as
  // OctoMap reports its read errors).
  std::istream& readData(std::istream& s) override;
  // Writes the node data in this tree's layout (OctoMap's writer would use the node's default).
  std::ostream& writeData(std::ostream& s) const override;

  // The same, with the node count from the header and a message: false (tree empty) when the data
  // is short, holds an invalid node, a child below the finest level, more or fewer nodes than
  // `expected_nodes`, or bytes after the last node.
  bool readNodes(std::istream& s, uint64_t expected_nodes, std::string* error);

 private:
  bool readNodesRecurs(EvidentialOcTreeNode* node, unsigned depth, std::istream& s,
                       uint64_t max_nodes, uint64_t* count, std::string* error);
  void updateInnerNodesRecurs(EvidentialOcTreeNode* node, unsigned depth);
  void writeNodesRecurs(const EvidentialOcTreeNode* node, std::ostream& s) const;

  EvidentialLayout layout_;

  // Registers a prototype per layout with OctoMap's factory at load time (the pattern of OctoMap's
  // own trees).
  class StaticMemberInitializer {
   public:
    StaticMemberInitializer();
    void ensureLinking() {}
  };
  static StaticMemberInitializer registration_;
};

// Reads an EvidentialOcTree file of either layout written by exportOctomap() (or by
// AbstractOcTree::write on an EvidentialOcTree); the tree's layout() says which. Never throws and
// never crashes on bad input: garbage, a truncated file, a .bt file, another tree type (OcTree,
// ColorOcTree, ...), or masses no grid can hold give false and a one-line `error` that names the
// problem. Checks the header's tree id before any node is read, so OctoMap's unchecked readers
// never see a foreign file.
bool readEvidentialOctree(const std::string& path, std::unique_ptr<EvidentialOcTree>* tree,
                          std::string* error);
// The same from a stream (`name` is used in messages).
bool readEvidentialOctree(std::istream& in, const std::string& name,
                          std::unique_ptr<EvidentialOcTree>* tree, std::string* error);

}  // namespace io
}  // namespace evidential_slam
