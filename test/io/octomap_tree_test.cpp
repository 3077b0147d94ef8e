// EvidentialOcTree: node layout, pruning, export round trip, OctoMap's own code on the tree, the
// .bt and .color.ot contents, and the reader's errors on bad files.
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <tuple>

#include "child_process.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/io/evidential_octree.h"
#include "evidential_slam/io/octomap_export.h"
#include "octomap_test_support.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;
using octomap::OcTreeKey;

OcTreeKey keyOf(const CellIndex& c, int kz = 32768) {
  return OcTreeKey(static_cast<uint16_t>(c.x + 32768), static_cast<uint16_t>(c.y + 32768),
                   static_cast<uint16_t>(kz));
}

std::string exportGrid(const EvidentialGridMap& grid, const fs::path& dir,
                       const OctomapExportConfig& config = OctomapExportConfig(),
                       OctomapExportResult* result = nullptr) {
  OctomapExportResult local;
  std::string error;
  const std::string prefix = (dir / "map").string();
  EXPECT_TRUE(exportOctomap(grid, config, prefix, result ? result : &local, &error)) << error;
  return prefix;
}

std::unique_ptr<EvidentialOcTree> readOrDie(const std::string& path) {
  std::unique_ptr<EvidentialOcTree> tree;
  std::string error;
  EXPECT_TRUE(readEvidentialOctree(path, &tree, &error)) << error;
  return tree;
}

// ---- node and tree --------------------------------------------------------------------------

TEST(EvidentialOcTreeNode, PayloadIsTwentyBytesWithTheAnomalyAndRoundTrips) {
  EvidentialOcTreeNode node;
  node.setCell(Cell::fromStored(0.6f, 0.1f, 0.3f));
  node.setAnomaly(2.75f);
  std::ostringstream out;
  node.writeData(out);
  const std::string bytes = out.str();
  ASSERT_EQ(bytes.size(), 20u);
  ASSERT_EQ(EvidentialOcTreeNode::payloadBytes(EvidentialLayout::kMassesAnomaly), 20u);
  float v[5];
  std::memcpy(v, bytes.data(), sizeof(v));
  EXPECT_EQ(v[4], 2.75f);
  EXPECT_EQ(v[0], occupancyLogOdds(node.cell()));
  // The cell's stored values (quantised: m̃ in steps of 2^-23, λ a half float).
  EXPECT_EQ(v[1], node.cell().occupied());
  EXPECT_EQ(v[2], node.cell().free());
  EXPECT_EQ(v[3], node.cell().lambda());
  EXPECT_NEAR(v[1], 0.6f, 1e-5f);
  EXPECT_NEAR(v[2], 0.1f, 1e-5f);
  EXPECT_NEAR(v[3], 0.3f, 2e-4f);

  std::istringstream in(bytes);
  EvidentialOcTreeNode back;
  ASSERT_TRUE(back.readData(in));
  EXPECT_TRUE(back == node);
  EXPECT_EQ(back.anomaly(), 2.75f);
  EXPECT_FLOAT_EQ(back.getLogOdds(), node.getLogOdds());
}

TEST(EvidentialOcTreeNode, LayoutOneIsSixteenBytesWithoutTheAnomaly) {
  EvidentialOcTreeNode node;
  node.setCell(Cell::fromStored(0.5f, 0.25f, 1.5f));
  node.setAnomaly(4.0f);
  std::ostringstream out;
  node.writeData(out, EvidentialLayout::kMasses);
  const std::string bytes = out.str();
  ASSERT_EQ(bytes.size(), 16u);
  ASSERT_EQ(EvidentialOcTreeNode::payloadBytes(EvidentialLayout::kMasses), 16u);
  float v[4];
  std::memcpy(v, bytes.data(), sizeof(v));
  EXPECT_EQ(v[1], 0.5f);
  EXPECT_EQ(v[2], 0.25f);
  EXPECT_EQ(v[3], 1.5f);
  std::istringstream in(bytes);
  EvidentialOcTreeNode back;
  ASSERT_TRUE(back.readData(in, EvidentialLayout::kMasses));
  EXPECT_TRUE(back.cell() == node.cell());
  EXPECT_EQ(back.anomaly(), 0.0f);  // layout 1 holds none
  EXPECT_EQ(in.peek(), std::char_traits<char>::eof());
}
TEST(EvidentialOcTreeNode, ValueIsTheLogOddsOfBetP) {
  EXPECT_EQ(occupancyLogOdds(Cell{}), 0.0f);  // vacuous: BetP 0.5
  const Cell wall = Cell::fromStored(0.9f, 0.05f, 0.0f);
  const double p = pignistic(wall);
  EXPECT_NEAR(occupancyLogOdds(wall), std::log(p / (1 - p)), 1e-5);
  EXPECT_GT(occupancyLogOdds(wall), 0.0f);
  EXPECT_LT(occupancyLogOdds(Cell::fromStored(0.0f, 0.8f, 0.0f)), 0.0f);
  // Certain cells stay finite.
  EXPECT_NEAR(occupancyLogOdds(Cell::fromStored(1.0f, 0.0f, 0.0f)), std::log(1e6), 1e-3);
  EXPECT_NEAR(occupancyLogOdds(Cell::fromStored(0.0f, 1.0f, 0.0f)), -std::log(1e6), 1e-3);
}

TEST(EvidentialOcTreeNode, ReadRejectsValuesNoGridCanHold) {
  const float nan = std::nanf("");
  const float inf = INFINITY;
  const std::vector<std::array<float, 4>> bad = {
      {nan, 0.5f, 0.1f, 0.0f},  {inf, 0.5f, 0.1f, 0.0f},  {0.0f, nan, 0.1f, 0.0f},
      {0.0f, 0.5f, inf, 0.0f},  {0.0f, 0.5f, 0.1f, nan},  {0.0f, -0.5f, 0.1f, 0.0f},
      {0.0f, 1.5f, 0.0f, 0.0f}, {0.0f, 0.7f, 0.7f, 0.0f}, {0.0f, 0.5f, 0.1f, -1.0f},
  };
  for (const auto& v : bad) {
    std::istringstream in(std::string(reinterpret_cast<const char*>(v.data()), sizeof(v)));
    EvidentialOcTreeNode node;
    node.readData(in, EvidentialLayout::kMasses);
    EXPECT_TRUE(in.fail()) << v[0] << " " << v[1] << " " << v[2] << " " << v[3];
    EXPECT_FALSE(in.eof());
  }
  // Layout 2: the same masses are fine, the anomaly must be finite and >= 0.
  for (float anomaly : {nan, inf, -inf, -0.5f}) {
    const float v[5] = {0.0f, 0.5f, 0.1f, 0.0f, anomaly};
    std::istringstream in(std::string(reinterpret_cast<const char*>(v), sizeof(v)));
    EvidentialOcTreeNode node;
    node.readData(in);
    EXPECT_TRUE(in.fail()) << anomaly;
    EXPECT_FALSE(in.eof());
  }
  {
    const float v[5] = {0.0f, 0.5f, 0.1f, 0.0f, 0.0f};
    std::istringstream in(std::string(reinterpret_cast<const char*>(v), sizeof(v)));
    EvidentialOcTreeNode node;
    EXPECT_TRUE(node.readData(in));
  }
  std::istringstream short_in(std::string(10, '\0'));
  EvidentialOcTreeNode node;
  node.readData(short_in);
  EXPECT_TRUE(short_in.fail());
  EXPECT_TRUE(short_in.eof());
}

// Fills the 8 finest voxels under one parent.
void fillOctant(EvidentialOcTree* tree, const std::array<Cell, 8>& cells,
                const std::array<float, 8>& anomaly = {}) {
  for (int i = 0; i < 8; ++i) {
    const OcTreeKey key(static_cast<uint16_t>(32768 + (i & 1)),
                        static_cast<uint16_t>(32768 + ((i >> 1) & 1)),
                        static_cast<uint16_t>(32768 + ((i >> 2) & 1)));
    ASSERT_NE(tree->setNodeCell(key, cells[i], anomaly[i]), nullptr);
  }
  tree->updateInnerNodes();
}

TEST(EvidentialOcTree, PrunesOnlyChildrenWithEqualMasses) {
  const Cell free_cell = Cell::fromStored(0.0f, 0.8f, 0.0f);
  std::array<Cell, 8> equal;
  equal.fill(free_cell);
  EvidentialOcTree same(0.05);
  fillOctant(&same, equal);
  const size_t before = same.size();
  same.prune();
  EXPECT_EQ(same.size(), before - 8);
  EXPECT_EQ(same.getNumLeafNodes(), 1u);
  const EvidentialOcTreeNode* merged = same.search(OcTreeKey(32769, 32769, 32769));
  ASSERT_NE(merged, nullptr);
  EXPECT_TRUE(merged->cell() == free_cell);

  // Same BetP (so the same OctoMap value) but different masses: OctoMap's own rule would merge
  // these; ours must not.
  std::array<Cell, 8> balanced;
  balanced.fill(Cell::fromStored(0.25f, 0.25f, 0.0f));
  balanced[5] = Cell::fromStored(0.125f, 0.125f, 0.0f);
  ASSERT_EQ(occupancyLogOdds(balanced[0]), occupancyLogOdds(balanced[5]));
  EvidentialOcTree differ(0.05);
  fillOctant(&differ, balanced);
  const size_t unpruned = differ.size();
  differ.prune();
  EXPECT_EQ(differ.size(), unpruned);
  EXPECT_EQ(differ.getNumLeafNodes(), 8u);

  // Equal masses, different conflict.
  std::array<Cell, 8> conflict = equal;
  conflict[2].setLambda(0.5f);
  EvidentialOcTree lambda_differs(0.05);
  fillOctant(&lambda_differs, conflict);
  lambda_differs.prune();
  EXPECT_EQ(lambda_differs.getNumLeafNodes(), 8u);
}

TEST(EvidentialOcTree, PrunesOnlyChildrenWithEqualAnomaly) {
  std::array<Cell, 8> cells;
  cells.fill(Cell::fromStored(0.0f, 0.8f, 0.0f));
  std::array<float, 8> anomaly;
  anomaly.fill(1.5f);
  EvidentialOcTree same(0.05);
  fillOctant(&same, cells, anomaly);
  same.prune();
  EXPECT_EQ(same.getNumLeafNodes(), 1u);
  // The pruned leaf stands for eight voxels of 1.5 bits each.
  EXPECT_EQ(same.search(OcTreeKey(32768, 32769, 32768))->anomaly(), 1.5f);
  anomaly[5] = 1.25f;
  EvidentialOcTree differ(0.05);
  fillOctant(&differ, cells, anomaly);
  differ.prune();
  EXPECT_EQ(differ.getNumLeafNodes(), 8u);
}

TEST(EvidentialOcTree, InnerNodesCarryTheLargestAnomalyBelow) {
  // The most occupied child (3) holds no anomaly; the largest (6: 2.5 bits) is in a free one.
  std::array<Cell, 8> cells;
  cells.fill(Cell::fromStored(0.0f, 0.8f, 0.0f));
  cells[3] = Cell::fromStored(0.7f, 0.1f, 0.2f);
  const std::array<float, 8> anomaly = {0.0f, 0.5f, 0.0f, 0.0f, 1.0f, 0.0f, 2.5f, 0.0f};
  EvidentialOcTree tree(0.05);
  fillOctant(&tree, cells, anomaly);
  size_t inner = 0;
  for (auto it = tree.begin_tree(), end = tree.end_tree(); it != end; ++it) {
    if (it.isLeaf()) continue;
    ++inner;
    EXPECT_EQ(it->anomaly(), 2.5f) << "depth " << it.getDepth();
    EXPECT_TRUE(it->cell() == cells[3]);
  }
  EXPECT_EQ(inner, 16u);  // root to the octant's parent
}

TEST(EvidentialOcTree, InnerNodesCarryTheirMostOccupiedChild) {
  std::array<Cell, 8> cells;
  cells.fill(Cell::fromStored(0.0f, 0.8f, 0.0f));
  cells[3] = Cell::fromStored(0.7f, 0.1f, 0.2f);
  cells[6] = Cell::fromStored(0.4f, 0.1f, 0.0f);
  EvidentialOcTree tree(0.05);
  fillOctant(&tree, cells);
  for (auto it = tree.begin_tree(), end = tree.end_tree(); it != end; ++it) {
    EXPECT_FLOAT_EQ(it->getLogOdds(), occupancyLogOdds(it->cell())) << "depth " << it.getDepth();
    if (it.isLeaf()) continue;
    EXPECT_TRUE(it->cell() == cells[3]);
  }
}

// ---- export and read back -------------------------------------------------------------------

void expectRoundTrip(const EvidentialGridMap& grid, const OctomapExportConfig& config,
                     int expected_layers, const fs::path& dir) {
  OctomapExportResult result;
  const AnomalyGrid anomaly = test::makeTestAnomaly();
  std::string error;
  const std::string prefix = (dir / "map").string();
  ASSERT_TRUE(exportOctomap(grid, anomaly, config, prefix, &result, &error)) << error;
  const auto cells = test::observedCells(grid);
  ASSERT_GT(cells.size(), 2500u);
  EXPECT_EQ(result.z_layers, expected_layers);
  EXPECT_EQ(result.observed_cells, cells.size());
  EXPECT_EQ(result.voxels, cells.size() * expected_layers);
  ASSERT_EQ(result.files.size(), 3u);
  for (const auto& f : result.files) {
    EXPECT_EQ(f.bytes, fs::file_size(f.path)) << f.path;
    EXPECT_FALSE(fs::exists(f.path + ".tmp"));
  }
  EXPECT_EQ(result.files[0].path, prefix + ".evidential.ot");
  EXPECT_EQ(result.files[1].path, prefix + ".bt");
  EXPECT_EQ(result.files[2].path, prefix + ".color.ot");

  const auto tree = readOrDie(prefix + ".evidential.ot");
  ASSERT_TRUE(tree);
  EXPECT_EQ(tree->layout(), EvidentialLayout::kMassesAnomaly);
  EXPECT_DOUBLE_EQ(tree->getResolution(), grid.resolution());
  EXPECT_EQ(tree->size(), result.files[0].nodes);
  size_t anomaly_voxels = 0;
  octomap::key_type kz0 = 0;
  ASSERT_TRUE(tree->coordToKeyChecked(config.z_min, kz0));
  size_t mismatches = 0;
  double max_diff = 0.0;
  for (const auto& o : cells) {
    for (int layer = 0; layer < expected_layers; ++layer) {
      const EvidentialOcTreeNode* node = tree->search(keyOf(o.index, kz0 + layer));
      ASSERT_NE(node, nullptr) << o.index.x << "," << o.index.y << " layer " << layer;
      // The stored floats are the grid's, bit for bit...
      if (!(node->cell() == o.cell)) {
        ++mismatches;
      }
      // ... so all four masses agree.
      const Mass a = node->mass(), b = o.cell.toMass();
      for (double d : {a.conflict - b.conflict, a.occupied - b.occupied, a.free - b.free,
                       a.unknown - b.unknown}) {
        max_diff = std::max(max_diff, std::abs(d));
      }
      EXPECT_FLOAT_EQ(node->getLogOdds(), occupancyLogOdds(o.cell));
      // The anomaly, bit for bit.
      EXPECT_EQ(node->anomaly(), anomaly.at(o.index.x, o.index.y));
      anomaly_voxels += node->anomaly() > 0.0f;
    }
  }
  EXPECT_EQ(anomaly_voxels, static_cast<size_t>(test::kTestAnomalyObservedCells) * expected_layers);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_LE(max_diff, 1e-7);
  // No voxel outside the observed cells of the slab.
  uint64_t voxels = 0;
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const uint64_t side = uint64_t{1} << (tree->getTreeDepth() - it.getDepth());
    voxels += side * side * side;
  }
  EXPECT_EQ(voxels, cells.size() * expected_layers);
}

TEST(OctomapExport, RoundTripOneLayerAtZeroByDefault) {
  const fs::path dir = test::scratchDir();
  expectRoundTrip(test::makeTestGrid(), OctomapExportConfig(), 1, dir);
  const auto tree = readOrDie((dir / "map.evidential.ot").string());
  double x0, y0, z0, x1, y1, z1;
  tree->getMetricMin(x0, y0, z0);
  tree->getMetricMax(x1, y1, z1);
  EXPECT_NEAR(z0, 0.0, 1e-9);
  EXPECT_NEAR(z1, 0.05, 1e-6);
  EXPECT_NEAR(x0, -40 * 0.05, 1e-6);  // the conflicted cell at (-40, 25)
  EXPECT_NEAR(x1, 54 * 0.05, 1e-6);   // the free block ends at x = 53
}

TEST(OctomapExport, RoundTripMultiLayerSlabIsPruned) {
  OctomapExportConfig config;
  config.z_min = -0.1;   // voxel -2: [-0.10, -0.05)
  config.z_max = 0.149;  // voxel 2: [0.10, 0.15)
  const fs::path dir = test::scratchDir();
  expectRoundTrip(test::makeTestGrid(), config, 5, dir);
  // Columns of equal voxels merge (at least the 4x4 block of identical free cells did).
  const auto tree = readOrDie((dir / "map.evidential.ot").string());
  EXPECT_LT(tree->getNumLeafNodes(), test::observedCells(test::makeTestGrid()).size() * 5);
}

TEST(OctomapExport, RoundTripAtAnotherResolution) {
  const fs::path dir = test::scratchDir();
  OctomapExportConfig config;
  config.z_min = config.z_max = 1.0;
  expectRoundTrip(test::makeTestGrid(0.1), config, 1, dir);
}

TEST(OctomapExport, OctomapsOwnFactoryRecreatesTheTree) {
  const fs::path dir = test::scratchDir();
  const std::string prefix = exportGrid(test::makeTestGrid(), dir);
  std::unique_ptr<octomap::AbstractOcTree> base(
      octomap::AbstractOcTree::read(prefix + ".evidential.ot"));
  ASSERT_TRUE(base);
  EXPECT_EQ(base->getTreeType(), "EvidentialAnomalyOcTree");
  auto* tree = dynamic_cast<EvidentialOcTree*>(base.get());
  ASSERT_NE(tree, nullptr);
  EXPECT_EQ(tree->layout(), EvidentialLayout::kMassesAnomaly);
  const auto checked = readOrDie(prefix + ".evidential.ot");
  ASSERT_EQ(tree->size(), checked->size());
  std::ostringstream a, b;
  tree->writeData(a);
  checked->writeData(b);
  EXPECT_EQ(a.str(), b.str());
}

// Layout 2 with hand-chosen values: two cells, one slab layer; every float of the file checked.
TEST(OctomapExport, MassesAndAnomalyRoundTripExactly) {
  EvidentialGridMap grid(0.05);
  grid.mutableCell(0, 0) = Cell::fromStored(0.5f, 0.25f, 0.0f);
  grid.mutableCell(1, 0) = Cell::fromStored(0.0f, 0.75f, 0.5f);
  AnomalyGrid anomaly;
  anomaly.add(1, 0, 3.25f);
  anomaly.add(1, 0, 0.5f);  // accumulated: 3.75 bits
  const fs::path dir = test::scratchDir();
  OctomapExportResult result;
  std::string error;
  ASSERT_TRUE(
      exportOctomap(grid, anomaly, OctomapExportConfig(), (dir / "map").string(), &result, &error))
      << error;
  const std::string file = test::readText(dir / "map.evidential.ot");
  EXPECT_NE(file.find("\nid EvidentialAnomalyOcTree\n"), std::string::npos);
  const auto tree = readOrDie((dir / "map.evidential.ot").string());
  ASSERT_TRUE(tree);
  const EvidentialOcTreeNode* a = tree->search(keyOf({0, 0}));
  const EvidentialOcTreeNode* b = tree->search(keyOf({1, 0}));
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  // (0, 0): m(o) = 0.5, m(e) = 0.25, m(Θ) = 0.25, no conflict, no anomaly.
  EXPECT_EQ(a->mass().occupied, 0.5);
  EXPECT_EQ(a->mass().free, 0.25);
  EXPECT_EQ(a->mass().unknown, 0.25);
  EXPECT_EQ(a->mass().conflict, 0.0);
  EXPECT_EQ(a->anomaly(), 0.0f);
  // (1, 0): λ = 0.5: m(∅) = 1 - e^-0.5 = 0.39346934, m(e) = 0.75 e^-0.5 = 0.45489799,
  // m(Θ) = 0.25 e^-0.5 = 0.15163266; 3.75 bits.
  EXPECT_NEAR(b->mass().conflict, 0.39346934, 1e-8);
  EXPECT_EQ(b->mass().occupied, 0.0);
  EXPECT_NEAR(b->mass().free, 0.45489799, 1e-8);
  EXPECT_NEAR(b->mass().unknown, 0.15163266, 1e-8);
  EXPECT_EQ(b->anomaly(), 3.75f);
  // The last node written is (1, 0)'s voxel: its five floats, then no children.
  ASSERT_GE(file.size(), 21u);
  float v[5];
  std::memcpy(v, file.data() + file.size() - 21, sizeof(v));
  EXPECT_EQ(v[1], 0.0f);
  EXPECT_EQ(v[2], 0.75f);
  EXPECT_EQ(v[3], 0.5f);
  EXPECT_EQ(v[4], 3.75f);
  EXPECT_EQ(file.back(), '\0');
  // The root: the most occupied child's masses ((0, 0)), the largest anomaly below.
  EXPECT_TRUE(tree->getRoot()->cell() == grid.cell(0, 0));
  EXPECT_EQ(tree->getRoot()->anomaly(), 3.75f);
}

// test/data/octomap_masses_v1.evidential.ot was written by the exporter's tree before the anomaly
// was exported (layout 1, id EvidentialOcTree): four cells at 0.05 m, one layer, with
// (m̃(o), m̃(e), λ) = (0,0): (0.5, 0.25, 0), (1,0): (0, 0.75, 0.5), (-2,3): (0.125, 0.375, 1.5),
// (5,-4): (1, 0, 0.25).
TEST(OctomapExport, FilesOfTheOldLayoutStillLoad) {
  const std::string path = test::dataPath("octomap_masses_v1.evidential.ot");
  const auto tree = readOrDie(path);
  ASSERT_TRUE(tree);
  EXPECT_EQ(tree->layout(), EvidentialLayout::kMasses);
  EXPECT_EQ(tree->getTreeType(), "EvidentialOcTree");
  EXPECT_DOUBLE_EQ(tree->getResolution(), 0.05);
  EXPECT_EQ(tree->getNumLeafNodes(), 4u);
  struct Expected {
    CellIndex index;
    double conflict, occupied, free, unknown;
  };
  // m(∅) = 1 - e^-λ, m(X) = e^-λ m̃(X).
  const Expected expected[] = {
      {{0, 0}, 0.0, 0.5, 0.25, 0.25},
      {{1, 0}, 0.39346934, 0.0, 0.45489799, 0.15163266},
      {{-2, 3}, 0.77686984, 0.02789127, 0.08367381, 0.11156508},
      {{5, -4}, 0.22119922, 0.77880078, 0.0, 0.0},
  };
  for (const Expected& e : expected) {
    const EvidentialOcTreeNode* node = tree->search(keyOf(e.index));
    ASSERT_NE(node, nullptr) << e.index.x << "," << e.index.y;
    const Mass m = node->mass();
    EXPECT_NEAR(m.conflict, e.conflict, 1e-8) << e.index.x << "," << e.index.y;
    EXPECT_NEAR(m.occupied, e.occupied, 1e-8) << e.index.x << "," << e.index.y;
    EXPECT_NEAR(m.free, e.free, 1e-8) << e.index.x << "," << e.index.y;
    EXPECT_NEAR(m.unknown, e.unknown, 1e-8) << e.index.x << "," << e.index.y;
    EXPECT_EQ(node->anomaly(), 0.0f);
  }
  // Written back in its own layout, the file is unchanged byte for byte.
  std::ostringstream out;
  tree->write(out);
  EXPECT_EQ(out.str(), test::readText(path));
  // OctoMap's own factory finds the old type too.
  std::unique_ptr<octomap::AbstractOcTree> base(octomap::AbstractOcTree::read(path));
  auto* via_factory = dynamic_cast<EvidentialOcTree*>(base.get());
  ASSERT_NE(via_factory, nullptr);
  EXPECT_EQ(via_factory->layout(), EvidentialLayout::kMasses);
  EXPECT_EQ(via_factory->size(), tree->size());
}

TEST(OctomapExport, GenericOctomapCodeWorksOnTheTree) {
  // A corridor: free cells x = 0..39 on y = 0, a wall at x = 40, one balanced cell at x = 42.
  EvidentialGridMap grid(0.05);
  for (int x = 0; x < 40; ++x) updateCell(grid.mutableCell(x, 0), ScanMass{0.0f, 0.8f});
  updateCell(grid.mutableCell(40, 0), ScanMass{0.63f, 0.0f});
  grid.mutableCell(42, 0) = Cell::fromStored(0.2f, 0.2f, 0.0f);
  const fs::path dir = test::scratchDir();
  const auto tree = readOrDie(exportGrid(grid, dir) + ".evidential.ot");
  ASSERT_TRUE(tree);
  // isNodeOccupied: BetP(o) >= 0.5.
  EXPECT_FALSE(tree->isNodeOccupied(tree->search(0.5, 0.025, 0.025)));
  EXPECT_TRUE(tree->isNodeOccupied(tree->search(2.025, 0.025, 0.025)));
  EXPECT_TRUE(tree->isNodeOccupied(tree->search(2.125, 0.025, 0.025)));
  EXPECT_EQ(tree->search(2.075, 0.025, 0.025), nullptr);  // never observed: unknown
  // Ray casting through the free cells stops at the wall.
  octomap::point3d end;
  ASSERT_TRUE(tree->castRay(octomap::point3d(0.025f, 0.025f, 0.025f),
                            octomap::point3d(1.0f, 0.0f, 0.0f), end));
  EXPECT_NEAR(end.x(), 2.025, 1e-4);
  // Leaf iterator over everything stored.
  size_t leaves = 0;
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) ++leaves;
  EXPECT_EQ(leaves, 42u);
}

TEST(OctomapExport, BinaryFileHoldsBetPThresholdedAtOneHalf) {
  const EvidentialGridMap grid = test::makeTestGrid();
  const fs::path dir = test::scratchDir();
  const std::string prefix = exportGrid(grid, dir);
  octomap::OcTree bt(0.1);
  ASSERT_TRUE(bt.readBinary(prefix + ".bt"));
  EXPECT_DOUBLE_EQ(bt.getResolution(), 0.05);
  size_t occupied = 0, free = 0;
  for (const auto& o : test::observedCells(grid)) {
    const octomap::OcTreeNode* node = bt.search(keyOf(o.index));
    ASSERT_NE(node, nullptr);
    const bool expect_occupied = pignistic(o.cell) >= 0.5;
    EXPECT_EQ(bt.isNodeOccupied(node), expect_occupied) << o.index.x << "," << o.index.y;
    ++(expect_occupied ? occupied : free);
  }
  EXPECT_GT(occupied, 50u);
  EXPECT_GT(free, 1000u);
  // An unobserved hole stays unknown.
  EXPECT_EQ(bt.search(keyOf(CellIndex{0, 0})), nullptr);
  ASSERT_FALSE(grid.cell(0, 0).observed());
}

TEST(OctomapExport, ColorFileHoldsTheMassesAsRgb) {
  const EvidentialGridMap grid = test::makeTestGrid();
  const fs::path dir = test::scratchDir();
  const std::string prefix = exportGrid(grid, dir);
  std::unique_ptr<octomap::AbstractOcTree> base(
      octomap::AbstractOcTree::read(prefix + ".color.ot"));
  auto* color = dynamic_cast<octomap::ColorOcTree*>(base.get());
  ASSERT_NE(color, nullptr);
  for (const auto& o : test::observedCells(grid)) {
    const octomap::ColorOcTreeNode* node = color->search(keyOf(o.index));
    ASSERT_NE(node, nullptr);
    const Mass m = o.cell.toMass();
    const auto c = node->getColor();
    EXPECT_EQ(c.r, std::lround(255 * m.occupied));
    EXPECT_EQ(c.g, std::lround(255 * m.free));
    EXPECT_EQ(c.b, std::lround(255 * m.unknown));
    EXPECT_FLOAT_EQ(node->getLogOdds(), occupancyLogOdds(o.cell));
  }
}

TEST(OctomapExport, EmptyGridGivesEmptyTrees) {
  const fs::path dir = test::scratchDir();
  OctomapExportResult result;
  const std::string prefix = exportGrid(EvidentialGridMap(0.05), dir, {}, &result);
  EXPECT_EQ(result.voxels, 0u);
  const auto tree = readOrDie(prefix + ".evidential.ot");
  ASSERT_TRUE(tree);
  EXPECT_EQ(tree->size(), 0u);
}

TEST(OctomapExport, RefusesBadConfigAndUnwritableOutput) {
  std::string why;
  OctomapExportConfig config;
  EXPECT_TRUE(config.isValid(&why)) << why;
  config.z_min = 1.0;
  EXPECT_FALSE(config.isValid(&why));
  config = OctomapExportConfig();
  config.z_max = NAN;
  EXPECT_FALSE(config.isValid(&why));
  config = OctomapExportConfig();
  config.max_layers = 0;
  EXPECT_FALSE(config.isValid(&why));

  const fs::path dir = test::scratchDir();
  const EvidentialGridMap grid = test::makeTestGrid();
  OctomapExportResult result;
  std::string error;
  config = OctomapExportConfig();
  config.z_max = 20.0;  // 401 layers at 0.05 m
  EXPECT_FALSE(exportOctomap(grid, config, (dir / "thick").string(), &result, &error));
  EXPECT_NE(error.find("voxel layers"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "thick.evidential.ot"));

  EXPECT_FALSE(exportOctomap(grid, OctomapExportConfig(), (dir / "no/such/dir/map").string(),
                             &result, &error));
  EXPECT_NE(error.find("cannot write"), std::string::npos) << error;

  EvidentialGridMap far(0.05);
  updateCell(far.mutableCell(40000, 0), ScanMass{0.0f, 0.8f});
  EXPECT_FALSE(exportOctomap(far, OctomapExportConfig(), (dir / "far").string(), &result, &error));
  EXPECT_NE(error.find("range"), std::string::npos) << error;
}

// The three files replace the old ones together: an export that fails on the second (here no
// file may grow past 64 kB, as on a full disk) leaves all three old files as they were.
TEST(OctomapExport, AFailedExportLeavesThePreviousFiles) {
  const fs::path dir = test::scratchDir();
  const std::string prefix = (dir / "map").string();
  EvidentialGridMap small(0.05);
  updateCell(small.mutableCell(0, 0), ScanMass{0.0f, 0.8f});
  OctomapExportResult result;
  std::string error;
  ASSERT_TRUE(exportOctomap(small, OctomapExportConfig(), prefix, &result, &error)) << error;
  std::vector<std::string> before;
  for (const auto& f : result.files) before.push_back(test::readText(f.path));
  const EvidentialGridMap big = test::makeTestGrid();
  OctomapExportConfig thick;
  thick.z_max = 0.5;  // 11 layers: the evidential tree is far above 64 kB
  const int status = test::runInChild(
      [&] {
        OctomapExportResult r;
        std::string why;
        if (exportOctomap(big, thick, prefix, &r, &why)) return 1;
        return why.find("': File too large") != std::string::npos ? 0 : 2;
      },
      64 * 1024);
  EXPECT_EQ(status, 0);
  for (size_t i = 0; i < result.files.size(); ++i) {
    EXPECT_TRUE(test::readText(result.files[i].path) == before[i]) << result.files[i].path;
  }
  size_t entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.is_regular_file();
  EXPECT_EQ(entries, 3u) << "temporary files left behind";
}

// ---- bad files ------------------------------------------------------------------------------

struct ReadOutcome {
  bool ok = false;
  std::string error;
};

ReadOutcome readBytes(const std::string& bytes) {
  std::istringstream in(bytes);
  std::unique_ptr<EvidentialOcTree> tree;
  ReadOutcome r;
  r.ok = readEvidentialOctree(in, "input", &tree, &r.error);
  EXPECT_EQ(r.ok, tree != nullptr);
  if (!r.ok) {
    EXPECT_FALSE(r.error.empty());
    EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
  }
  return r;
}

void expectError(const std::string& bytes, const std::string& phrase) {
  const ReadOutcome r = readBytes(bytes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(phrase), std::string::npos) << "error: " << r.error;
}

// A small valid file: 3 cells, one layer, one of them with an anomaly (in layout 2).
std::string smallFile(EvidentialLayout layout = kLatestEvidentialLayout) {
  EvidentialGridMap grid(0.05);
  updateCell(grid.mutableCell(0, 0), ScanMass{0.0f, 0.8f});
  updateCell(grid.mutableCell(1, 0), ScanMass{0.63f, 0.0f});
  updateCell(grid.mutableCell(-1, 3), ScanMass{0.2f, 0.3f});
  EvidentialOcTree tree(0.05, layout);
  for (const auto& o : test::observedCells(grid)) {
    tree.setNodeCell(keyOf(o.index), o.cell, o.index.x == 1 ? 1.5f : 0.0f);
  }
  tree.updateInnerNodes();
  std::ostringstream out;
  tree.write(out);
  return out.str();
}

size_t dataOffset(const std::string& file) { return file.find("data\n") + 5; }

TEST(EvidentialOctreeReader, SmallFileIsValid) {
  for (const auto& [layout, id, node_bytes] :
       {std::make_tuple(EvidentialLayout::kMassesAnomaly, "EvidentialAnomalyOcTree", 21u),
        std::make_tuple(EvidentialLayout::kMasses, "EvidentialOcTree", 17u)}) {
    const std::string file = smallFile(layout);
    EXPECT_TRUE(readBytes(file).ok);
    EXPECT_NE(file.find(std::string("id ") + id + "\n"), std::string::npos);
    // OctoMap writes every node's payload plus one child byte.
    const auto tree = [&] {
      std::istringstream in(file);
      std::unique_ptr<EvidentialOcTree> t;
      std::string error;
      EXPECT_TRUE(readEvidentialOctree(in, "small", &t, &error)) << error;
      return t;
    }();
    ASSERT_TRUE(tree);
    EXPECT_EQ(tree->layout(), layout);
    EXPECT_EQ(file.size() - dataOffset(file), tree->size() * node_bytes);
    // The header's id decides the layout: the other id misreads the nodes and is refused.
    std::string swapped = file;
    const std::string other =
        layout == EvidentialLayout::kMasses ? "EvidentialAnomalyOcTree" : "EvidentialOcTree";
    swapped.replace(swapped.find(id), std::string(id).size(), other);
    EXPECT_FALSE(readBytes(swapped).ok) << id;
  }
}

TEST(EvidentialOctreeReader, MissingEmptyAndDirectory) {
  const fs::path dir = test::scratchDir();
  std::unique_ptr<EvidentialOcTree> tree;
  std::string error;
  EXPECT_FALSE(readEvidentialOctree((dir / "nope.ot").string(), &tree, &error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
  EXPECT_FALSE(readEvidentialOctree(dir.string(), &tree, &error));
  EXPECT_NE(error.find("is a directory"), std::string::npos) << error;
  test::writeText(dir / "empty.ot", "");
  EXPECT_FALSE(readEvidentialOctree((dir / "empty.ot").string(), &tree, &error));
  EXPECT_NE(error.find("empty file"), std::string::npos) << error;
  EXPECT_NE(error.find("empty.ot"), std::string::npos) << error;
  EXPECT_FALSE(tree);
}

TEST(EvidentialOctreeReader, GarbageIsNotAnOctomapFile) {
  expectError("hello world\n", "not an OctoMap .ot file");
  std::mt19937 rng(3);
  for (int n = 0; n < 50; ++n) {
    std::string bytes(1 + rng() % 5000, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    expectError(bytes, "not an OctoMap .ot file");
  }
  expectError(std::string(100000, 'x'), "not an OctoMap .ot file");  // no newline at all
}

TEST(EvidentialOctreeReader, OtherTreeTypesAreRejectedByName) {
  const fs::path dir = test::scratchDir();
  const std::string prefix = exportGrid(test::makeTestGrid(), dir);
  expectError(test::readText(prefix + ".bt"), "binary OctoMap file");
  expectError(test::readText(prefix + ".color.ot"),
              "'ColorOcTree', not an 'EvidentialAnomalyOcTree' or 'EvidentialOcTree'");
  octomap::OcTree plain(0.05);
  plain.updateNode(octomap::point3d(0.1f, 0.1f, 0.1f), true);
  std::ostringstream out;
  plain.write(out);
  expectError(out.str(), "'OcTree', not an 'EvidentialAnomalyOcTree' or 'EvidentialOcTree'");
}

TEST(EvidentialOctreeReader, EveryTruncationIsAnError) {
  const std::string file = smallFile();
  for (size_t n = 0; n < file.size(); ++n) {
    const ReadOutcome r = readBytes(file.substr(0, n));
    EXPECT_FALSE(r.ok) << "truncated to " << n << " bytes";
    if (n > dataOffset(file)) {
      EXPECT_NE(r.error.find("truncated"), std::string::npos) << n << ": " << r.error;
    }
  }
}

TEST(EvidentialOctreeReader, CorruptDataIsNamed) {
  const std::string file = smallFile();
  const size_t data = dataOffset(file);
  {  // NaN in the first node's m~(o)
    std::string bad = file;
    const float nan = std::nanf("");
    std::memcpy(&bad[data + 4], &nan, 4);
    expectError(bad, "no grid can hold");
  }
  {  // m~(o) + m~(e) > 1 in the last node
    std::string bad = file;
    const float big = 0.9f;
    std::memcpy(&bad[bad.size() - 21 + 4], &big, 4);
    std::memcpy(&bad[bad.size() - 21 + 8], &big, 4);
    expectError(bad, "no grid can hold");
  }
  {  // a negative anomaly in the last node
    std::string bad = file;
    const float negative = -1.0f;
    std::memcpy(&bad[bad.size() - 21 + 16], &negative, 4);
    expectError(bad, "no grid can hold");
  }
  expectError(file + "x", "after the last node");
  {
    std::string more = file;
    more.replace(more.find("size "), std::string("size ").size(), "size 1");  // 1N nodes
    expectError(more, "announces");
  }
  {
    std::string fewer = file;
    const size_t at = fewer.find("size ") + 5;
    const size_t end = fewer.find('\n', at);
    const int n = std::stoi(fewer.substr(at, end - at));
    fewer.replace(at, end - at, std::to_string(n - 1));
    expectError(fewer, "more nodes than");
  }
  {  // a node at the finest level that claims children: a chain of 17 single-child nodes + 1
    std::string chain = "# Octomap OcTree file\nid EvidentialOcTree\nsize 18\nres 0.05\ndata\n";
    const float payload[4] = {0.0f, 0.0f, 0.8f, 0.0f};
    for (int depth = 0; depth <= 17; ++depth) {
      chain.append(reinterpret_cast<const char*>(payload), sizeof(payload));
      chain.push_back(depth < 17 ? '\x01' : '\0');
    }
    expectError(chain, "claims children");
  }
  {  // all-ones child bytes: OctoMap's own reader would recurse without bound
    std::string deep = "# Octomap OcTree file\nid EvidentialOcTree\nsize 100000\nres 0.05\ndata\n";
    const float payload[4] = {0.0f, 0.0f, 0.8f, 0.0f};
    for (int i = 0; i < 5000; ++i) {
      deep.append(reinterpret_cast<const char*>(payload), sizeof(payload));
      deep.push_back('\xff');
    }
    EXPECT_FALSE(readBytes(deep).ok);
  }
}

TEST(EvidentialOctreeReader, BadHeaders) {
  const std::string nodes = smallFile().substr(dataOffset(smallFile()));
  const std::string magic = "# Octomap OcTree file\n";
  expectError(magic, "no 'data' line");
  expectError(magic + "id EvidentialOcTree\nsize 3\ndata\n" + nodes, "no 'res'");
  expectError(magic + "id EvidentialOcTree\nres 0.05\ndata\n" + nodes, "no 'size'");
  expectError(magic + "size 3\nres 0.05\ndata\n" + nodes, "no tree 'id'");
  expectError(magic + "id EvidentialOcTree\nsize 3\nres 0\ndata\n" + nodes, "resolution");
  expectError(magic + "id EvidentialOcTree\nsize 3\nres -1\ndata\n" + nodes, "resolution");
  expectError(magic + "id EvidentialOcTree\nsize 3\nres nan\ndata\n" + nodes, "resolution");
  expectError(magic + "id EvidentialOcTree\nsize 3\nres 1e-300\ndata\n" + nodes, "resolution");
  expectError(magic + "id EvidentialOcTree\nsize -3\nres 0.05\ndata\n" + nodes, "size");
  expectError(magic + "id EvidentialOcTree\nsize 3\nres 0.05\n" + std::string(5000, 'z'),
              "longer than");
  std::string comments = magic;
  for (int i = 0; i < 300; ++i) comments += "# comment\n";
  expectError(comments, "no 'data' line");
  // Unknown keys and comments are skipped, as OctoMap does.
  const std::string file = smallFile();
  std::string extra = file;
  extra.insert(extra.find("id "), "# another comment\nowner someone\n");
  EXPECT_TRUE(readBytes(extra).ok);
}

TEST(EvidentialOctreeReader, RandomNodeDataAfterAValidHeaderNeverCrashes) {
  std::mt19937 rng(11);
  int accepted = 0;
  for (int n = 0; n < 300; ++n) {
    std::string file = "# Octomap OcTree file\nid EvidentialOcTree\nsize " +
                       std::to_string(rng() % 50) + "\nres 0.05\ndata\n";
    const size_t len = rng() % 2000;
    for (size_t i = 0; i < len; ++i) {
      // Mostly small floats in [0, 1] and small child bytes, so some files are (nearly) valid.
      file.push_back(static_cast<char>(i % 17 == 16 ? (rng() % 4 == 0 ? rng() % 3 : 0) : rng()));
    }
    accepted += readBytes(file).ok;
  }
  SUCCEED() << accepted << " random files were valid";
}

TEST(EvidentialOctreeReader, OctomapsReadPathLeavesATruncatedTreeEmpty) {
  const std::string file = smallFile();
  std::istringstream in(file.substr(0, file.size() - 5));
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(in));
  ASSERT_TRUE(tree);            // OctoMap returns the tree it created ...
  EXPECT_EQ(tree->size(), 0u);  // ... but our readData left it empty
  EXPECT_TRUE(in.fail());
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
