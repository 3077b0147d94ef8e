// The exported files in other programs: octomap-tools' own bt2vrml, convert_octree and
// compare_octrees, a program that only knows OctoMap's factory, evidential_octomap_info, and the
// offline runner's --export-octomap end to end.
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <regex>

#include <nlohmann/json.hpp>

#include "evidential_slam/core/measures.h"
#include "evidential_slam/io/evidential_octree.h"
#include "evidential_slam/io/npy.h"
#include "evidential_slam/io/octomap_export.h"
#include "octomap_test_support.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;
using test::runProgram;
using test::RunResult;

size_t countOf(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class OctomapTools : public ::testing::Test {
 protected:
  void SetUp() override {
    scratch_ = test::scratchDir();
    grid_ = test::makeTestGrid();
    anomaly_ = test::makeTestAnomaly();
    prefix_ = (scratch_ / "map").string();
    std::string error;
    ASSERT_TRUE(exportOctomap(grid_, anomaly_, OctomapExportConfig(), prefix_, &result_, &error))
        << error;
  }
  void requireTool(const std::string& path, const char* name) {
    ASSERT_FALSE(path.empty()) << name << " was not found at configure time (octomap-tools)";
  }

  fs::path scratch_;
  EvidentialGridMap grid_;
  AnomalyGrid anomaly_;
  std::string prefix_;
  OctomapExportResult result_;
};

TEST_F(OctomapTools, Bt2vrmlDrawsEveryOccupiedVoxel) {
  requireTool(ES_BT2VRML, "bt2vrml");
  octomap::OcTree bt(0.1);
  ASSERT_TRUE(bt.readBinary(prefix_ + ".bt"));
  size_t occupied = 0;
  for (auto it = bt.begin_leafs(); it != bt.end_leafs(); ++it) occupied += bt.isNodeOccupied(*it);
  ASSERT_GT(occupied, 50u);

  const RunResult r = runProgram(ES_BT2VRML, {prefix_ + ".bt"}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.err.find("ERROR"), std::string::npos) << r.err;  // bt2vrml exits 0 on errors too
  EXPECT_NE(r.out.find("Finished writing " + std::to_string(occupied) + " voxels"),
            std::string::npos)
      << r.out;
  const std::string wrl = test::readText(prefix_ + ".bt.wrl");
  EXPECT_EQ(wrl.rfind("#VRML V2.0", 0), 0u);
  EXPECT_EQ(countOf(wrl, "Transform {"), occupied);
}

TEST_F(OctomapTools, ConvertOctreeReadsAndRewritesTheBinaryLosslessly) {
  requireTool(ES_CONVERT_OCTREE, "convert_octree");
  const std::string ot = (scratch_ / "from_bt.ot").string();
  const std::string bt = (scratch_ / "again.bt").string();
  RunResult r = runProgram(ES_CONVERT_OCTREE, {prefix_ + ".bt", ot}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Finished writing"), std::string::npos) << r.out;
  r = runProgram(ES_CONVERT_OCTREE, {ot, bt}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(test::readText(bt), test::readText(prefix_ + ".bt"));

  // The .ot OctoMap wrote is an OcTree with one leaf per observed cell's occupancy.
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(ot));
  auto* octree = dynamic_cast<octomap::OcTree*>(tree.get());
  ASSERT_NE(octree, nullptr);
  for (const auto& o : test::observedCells(grid_)) {
    const octomap::OcTreeNode* node =
        octree->search((o.index.x + 0.5) * 0.05, (o.index.y + 0.5) * 0.05, 0.025);
    ASSERT_NE(node, nullptr);
    EXPECT_EQ(octree->isNodeOccupied(node), pignistic(o.cell) >= 0.5);
  }
}

TEST_F(OctomapTools, ConvertOctreeReadsTheColorFile) {
  requireTool(ES_CONVERT_OCTREE, "convert_octree");
  const std::string copy = (scratch_ / "copy.color.ot").string();
  const RunResult r = runProgram(ES_CONVERT_OCTREE, {prefix_ + ".color.ot", copy}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("ColorOcTree"), std::string::npos) << r.err;
  EXPECT_EQ(test::readText(copy), test::readText(prefix_ + ".color.ot"));
}

TEST_F(OctomapTools, CompareOctreesReadsTheConvertedBinary) {
  requireTool(ES_CONVERT_OCTREE, "convert_octree");
  requireTool(ES_COMPARE_OCTREES, "compare_octrees");
  // compare_octrees reads .ot OcTrees only (it crashes on a .bt or a ColorOcTree): convert the .bt
  // with convert_octree, then let it expand and compare the result with itself: one leaf per
  // observed cell, no divergence.
  const std::string ot = (scratch_ / "from_bt.ot").string();
  RunResult r = runProgram(ES_CONVERT_OCTREE, {prefix_ + ".bt", ot}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = runProgram(ES_COMPARE_OCTREES, {ot, ot}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Expanded num. leafs: " + std::to_string(result_.observed_cells) + "\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("KLD: 0\n"), std::string::npos) << r.out;
}

TEST_F(OctomapTools, ConvertOctreeRejectsGarbage) {
  requireTool(ES_CONVERT_OCTREE, "convert_octree");
  test::writeText(scratch_ / "garbage.bt", "not an octree\n");
  const RunResult r =
      runProgram(ES_CONVERT_OCTREE,
                 {(scratch_ / "garbage.bt").string(), (scratch_ / "out.ot").string()}, scratch_);
  EXPECT_NE(r.exit_code, 0);  // the tool's checks are live: a test of the .bt above can fail
}

TEST_F(OctomapTools, AThirdPartyProgramReadsTheTreeThroughOctomapsFactory) {
  const RunResult r = runProgram(ES_CONSUMER_BIN, {prefix_ + ".evidential.ot"}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(
      r.out.find("type EvidentialAnomalyOcTree nodes " + std::to_string(result_.files[0].nodes)),
      std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("first leaf"), std::string::npos) << r.out;
  // And the file of the old layout, whose first leaf is cell (-2, 3) (lowest key first).
  const RunResult old =
      runProgram(ES_CONSUMER_BIN, {test::dataPath("octomap_masses_v1.evidential.ot")}, scratch_);
  ASSERT_EQ(old.exit_code, 0) << old.out << old.err;
  EXPECT_NE(old.out.find("type EvidentialOcTree nodes 50\n"), std::string::npos) << old.out;
  EXPECT_NE(old.out.find("anomaly 0\n"), std::string::npos) << old.out;
}

// ---- evidential_octomap_info ----------------------------------------------------------------

TEST_F(OctomapTools, InfoToolPrintsTheStatisticsOfTheGrid) {
  const RunResult r = runProgram(ES_INFO_BIN, {prefix_ + ".evidential.ot"}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const auto cells = test::observedCells(grid_);
  EXPECT_NE(r.out.find("EvidentialAnomalyOcTree (layout 2), resolution 0.05 m"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(std::to_string(cells.size()) + " voxels in 1 height layer(s)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("z [0.0000, 0.0500] m"), std::string::npos) << r.out;
  // Mean of every layer as printed (6 decimals) against the grid's own cells and the anomaly.
  // Four observed cells hold 2.5 + 0.125 + 17.75 + 1 bits (the unobserved one is not a voxel).
  EXPECT_NE(r.out.find("anomaly:     4 voxels with an anomaly, 21.375 bits over all voxels"),
            std::string::npos)
      << r.out;
  for (int l = 0; l < kLayerCount; ++l) {
    double sum = 0.0, lo = 1e300, hi = -1e300;
    for (const auto& o : cells) {
      const double v = static_cast<Layer>(l) == Layer::kAnomaly
                           ? anomaly_.at(o.index.x, o.index.y)
                           : layerValue(o.cell, static_cast<Layer>(l));
      sum += v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    const std::regex line("\n" + layerNames()[l] + " +(\\S+) +(\\S+) +(\\S+)\n");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, line)) << layerNames()[l] << "\n" << r.out;
    EXPECT_NEAR(std::stod(m[1]), lo, 1e-6) << layerNames()[l];
    EXPECT_NEAR(std::stod(m[2]), sum / cells.size(), 1e-6) << layerNames()[l];
    EXPECT_NEAR(std::stod(m[3]), hi, 1e-6) << layerNames()[l];
  }
}

TEST_F(OctomapTools, InfoToolReadsTheOldLayout) {
  const RunResult r =
      runProgram(ES_INFO_BIN, {test::dataPath("octomap_masses_v1.evidential.ot")}, scratch_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("EvidentialOcTree (layout 1), resolution 0.05 m"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("4 voxels in 1 height layer(s)"), std::string::npos) << r.out;
  // No anomaly row, and the reason.
  EXPECT_EQ(r.out.find("\nanomaly  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("anomaly:     not in this file (layout 1"), std::string::npos) << r.out;
  // m(o) over the four voxels: 0.5, 0, 0.125 e^-1.5, e^-0.25 -> max 0.778801.
  EXPECT_NE(r.out.find("\noccupied                 0.000000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.778801\n"), std::string::npos) << r.out;
}

TEST_F(OctomapTools, InfoToolErrors) {
  RunResult r = runProgram(ES_INFO_BIN, {prefix_ + ".bt"}, scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("binary OctoMap file"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = runProgram(ES_INFO_BIN, {prefix_ + ".color.ot"}, scratch_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("ColorOcTree"), std::string::npos) << r.err;
  r = runProgram(ES_INFO_BIN, {}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "error: FILE is required (see --help)\n");
  r = runProgram(ES_INFO_BIN, {"--bogus", "x"}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "error: unknown option '--bogus' (see --help)\n");
  r = runProgram(ES_INFO_BIN, {"a.ot", "b.ot"}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "error: unexpected argument 'b.ot' (see --help)\n");
  r = runProgram(ES_INFO_BIN, {"a.ot", "--compare-layers"}, scratch_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "error: --compare-layers needs a value (see --help)\n");
  r = runProgram(ES_INFO_BIN, {"--help"}, scratch_);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--compare-layers DIR"), std::string::npos) << r.out;
}

// ---- offline runner -------------------------------------------------------------------------

const std::vector<std::string> kFast = {"--particles", "20", "--seed", "3",
                                        "--threads",   "2",  "--quiet"};

std::vector<std::string> offlineArgs(const fs::path& out, std::vector<std::string> extra) {
  std::vector<std::string> args = {"--rawlog", test::dataPath("sim.rawlog"), "--out", out.string(),
                                   "--export-octomap"};
  args.insert(args.end(), kFast.begin(), kFast.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST(OctomapOffline, ExportOctomapWritesThreeFilesThatReadBackIdentically) {
  const fs::path scratch = test::scratchDir();
  const fs::path out = scratch / "out";
  RunResult r = runProgram(ES_OFFLINE_BIN, offlineArgs(out, {}), scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("octomap:    " + (out / "octomap").string()), std::string::npos) << r.out;
  const std::vector<std::string> names = {"map.evidential.ot", "map.bt", "map.color.ot"};
  const auto summary = nlohmann::json::parse(test::readText(out / "summary.json"));
  ASSERT_TRUE(summary.contains("octomap")) << summary.dump(2);
  const auto& o = summary["octomap"];
  ASSERT_EQ(o["files"].size(), 3u);
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(o["files"][i], "octomap/" + names[i]);
    EXPECT_EQ(o["bytes"][i].get<uint64_t>(), fs::file_size(out / "octomap" / names[i]));
    const auto& outputs = summary["outputs"];
    EXPECT_NE(std::find(outputs.begin(), outputs.end(), "octomap/" + names[i]), outputs.end());
  }
  EXPECT_EQ(o["z_layers"], 1);
  EXPECT_GT(o["voxels"].get<uint64_t>(), 10000u);
  EXPECT_GT(o["export_time_s"].get<double>(), 0.0);

  // Every observed cell of layers/ against the evidential file, through the info tool.
  r = runProgram(
      ES_INFO_BIN,
      {(out / "octomap/map.evidential.ot").string(), "--compare-layers", (out / "layers").string()},
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("result:      identical masses and anomaly"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 0 missing, 0 extra"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::to_string(o["voxels"].get<uint64_t>()) + " voxels vs"),
            std::string::npos)
      << r.out;
  // The anomaly of layers/anomaly.npy is in the export too, on every voxel.
  EXPECT_NE(r.out.find("max |diff| anomaly 0 bits"), std::string::npos) << r.out;
  std::smatch anomaly;
  ASSERT_TRUE(std::regex_search(r.out, anomaly, std::regex("anomaly: +(\\d+) voxels with")))
      << r.out;
  EXPECT_GT(std::stoul(anomaly[1].str()), 0u) << "the run has no anomaly to compare";
  std::printf("offline export: %s voxels with an anomaly\n", anomaly[1].str().c_str());

  {  // One observed cell's anomaly changed in layers/: the comparison sees it.
    NpyArray observed, anomaly_npy;
    std::string error;
    ASSERT_TRUE(readNpy((out / "layers/observed.npy").string(), &observed, &error)) << error;
    ASSERT_TRUE(readNpy((out / "layers/anomaly.npy").string(), &anomaly_npy, &error)) << error;
    const std::vector<uint8_t> seen_cells = observed.asUint8();
    std::vector<float> bits = anomaly_npy.asFloat32();
    const size_t cell = std::find(seen_cells.begin(), seen_cells.end(), 1) - seen_cells.begin();
    ASSERT_LT(cell, bits.size());
    bits[cell] += 0.5f;
    const fs::path changed = scratch / "changed_layers";
    fs::copy(out / "layers", changed);
    ASSERT_TRUE(writeNpy((changed / "anomaly.npy").string(), bits.data(),
                         static_cast<int>(anomaly_npy.shape[0]),
                         static_cast<int>(anomaly_npy.shape[1]), &error))
        << error;
    const RunResult d = runProgram(
        ES_INFO_BIN,
        {(out / "octomap/map.evidential.ot").string(), "--compare-layers", changed.string()},
        scratch);
    EXPECT_EQ(d.exit_code, 3) << d.out << d.err;
    EXPECT_NE(d.out.find("max |diff| anomaly 0.5 bits"), std::string::npos) << d.out;
    EXPECT_NE(d.out.find("result:      DIFFERENT masses and anomaly"), std::string::npos) << d.out;
  }

  if (std::string(ES_BT2VRML).empty()) FAIL() << "bt2vrml not found (octomap-tools)";
  r = runProgram(ES_BT2VRML, {(out / "octomap/map.bt").string()}, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("ERROR"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("Finished writing 0 voxels"), std::string::npos) << r.out;
}

TEST(OctomapOffline, CompareLayersDetectsADifferentMap) {
  // The info tool's comparison is live: the layers of one run against the tree of another (with
  // another seed) must differ.
  const fs::path scratch = test::scratchDir();
  const fs::path a = scratch / "a", b = scratch / "b";
  ASSERT_EQ(runProgram(ES_OFFLINE_BIN, offlineArgs(a, {"--max-scans", "40"}), scratch).exit_code,
            0);
  ASSERT_EQ(runProgram(ES_OFFLINE_BIN, offlineArgs(b, {"--max-scans", "60"}), scratch).exit_code,
            0);
  const RunResult r = runProgram(
      ES_INFO_BIN,
      {(a / "octomap/map.evidential.ot").string(), "--compare-layers", (b / "layers").string()},
      scratch);
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("DIFFERENT masses"), std::string::npos) << r.out;
}

TEST(OctomapOffline, SlabHeightsAndUnwritableOutput) {
  const fs::path scratch = test::scratchDir();
  const fs::path out = scratch / "out";
  RunResult r = runProgram(
      ES_OFFLINE_BIN,
      offlineArgs(out, {"--max-scans", "30", "--octomap-z-min", "-0.2", "--octomap-z-max", "0.3"}),
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto summary = nlohmann::json::parse(test::readText(out / "summary.json"));
  EXPECT_EQ(summary["octomap"]["z_layers"], 11);  // voxels -4 .. 6 at 0.05 m
  EXPECT_DOUBLE_EQ(summary["octomap"]["z_min"].get<double>(), -0.2);
  r = runProgram(ES_INFO_BIN, {(out / "octomap/map.evidential.ot").string()}, scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("in 11 height layer(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("z [-0.2000, 0.3500] m"), std::string::npos) << r.out;

  const fs::path blocked = scratch / "blocked";
  fs::create_directories(blocked);
  test::writeText(blocked / "octomap", "a file where the directory should go");
  r = runProgram(ES_OFFLINE_BIN, offlineArgs(blocked, {"--max-scans", "30"}), scratch);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error: cannot create output directory"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
