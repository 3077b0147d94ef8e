// Tests of `evidential_slam_fuse` (session/fuse_command.h): its command line, its run on map files
// and on a run's layers, its outputs and fusion.json, and the process's exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/core/layers.h"
#include "evidential_slam/io/map_file.h"
#include "evidential_slam/session/fuse_command.h"
#include "evidential_slam/session/map_files.h"
#include "evidential_slam/session/offline_runner.h"
#include "test_util.h"

namespace evidential_slam {
namespace {

namespace fs = std::filesystem;

bool parse(const std::vector<std::string>& args, io::FuseOptions* o, std::string* error) {
  bool help = false;
  return io::parseFuseArgs(args, o, &help, error);
}

std::string parseError(const std::vector<std::string>& args) {
  io::FuseOptions o;
  std::string error;
  EXPECT_FALSE(parse(args, &o, &error)) << "accepted";
  return error;
}

TEST(FuseArgsTest, ParsesTheIssuesSynopsis) {
  io::FuseOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--map", "a", "--map=b", "--map", "c", "--pose", "1,-2,0.5", "--pose=0,0,3",
                     "--rule", "yager", "--discount", "0.1", "--out", "o", "--export-octomap"},
                    &o, &error))
      << error;
  EXPECT_EQ(o.maps, (std::vector<std::string>{"a", "b", "c"}));
  ASSERT_EQ(o.poses.size(), 2u);
  EXPECT_DOUBLE_EQ(o.poses[0].x, 1.0);
  EXPECT_DOUBLE_EQ(o.poses[0].y, -2.0);
  EXPECT_DOUBLE_EQ(o.poses[0].theta, 0.5);
  EXPECT_EQ(o.rule, fusion::Rule::kYager);
  EXPECT_EQ(o.discounts, std::vector<double>{0.1});
  EXPECT_TRUE(o.session.export_octomap);
  EXPECT_FALSE(o.estimate);
  bool help = false;
  EXPECT_TRUE(io::parseFuseArgs({"--help"}, &o, &help, &error));
  EXPECT_TRUE(help);
}

TEST(FuseArgsTest, AnInitialGuessImpliesEstimation) {
  io::FuseOptions o;
  std::string error;
  ASSERT_TRUE(parse({"--map", "a", "--map", "b", "--map", "c", "--initial-guess", "1,-2,0.5",
                     "--initial-guess=3,4,0,0.25", "--rule", "cautious", "--out", "o"},
                    &o, &error))
      << error;
  EXPECT_TRUE(o.estimate);
  ASSERT_EQ(o.guesses.size(), 2u);
  EXPECT_DOUBLE_EQ(o.guesses[0].pose.y, -2.0);
  EXPECT_DOUBLE_EQ(o.guesses[0].sigma, 1.0);
  EXPECT_DOUBLE_EQ(o.guesses[1].pose.x, 3.0);
  EXPECT_DOUBLE_EQ(o.guesses[1].sigma, 0.25);
}

TEST(FuseArgsTest, BadUsageGetsAOneLineError) {
  const std::vector<std::string> two = {"--map", "a", "--map", "b", "--out", "o"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = two;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  EXPECT_NE(parseError({"--map", "a", "--rule", "cautious", "--out", "o"}).find("two --map"),
            std::string::npos);
  EXPECT_NE(parseError(two).find("--rule is required"), std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "max"})).find("not 'max'"), std::string::npos);
  EXPECT_NE(parseError({"--map", "a", "--map", "b", "--rule", "cautious"}).find("--out"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--pose", "1,2"})).find("x,y,yaw"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--pose", "1,2,nan"})).find("x,y,yaw"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--pose", "0,0,0", "--pose", "0,0,0"}))
                .find("one per map after the first"),
            std::string::npos);
  EXPECT_NE(
      parseError(with({"--rule", "cautious", "--pose", "0,0,0", "--estimate"})).find("exclude"),
      std::string::npos);
  EXPECT_EQ(parseError(with({"--rule", "cautious", "--initial-guess", "1,2"})),
            "--initial-guess wants x,y,yaw or x,y,yaw,sigma (m, m, rad, m > 0), not '1,2'");
  EXPECT_NE(parseError(with({"--rule", "cautious", "--initial-guess", "1,2,3,0"})).find("m > 0"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--initial-guess", "1,,3"})).find("not '1,,3'"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--initial-guess", "0,0,0", "--initial-guess",
                             "0,0,0"}))
                .find("one per map after the first"),
            std::string::npos);
  EXPECT_EQ(parseError(with({"--rule", "cautious", "--initial-guess", "0,0,0", "--pose", "0,0,0"})),
            "--pose and --initial-guess exclude each other");
  EXPECT_NE(parseError(with({"--rule", "cautious", "--discount", "1.5"})).find("[0, 1]"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--discount", "0", "--discount", "0",
                             "--discount", "0"}))
                .find("one for all or one per map"),
            std::string::npos);
  EXPECT_EQ(parseError(with({"--rule", "cautious", "--bogus"})), "unknown option '--bogus'");
  EXPECT_EQ(parseError(with({"--rule", "cautious", "--estimate=1"})), "--estimate takes no value");
  EXPECT_EQ(parseError(with({"--rule"})), "--rule needs a value");
  EXPECT_EQ(parseError(with({"--rule", "cautious", "--ground-truth-resolution", "0"})),
            "--ground-truth-resolution wants a number > 0 (m per pixel)");
  EXPECT_NE(parseError(with({"--rule", "cautious", "--param", "particles=3"}))
                .find("not a parameter of a map's files"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--param", "occupied_thresh=2"}))
                .find("occupied_thresh"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--ground-truth-pose", "0,0,0"}))
                .find("need --ground-truth"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--frobnicate"})).find("unknown option"),
            std::string::npos);
  EXPECT_NE(parseError(with({"--rule"})).find("needs a value"), std::string::npos);
  EXPECT_NE(parseError(with({"--rule", "cautious", "--estimate=1"})).find("takes no value"),
            std::string::npos);
}

// Two overlapping rooms' maps at 0.1 m: A sees x in [0, 40) cells, B the same world from x = 20 on,
// in its own frame 1 m (10 cells) to the right of A's; a wall at x = 30 (world) both see, with
// conflict in B.
void paint(EvidentialGridMap* map, int x0, int x1, int shift, float lambda) {
  for (int y = 0; y < 20; ++y) {
    for (int x = x0; x < x1; ++x) {
      const bool wall = x == 30 || y == 0 || y == 19;
      map->mutableCell(x - shift, y) =
          wall ? Cell::fromStored(0.8f, 0.0f, lambda) : Cell::fromStored(0.0f, 0.7f, 0.0f);
    }
  }
}

struct Maps {
  EvidentialGridMap a{0.1}, b{0.1};
  Maps() {
    paint(&a, 0, 40, 0, 0.0f);
    paint(&b, 20, 60, 10, 0.3f);
  }
};

fs::path saveMap(const EvidentialGridMap& map, const fs::path& path) {
  std::string error;
  EXPECT_TRUE(io::writeMapFile(path.string(), map, io::MapFileInfo(), &error)) << error;
  return path;
}

io::FuseOptions options(const std::vector<std::string>& args) {
  io::FuseOptions o;
  std::string error;
  EXPECT_TRUE(parse(args, &o, &error)) << error;
  return o;
}

int run(const io::FuseOptions& o, std::string* err_text = nullptr) {
  std::FILE* out = std::tmpfile();
  std::FILE* err = std::tmpfile();
  const int code = io::runFuse(o, out, err);
  if (err_text != nullptr) {
    std::rewind(err);
    char buf[4096];
    const size_t n = std::fread(buf, 1, sizeof(buf), err);
    *err_text = std::string(buf, n);
  }
  std::fclose(out);
  std::fclose(err);
  return code;
}

TEST(FuseRunTest, WritesAMapsFilesTheMapFileAndFusionJson) {
  const fs::path dir = test::scratchDir();
  const Maps m;
  const fs::path a = saveMap(m.a, dir / "a.evmap"), b = saveMap(m.b, dir / "b.evmap");
  const fs::path out = dir / "out";
  ASSERT_EQ(run(options({"--map", a.string(), "--map", b.string(), "--pose", "1,0,0", "--rule",
                         "cautious", "--out", out.string()})),
            io::kExitOk);

  // The same files as a SLAM run's map (writeMapFiles) and the lossless map file.
  for (const std::string& name : layerNames()) {
    EXPECT_TRUE(fs::exists(out / "layers" / (name + ".npy"))) << name;
    EXPECT_TRUE(fs::exists(out / "layers" / (name + ".pgm"))) << name;
  }
  EXPECT_TRUE(fs::exists(out / "layers" / "map.yaml"));
  EXPECT_FALSE(fs::exists(out / "octomap"));

  // map.evmap holds exactly what fuseMaps makes of the two maps at that pose.
  EvidentialGridMap expected, written;
  fusion::FusionReport report;
  ASSERT_TRUE(fusion::fuseMaps({{&m.a, Pose2()}, {&m.b, Pose2(1.0, 0.0, 0.0)}},
                               fusion::FusionConfig(), &expected, &report, nullptr));
  io::MapFileInfo info;
  std::string error;
  ASSERT_TRUE(io::readMapFile((out / io::kMapFileName).string(), &written, &info, &error)) << error;
  EXPECT_EQ(info.metadata["fusion_rule"], "cautious");
  EXPECT_EQ(info.metadata["source"], "evidential_slam_fuse");
  const CellBox box = expected.observedBox();
  EXPECT_EQ(written.observedBox().min_x, box.min_x);
  EXPECT_EQ(written.observedBox().max_x, box.max_x);
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      ASSERT_TRUE(written.cell(x, y) == expected.cell(x, y)) << x << ", " << y;
    }
  }

  const nlohmann::json j = nlohmann::json::parse(test::readText(out / "fusion.json"));
  EXPECT_EQ(j["rule"], "cautious");
  EXPECT_EQ(j["overlap_cells"].get<size_t>(), report.overlap_cells);
  EXPECT_EQ(j["overlap_cells"].get<size_t>(), 20u * 20u);  // x in [20, 40) world
  EXPECT_EQ(j["fused_cells"].get<size_t>(), 60u * 20u);
  EXPECT_NEAR(j["mean_conflict"].get<double>(), report.mean_conflict, 1e-12);
  EXPECT_EQ(j["maps"][1]["pose_source"], "given");
  EXPECT_DOUBLE_EQ(j["maps"][1]["pose"]["x"].get<double>(), 1.0);
  EXPECT_EQ(j["maps"][0]["kind"], "map file");
  EXPECT_EQ(j["maps"][1]["stats"]["observed_cells"].get<size_t>(), 40u * 20u);
  EXPECT_GT(j["fused"]["mean_conflict"].get<double>(), 0.0);
}

// A SLAM run's directory without a map file: its layers are read back (and the result equals the
// map file's up to the layers' float precision).
TEST(FuseRunTest, ReadsARunsLayersAndScoresAgainstAMap) {
  const fs::path dir = test::scratchDir();
  const Maps m;
  MapSave save;
  save.map = m.a;
  MapFilesReport written;
  std::string error;
  ASSERT_TRUE(writeMapFiles((dir / "run_a").string(), save, SessionConfig(), &written, &error))
      << error;
  fs::remove(dir / "run_a" / io::kMapFileName);  // as a run from before the map file
  const fs::path b = saveMap(m.a, dir / "a.evmap");
  const fs::path out = dir / "out";
  ASSERT_EQ(run(options({"--map", (dir / "run_a").string(), "--map", b.string(), "--rule",
                         "conjunctive", "--out", out.string(), "--ground-truth", b.string()})),
            io::kExitOk);
  const nlohmann::json j = nlohmann::json::parse(test::readText(out / "fusion.json"));
  EXPECT_EQ(j["maps"][0]["kind"], "layers");
  EXPECT_EQ(j["maps"][1]["pose_source"], "shared frame");
  EXPECT_EQ(j["overlap_cells"].get<size_t>(), 40u * 20u);
  // Each map against itself as truth: everything it classifies is right, all it knows is covered.
  for (const auto& s : {j["scores"]["maps"][0], j["scores"]["maps"][1]}) {
    EXPECT_DOUBLE_EQ(s["accuracy"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(s["coverage"].get<double>(), 1.0);
  }
  // The conjunctive rule on a map and itself: more certain than either (less m(Θ)).
  EXPECT_LT(j["fused"]["mean_nonspecificity"].get<double>(),
            j["maps"][0]["stats"]["mean_nonspecificity"].get<double>() - 0.05);
}

TEST(FuseRunTest, CautiousFusionOfAMapWithItselfChangesNothing) {
  const fs::path dir = test::scratchDir();
  const Maps m;
  const fs::path a = saveMap(m.b, dir / "a.evmap");
  const fs::path out = dir / "out";
  ASSERT_EQ(run(options({"--map", a.string(), "--map", a.string(), "--rule", "cautious", "--out",
                         out.string()})),
            io::kExitOk);
  EvidentialGridMap written;
  io::MapFileInfo info;
  ASSERT_TRUE(io::readMapFile((out / io::kMapFileName).string(), &written, &info, nullptr));
  const CellBox box = m.b.observedBox();
  for (int y = box.min_y; y <= box.max_y; ++y) {
    for (int x = box.min_x; x <= box.max_x; ++x) {
      ASSERT_TRUE(written.cell(x, y) == m.b.cell(x, y)) << x << ", " << y;
    }
  }
}

TEST(FuseRunTest, EstimatesThePoseOfAMapOnTheFirst) {
  const fs::path dir = test::scratchDir();
  // A world with structure to align on: walls and pillars in a 12 m x 8 m room, seen whole by A,
  // and by B in a frame moved by (0.6, -0.3, 0.2 rad).
  EvidentialGridMap world(0.05);
  auto wall = [&](int x, int y) {
    return x == 0 || y == 0 || x == 239 || y == 159 || (x == 80 && y < 100) ||
           (y == 60 && x > 140) || ((x - 180) * (x - 180) + (y - 110) * (y - 110) < 30) ||
           (x > 30 && x < 50 && y > 120 && y < 130);
  };
  for (int y = 0; y < 160; ++y) {
    for (int x = 0; x < 240; ++x) {
      world.mutableCell(x, y) =
          wall(x, y) ? Cell::fromStored(0.8f, 0.0f, 0.0f) : Cell::fromStored(0.0f, 0.7f, 0.0f);
    }
  }
  const Pose2 truth(0.6, -0.3, 0.2);
  EvidentialGridMap b(0.05);
  // B's cells: the world resampled in B's frame (nearest cell).
  const Pose2 b_to_world = truth;
  for (int y = -40; y < 220; ++y) {
    for (int x = -40; x < 300; ++x) {
      const Eigen::Vector2d w =
          b_to_world.transformPoint(Eigen::Vector2d((x + 0.5) * 0.05, (y + 0.5) * 0.05));
      const int wx = static_cast<int>(std::floor(w.x() / 0.05));
      const int wy = static_cast<int>(std::floor(w.y() / 0.05));
      if (wx < 0 || wy < 0 || wx >= 240 || wy >= 160) continue;
      b.mutableCell(x, y) = world.cell(wx, wy);
    }
  }
  const fs::path a_path = saveMap(world, dir / "a.evmap"), b_path = saveMap(b, dir / "b.evmap");
  const fs::path out = dir / "out";
  std::string err;
  ASSERT_EQ(run(options({"--map", a_path.string(), "--map", b_path.string(), "--estimate", "--rule",
                         "cautious", "--out", out.string()}),
                &err),
            io::kExitOk)
      << err;
  const nlohmann::json j = nlohmann::json::parse(test::readText(out / "fusion.json"));
  EXPECT_EQ(j["maps"][1]["pose_source"], "estimated");
  EXPECT_NEAR(j["maps"][1]["pose"]["x"].get<double>(), truth.x, 0.05);
  EXPECT_NEAR(j["maps"][1]["pose"]["y"].get<double>(), truth.y, 0.05);
  EXPECT_NEAR(j["maps"][1]["pose"]["yaw"].get<double>(), truth.theta, 0.02);
  EXPECT_TRUE(j["maps"][1].contains("alignment"));
}

TEST(FuseRunTest, BadInputIsExitCodeTwoWithOneLine) {
  const fs::path dir = test::scratchDir();
  const Maps m;
  const fs::path a = saveMap(m.a, dir / "a.evmap");
  std::string err;
  // A map that does not exist.
  EXPECT_EQ(run(options({"--map", a.string(), "--map", (dir / "none").string(), "--rule",
                         "cautious", "--out", (dir / "o1").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("does not exist"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  // A directory that is no map.
  fs::create_directories(dir / "empty");
  EXPECT_EQ(run(options({"--map", a.string(), "--map", (dir / "empty").string(), "--rule",
                         "cautious", "--out", (dir / "o2").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("not a map"), std::string::npos) << err;
  // A damaged map file.
  test::writeText(dir / "bad.evmap", "not a map file");
  EXPECT_EQ(run(options({"--map", a.string(), "--map", (dir / "bad.evmap").string(), "--rule",
                         "cautious", "--out", (dir / "o3").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("bad.evmap"), std::string::npos) << err;
  // Resolutions that differ.
  EvidentialGridMap coarse(0.2);
  coarse.mutableCell(0, 0) = Cell::fromStored(0.5f, 0.0f, 0.0f);
  const fs::path c = saveMap(coarse, dir / "c.evmap");
  EXPECT_EQ(run(options({"--map", a.string(), "--map", c.string(), "--rule", "cautious", "--out",
                         (dir / "o4").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("one resolution"), std::string::npos) << err;
  // An alignment that finds nothing to align on: refused.
  EvidentialGridMap speck(0.1);
  speck.mutableCell(500, 500) = Cell::fromStored(0.0f, 0.5f, 0.0f);
  const fs::path s = saveMap(speck, dir / "s.evmap");
  EXPECT_EQ(run(options({"--map", a.string(), "--map", s.string(), "--estimate", "--rule",
                         "cautious", "--out", (dir / "o5").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("cannot align"), std::string::npos) << err;
  // An output directory that cannot be created.
  test::writeText(dir / "file", "x");
  EXPECT_EQ(run(options({"--map", a.string(), "--map", a.string(), "--rule", "cautious", "--out",
                         (dir / "file" / "out").string()}),
                &err),
            io::kExitBadInput);
  EXPECT_NE(err.find("cannot create"), std::string::npos) << err;
}

// The process: bad usage exits 1, bad input 2, each with one `error:` line.
TEST(FuseProcessTest, ExitCodes) {
  const fs::path dir = test::scratchDir();
  auto process = [&](const std::string& args, std::string* err) {
    const fs::path err_path = dir / "stderr.txt";
    const std::string cmd = std::string(ES_FUSE_BIN) + " " + args + " > /dev/null 2> " +
                            err_path.string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    *err = test::readText(err_path);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  std::string err;
  EXPECT_EQ(process("--map a --map b --out " + (dir / "o").string(), &err), io::kExitUsage);
  EXPECT_EQ(err, "error: --rule is required (see --help)\n");
  EXPECT_EQ(process("--map " + (dir / "x").string() + " --map " + (dir / "y").string() +
                        " --rule cautious --out " + (dir / "o").string(),
                    &err),
            io::kExitBadInput);
  EXPECT_EQ(err.rfind("error: map '", 0), 0u) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_EQ(process("--help", &err), io::kExitOk);
}

}  // namespace
}  // namespace evidential_slam
