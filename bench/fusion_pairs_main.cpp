// evidential_slam_fusion_pairs: the map-merging benchmark on generated pairs (docs/fusion.md §9).
// A seed draws office floors (rooms either side of a corridor, doors and furniture at random;
// half of them symmetric under a half turn but for one to three pieces of furniture), and two
// robots' maps of each: observed circles overlapping by 20-80 % of the smaller one, the second in a
// random frame, each distorted like a SLAM run's drift, and in some pairs a box the first robot saw
// that was gone when the second came. For every pair it aligns the second map on the first with
// the score alone (the search's conflict score and ambiguity ratio) and with the verification by
// conflict (core/fusion/alignment_check.h), and fuses the two at the true pose: cautious rule
// against map_merge's maximum of trinary maps and the log-odds sum of BetP, scored on the floor's
// truth.
//   evidential_slam_fusion_pairs [--seed S] [--pairs N] [--pair K] [--csv FILE] [--verbose]
// Without --seed the seed comes from the clock; it is printed first either way. --pair K runs pair
// K of the seed alone; --verbose says on stderr where each pair not aligned right went.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "../test/core/fusion/synthetic_world.h"
#include "evidential_slam/core/fusion/alignment.h"
#include "evidential_slam/core/fusion/map_fusion.h"
#include "evidential_slam/core/fusion/map_score.h"
#include "evidential_slam/core/measures.h"
#include "evidential_slam/io/command_line.h"

namespace {

namespace es = evidential_slam;
namespace syn = evidential_slam::synthetic;
using es::Pose2;
using es::fusion::CellClass;
using Rng = std::mt19937_64;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRes = 0.05;
// The maps' drift (synthetic::paint's bend): 0.005 rad turns a cell 5 m from the centre by
// 0.025 m at most, SLAM maps with an ATE of a few centimetres.
constexpr double kBend = 0.005;

double uniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Splits [0, width] into rooms 3-6 m wide: the walls between them.
std::vector<double> roomWalls(Rng& rng, double width) {
  std::vector<double> walls;
  for (double x = uniform(rng, 3.0, 6.0); x < width - 2.5; x += uniform(rng, 3.0, 6.0)) {
    walls.push_back(x);
  }
  return walls;
}

// One row of rooms between y0 (outer wall) and y1 (corridor wall): room walls and a door
// (0.9 m) into the corridor for each room. `twin` also adds the half turn about (cx, cy).
void addRoomRow(syn::World* w, Rng& rng, double width, double y0, double y1, bool twin, double cx,
                double cy) {
  auto wall = [&](double ax, double ay, double bx, double by) {
    w->walls.push_back({{ax, ay}, {bx, by}});
    if (twin) w->walls.push_back({{2 * cx - ax, 2 * cy - ay}, {2 * cx - bx, 2 * cy - by}});
  };
  std::vector<double> splits = roomWalls(rng, width);
  for (double x : splits) wall(x, y0, x, y1);
  splits.insert(splits.begin(), 0.0);
  splits.push_back(width);
  for (size_t i = 0; i + 1 < splits.size(); ++i) {
    const double a = splits[i], b = splits[i + 1];
    const double door = uniform(rng, a + 0.3, b - 1.2);
    wall(a, y1, door, y1);
    wall(door + 0.9, y1, b, y1);
  }
}

void addBlock(syn::World* w, double x, double y, double sx, double sy) {
  syn::addBox(w, x, y, x + sx, y + sy);
}

struct Floor {
  syn::World world;
  bool symmetric = false;
};

Floor randomFloor(Rng& rng) {
  Floor f;
  f.symmetric = uniform(rng, 0.0, 1.0) < 0.5;
  const double width = uniform(rng, 16.0, 28.0), height = uniform(rng, 10.0, 16.0);
  const double cy = 0.5 * height, cx = 0.5 * width;
  f.world.min = {0.0, 0.0};
  f.world.max = {width, height};
  syn::addBox(&f.world, 0, 0, width, height);
  addRoomRow(&f.world, rng, width, 0.0, cy - 1.0, f.symmetric, cx, cy);
  if (!f.symmetric) {
    // The other row on its own, its corridor wall at cy + 1 (rooms face down).
    std::vector<double> splits = roomWalls(rng, width);
    for (double x : splits) f.world.walls.push_back({{x, cy + 1.0}, {x, height}});
    splits.insert(splits.begin(), 0.0);
    splits.push_back(width);
    for (size_t i = 0; i + 1 < splits.size(); ++i) {
      const double a = splits[i], b = splits[i + 1];
      const double door = uniform(rng, a + 0.3, b - 1.2);
      f.world.walls.push_back({{a, cy + 1.0}, {door, cy + 1.0}});
      f.world.walls.push_back({{door + 0.9, cy + 1.0}, {b, cy + 1.0}});
    }
  }
  // Furniture in the rooms (only on one side of the twin: what breaks the symmetry).
  const int pieces = f.symmetric ? 1 + static_cast<int>(uniform(rng, 0.0, 3.0))
                                 : static_cast<int>(uniform(rng, 0.0, 4.0));
  for (int i = 0; i < pieces; ++i) {
    const double sx = uniform(rng, 0.4, 1.5), sy = uniform(rng, 0.4, 1.0);
    const bool low = uniform(rng, 0.0, 1.0) < 0.5;
    const double y = low ? uniform(rng, 0.5, cy - 2.5) : uniform(rng, cy + 1.5, height - 1.5);
    addBlock(&f.world, uniform(rng, 0.5, width - 2.0), y, sx, sy);
  }
  return f;
}

// The truth raster of `world` in its own frame: walls occupied, the building's inside free.
es::fusion::OccupancyRaster truthOf(const syn::World& world) {
  es::fusion::OccupancyRaster r;
  r.resolution = kRes;
  r.width = static_cast<int>(std::ceil((world.max.x() - world.min.x()) / kRes));
  r.height = static_cast<int>(std::ceil((world.max.y() - world.min.y()) / kRes));
  r.origin_x = world.min.x();
  r.origin_y = world.min.y();
  r.cells.resize(static_cast<size_t>(r.width) * r.height);
  for (int j = 0; j < r.height; ++j) {
    for (int i = 0; i < r.width; ++i) {
      const Eigen::Vector2d p(r.origin_x + (i + 0.5) * kRes, r.origin_y + (j + 0.5) * kRes);
      r.cells[static_cast<size_t>(j) * r.width + i] =
          world.distance(p) < 0.06 ? CellClass::kOccupied : CellClass::kFree;
    }
  }
  return r;
}

// A way of reading a cell class at a point of the first map's frame.
struct Score {
  size_t known = 0, classified = 0, correct = 0;
  double coverage() const { return known ? static_cast<double>(classified) / known : 0.0; }
  double accuracy() const { return classified ? static_cast<double>(correct) / classified : 0.0; }
};

template <typename ClassAt>
Score scoreOn(const es::fusion::OccupancyRaster& truth, ClassAt&& class_at) {
  Score s;
  for (int j = 0; j < truth.height; ++j) {
    for (int i = 0; i < truth.width; ++i) {
      const CellClass t = truth.at(i, j);
      ++s.known;
      const CellClass c =
          class_at(truth.origin_x + (i + 0.5) * kRes, truth.origin_y + (j + 0.5) * kRes);
      if (c == CellClass::kUnknown) continue;
      ++s.classified;
      s.correct += c == t;
    }
  }
  return s;
}

// The trinary class of the map files (occupied_thresh 0.65, free_thresh 0.196 on a probability).
CellClass trinary(double p) {
  return p >= 0.65 ? CellClass::kOccupied : p <= 0.196 ? CellClass::kFree : CellClass::kUnknown;
}

// The translation error is taken where the second map is, at `centre` (its observed circle's
// centre, in its frame): its frame's origin may lie 35 m from its cells, where a turn of 0.3°
// (within what the maps' drift bends them) moves the origin 0.18 m while the map's cells move
// 0.01-0.03 m.
const char* outcome(bool ok, const Pose2& found, const Pose2& truth,
                    const Eigen::Vector2d& centre) {
  if (!ok) return "refused";
  const double d = (found.transformPoint(centre) - truth.transformPoint(centre)).norm();
  const double a = std::abs(es::normalizeAngle(found.theta - truth.theta)) * 180.0 / kPi;
  return d <= 0.1 && a <= 1.0 ? "right" : d <= 0.5 && a <= 5.0 ? "imprecise" : "wrong";
}

struct Verdict {
  int accepted_right = 0, accepted_imprecise = 0, accepted_wrong = 0, refused = 0;
  void add(const std::string& o) {
    accepted_right += o == "right";
    accepted_imprecise += o == "imprecise";
    accepted_wrong += o == "wrong";
    refused += o == "refused";
  }
};

}  // namespace

int main(int argc, char** argv) {
  uint64_t seed =
      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count() % 1000000);
  int pairs = 50;
  std::string csv_path;
  bool verbose = false;  // --verbose: where each pair that was not aligned right went, on stderr
  int only = -1;         // --pair K: that pair alone
  es::io::CommandLine cl(
      "usage: " + std::string(argc > 0 ? argv[0] : "evidential_slam_fusion_pairs") +
          " [--seed S] [--pairs N] [--pair K] [--csv FILE] [--verbose]\n"
          "Generated office floors, two maps of each: aligns every pair (the score alone, and "
          "with\n"
          "the verification by conflict) and fuses it at the true pose next to map_merge's "
          "maximum\n"
          "and a log-odds sum, all scored on the floor's truth (docs/fusion.md, Generated pairs).",
      "Exit codes: 0 done, 1 bad usage, 3 a fusion failed.");
  auto count = [](const char* what, int least, int* out) {
    return [=](const std::string& v) {
      if (!es::io::parseNumber(v, out) || *out < least) {
        throw es::io::UsageError(std::string(what) + " wants an integer >= " +
                                 std::to_string(least) + ", not '" + v + "'");
      }
    };
  };
  cl.option("--seed", "S", "the generator's seed (default: from the clock, printed)",
            [&](const std::string& v) {
              if (!es::io::parseNumber(v, &seed)) {
                throw es::io::UsageError("--seed wants a non-negative integer, not '" + v + "'");
              }
            });
  cl.option("--pairs", "N", "how many pairs (default 50)", count("--pairs", 1, &pairs));
  cl.option("--pair", "K", "run pair K alone (0-based)", count("--pair", 0, &only));
  cl.option("--csv", "FILE", "one line per pair", [&](const std::string& v) { csv_path = v; });
  cl.flag("--verbose", "where each pair not aligned right went, on stderr",
          [&] { verbose = true; });
  if (const int code = cl.parseMain(argc, argv, 1); code >= 0) return code;
  std::printf("seed %llu, %d pairs\n", static_cast<unsigned long long>(seed), pairs);
  std::FILE* csv = csv_path.empty() ? nullptr : std::fopen(csv_path.c_str(), "w");
  if (csv != nullptr) {
    std::fprintf(csv,
                 "pair,symmetric,box,overlap,score_only,verified,decided_by_verifier,err_m,err_deg,"
                 "cov_a,cov_b,cov_fused,cov_max,cov_logodds,acc_a,acc_b,acc_fused,acc_max,"
                 "acc_logodds,err_centre_m\n");
  }
  // Verdicts by [symmetric][overlap >= 30 %] and [rule: score only, verified].
  Verdict verdict[2][2][2];
  int scored = 0;
  int fused_accurate_same_cells = 0, fused_accurate_on_both = 0;
  // Truth cells a map classifies (the second as the fused map samples it) that the fused map
  // leaves unknown: where the two maps contradict each other (conflict >= 0.01), and elsewhere.
  size_t lost_contradicted = 0, lost_uncontradicted = 0;
  int fused_knows_more_sampled = 0;
  int fused_knows_more = 0, fused_accurate = 0, max_accurate = 0, logodds_accurate = 0;
  double sum_cov[5] = {0}, sum_acc[5] = {0};
  es::fusion::AlignmentConfig score_only;
  score_only.verify_min_length = 1e9;  // never clear: the score decides alone
  es::fusion::AlignmentConfig verify_config;
  for (int k = only < 0 ? 0 : only; k < (only < 0 ? pairs : only + 1); ++k) {
    Rng rng(seed * 1000003ull + static_cast<uint64_t>(k));
    const Floor floor = randomFloor(rng);
    syn::World before = floor.world;  // the first robot's: with the box later removed
    const bool box = uniform(rng, 0.0, 1.0) < 0.5;
    if (box) {
      addBlock(&before, uniform(rng, 1.0, floor.world.max.x() - 2.0),
               uniform(rng, 1.0, floor.world.max.y() - 2.0), 0.8, 0.6);
    }
    // Observed circles centred on the floor, each holding at least 15 % of it (a robot's map of a
    // few square metres is no map to merge).
    const double area = floor.world.max.x() * floor.world.max.y();
    auto inside = [&](const Eigen::Vector2d& c, double r) {
      double cells = 0.0;
      for (double y = 0.25; y < floor.world.max.y(); y += 0.5) {
        for (double x = 0.25; x < floor.world.max.x(); x += 0.5) {
          cells += (Eigen::Vector2d(x, y) - c).norm() <= r ? 0.25 : 0.0;
        }
      }
      return cells / area;
    };
    double radius = 0.0;
    Eigen::Vector2d ca, cb;
    do {
      radius = uniform(rng, 5.0, 9.0);
      ca = {uniform(rng, 0.0, floor.world.max.x()), uniform(rng, 0.0, floor.world.max.y())};
      const double d = uniform(rng, 0.5, 1.8) * radius, dir = uniform(rng, -kPi, kPi);
      cb = ca + d * Eigen::Vector2d(std::cos(dir), std::sin(dir));
    } while (inside(ca, radius) < 0.15 || inside(cb, radius) < 0.15);
    const Pose2 truth(uniform(rng, -10.0, 10.0), uniform(rng, -10.0, 10.0),
                      uniform(rng, -kPi, kPi));
    const es::EvidentialGridMap a =
        syn::paint(before, Pose2(), ca, radius, kRes, 2 * k + 1, uniform(rng, -kBend, kBend));
    const es::EvidentialGridMap b =
        syn::paint(floor.world, truth, cb, radius, kRes, 2 * k + 2, uniform(rng, -kBend, kBend));
    if (a.observedBox().empty() || b.observedBox().empty()) continue;

    // The overlap at the true pose, as a share of the smaller map's observed cells.
    size_t observed_a = 0, observed_b = 0, both = 0;
    const es::CellBox box_a = a.observedBox(), box_b = b.observedBox();
    for (int y = box_a.min_y; y <= box_a.max_y; ++y) {
      for (int x = box_a.min_x; x <= box_a.max_x; ++x) observed_a += a.cell(x, y).observed();
    }
    for (int y = box_b.min_y; y <= box_b.max_y; ++y) {
      for (int x = box_b.min_x; x <= box_b.max_x; ++x) {
        if (!b.cell(x, y).observed()) continue;
        ++observed_b;
        const Eigen::Vector2d p = truth.transformPoint({(x + 0.5) * kRes, (y + 0.5) * kRes});
        both += a.cell(a.worldToCell(p.x(), p.y())).observed();
      }
    }
    const double overlap =
        static_cast<double>(both) / std::max<size_t>(1, std::min(observed_a, observed_b));

    const Eigen::Vector2d centre_b = truth.inverse().transformPoint(cb);  // in b's frame
    es::fusion::AlignmentResult plain, verified;
    std::string why;
    const bool plain_ok = es::fusion::alignMaps(a, b, score_only, &plain, &why);
    const bool verified_ok = es::fusion::alignMaps(a, b, verify_config, &verified, &why);
    if (verbose && std::string(outcome(verified_ok, verified.pose, truth, centre_b)) != "right") {
      // Where the miss comes from: the rank of the final candidate nearest the truth, its error.
      int rank = -1;
      double best_d = 1e9, best_a = 0.0;
      for (size_t i = 0; i < verified.candidates.size(); ++i) {
        const Pose2& p = verified.candidates[i].pose;
        const double d = std::hypot(p.x - truth.x, p.y - truth.y);
        const double deg = std::abs(es::normalizeAngle(p.theta - truth.theta)) * 180.0 / kPi;
        if (d + 0.1 * deg < best_d + 0.1 * best_a) {
          rank = static_cast<int>(i);
          best_d = d;
          best_a = deg;
        }
      }
      std::fprintf(stderr,
                   "pair %d (%s, overlap %.2f) %s; nearest final candidate #%d of %zu at %.3f m, "
                   "%.2f deg: %s\n",
                   k, floor.symmetric ? "sym" : "asym", overlap,
                   outcome(verified_ok, verified.pose, truth, centre_b), rank,
                   verified.candidates.size(), best_d, best_a, verified_ok ? "" : why.c_str());
      for (const auto& c : verified.candidates) {
        std::fprintf(
            stderr,
            "  [%.2f %.2f %.1f score %.3f conflict %.4f D %.4f C %.2f m M %.1f m overlap %zu]\n",
            c.pose.x, c.pose.y, c.pose.theta * 180 / kPi, c.score, c.conflict, c.disagreement,
            c.contradicted_m, c.matched_m, c.overlap);
      }
    }
    const int sym = floor.symmetric ? 1 : 0, big = overlap >= 0.3 ? 1 : 0;
    const char* plain_outcome = outcome(plain_ok, plain.pose, truth, centre_b);
    const char* verified_outcome = outcome(verified_ok, verified.pose, truth, centre_b);
    verdict[sym][big][0].add(plain_outcome);
    verdict[sym][big][1].add(verified_outcome);
    ++scored;

    // Fusion at the true pose, scored on the floor as the second robot left it.
    es::EvidentialGridMap fused;
    es::fusion::FusionReport report;
    es::fusion::FusionConfig config;
    if (!es::fusion::fuseMaps({{&a, Pose2()}, {&b, truth}}, config, &fused, &report, &why)) {
      std::fprintf(stderr, "pair %d: fusion failed: %s\n", k, why.c_str());
      return 3;
    }
    const es::fusion::OccupancyRaster truth_raster = truthOf(floor.world);
    const es::fusion::ClassifyConfig classify;
    auto cellOf = [](const es::EvidentialGridMap& m, const Pose2& pose, double x, double y) {
      const Eigen::Vector2d p = pose.inverse().transformPoint({x, y});
      return m.cell(m.worldToCell(p.x(), p.y()));
    };
    auto evidential = [&](const es::EvidentialGridMap& m, const Pose2& pose) {
      return scoreOn(truth_raster, [&](double x, double y) {
        return es::fusion::classify(cellOf(m, pose, x, y), classify);
      });
    };
    const Score sa = evidential(a, Pose2()), sb = evidential(b, truth),
                sf = evidential(fused, Pose2());
    const Score smax = scoreOn(truth_raster, [&](double x, double y) {
      CellClass c = CellClass::kUnknown;
      for (const es::Cell& cell : {cellOf(a, Pose2(), x, y), cellOf(b, truth, x, y)}) {
        if (!cell.observed()) continue;
        const CellClass t = trinary(es::pignistic(cell));
        if (t == CellClass::kOccupied || (t == CellClass::kFree && c == CellClass::kUnknown)) c = t;
      }
      return c;
    });
    const Score slog = scoreOn(truth_raster, [&](double x, double y) {
      double l = 0.0;
      bool any = false;
      for (const es::Cell& cell : {cellOf(a, Pose2(), x, y), cellOf(b, truth, x, y)}) {
        if (!cell.observed()) continue;
        const double p = std::clamp(es::pignistic(cell), 0.02, 0.98);
        l += std::log(p / (1.0 - p));
        any = true;
      }
      return any ? trinary(1.0 / (1.0 + std::exp(-l))) : CellClass::kUnknown;
    });
    const Score* scores[5] = {&sa, &sb, &sf, &smax, &slog};
    for (int i = 0; i < 5; ++i) {
      sum_cov[i] += scores[i]->coverage();
      sum_acc[i] += scores[i]->accuracy();
    }
    fused_knows_more += sf.coverage() >= std::max(sa.coverage(), sb.coverage());
    // The second map as the fused map's cells sample it (nearest neighbour at their centres):
    // scored at the truth's cells directly, its cells are sampled at other points.
    es::EvidentialGridMap b_sampled;
    if (!es::fusion::fuseMaps({{&a, Pose2(), 1.0}, {&b, truth}}, config, &b_sampled, &report,
                              &why)) {
      std::fprintf(stderr, "pair %d: resampling failed: %s\n", k, why.c_str());
      return 3;
    }
    const Score sbs = evidential(b_sampled, Pose2());
    fused_knows_more_sampled += sf.coverage() >= std::max(sa.coverage(), sbs.coverage());
    for (int j = 0; j < truth_raster.height; ++j) {
      for (int i = 0; i < truth_raster.width; ++i) {
        const double x = truth_raster.origin_x + (i + 0.5) * kRes;
        const double y = truth_raster.origin_y + (j + 0.5) * kRes;
        const es::Cell ca = cellOf(a, Pose2(), x, y), cb = cellOf(b_sampled, Pose2(), x, y);
        const bool known = es::fusion::classify(ca, classify) != CellClass::kUnknown ||
                           es::fusion::classify(cb, classify) != CellClass::kUnknown;
        if (!known ||
            es::fusion::classify(cellOf(fused, Pose2(), x, y), classify) != CellClass::kUnknown) {
          continue;
        }
        const bool both = ca.observed() && cb.observed();
        const double k_ab = both ? es::fusion::conflictBetween(es::fusion::Belief::fromCell(ca),
                                                               es::fusion::Belief::fromCell(cb))
                                 : 0.0;
        ++(k_ab >= 0.01 ? lost_contradicted : lost_uncontradicted);
      }
    }
    const double best_acc = std::max(sa.accuracy(), sb.accuracy());
    fused_accurate += sf.accuracy() >= best_acc - 0.001;
    // The same comparison on the same cells: the fused map's accuracy where the better map
    // classifies a cell (the union's other cells are the poorer map's, whose accuracy the fused
    // map keeps there, docs/fusion.md §9), and where both maps classify one.
    {
      const bool a_better = sa.accuracy() >= sb.accuracy();
      Score on_better, on_both, a_both, b_both;
      for (int j = 0; j < truth_raster.height; ++j) {
        for (int i = 0; i < truth_raster.width; ++i) {
          const double x = truth_raster.origin_x + (i + 0.5) * kRes;
          const double y = truth_raster.origin_y + (j + 0.5) * kRes;
          const CellClass t = truth_raster.at(i, j);
          const CellClass ca = es::fusion::classify(cellOf(a, Pose2(), x, y), classify);
          const CellClass cb = es::fusion::classify(cellOf(b, truth, x, y), classify);
          const CellClass cf = es::fusion::classify(cellOf(fused, Pose2(), x, y), classify);
          auto add = [&](Score* s, CellClass c) {
            ++s->known;
            if (c == CellClass::kUnknown) return;
            ++s->classified;
            s->correct += c == t;
          };
          if ((a_better ? ca : cb) != CellClass::kUnknown) add(&on_better, cf);
          if (ca != CellClass::kUnknown && cb != CellClass::kUnknown) {
            add(&on_both, cf);
            add(&a_both, ca);
            add(&b_both, cb);
          }
        }
      }
      fused_accurate_same_cells += on_better.accuracy() >= best_acc - 0.001;
      fused_accurate_on_both +=
          on_both.classified == 0 ||
          on_both.accuracy() >= std::max(a_both.accuracy(), b_both.accuracy()) - 0.001;
    }
    max_accurate += smax.accuracy() >= best_acc - 0.001;
    logodds_accurate += slog.accuracy() >= best_acc - 0.001;
    if (csv != nullptr) {
      std::fprintf(csv,
                   "%d,%d,%d,%.3f,%s,%s,%d,%.4f,%.3f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,"
                   "%.5f,%.4f\n",
                   k, sym, box ? 1 : 0, overlap, plain_outcome, verified_outcome,
                   verified.decided_by_verifier ? 1 : 0,
                   std::hypot(verified.pose.x - truth.x, verified.pose.y - truth.y),
                   std::abs(es::normalizeAngle(verified.pose.theta - truth.theta)) * 180.0 / kPi,
                   sa.coverage(), sb.coverage(), sf.coverage(), smax.coverage(), slog.coverage(),
                   sa.accuracy(), sb.accuracy(), sf.accuracy(), smax.accuracy(), slog.accuracy(),
                   (verified.pose.transformPoint(centre_b) - cb).norm());
    }
  }
  if (csv != nullptr) std::fclose(csv);

  std::printf(
      "\nalignment (right: within 0.1 m and 1 degree of the truth at the second map's centre; "
      "imprecise: within 0.5 m and 5 degrees; wrong: farther)\n");
  std::printf("%-12s %-9s %-22s %6s %10s %6s %8s\n", "floors", "overlap", "rule", "right",
              "imprecise", "wrong", "refused");
  const char* floors[2] = {"asymmetric", "symmetric"};
  const char* overlaps[2] = {"< 30 %", ">= 30 %"};
  const char* rules[2] = {"score alone", "score + conflict check"};
  for (int s = 0; s < 2; ++s) {
    for (int o = 0; o < 2; ++o) {
      for (int r = 0; r < 2; ++r) {
        const Verdict& v = verdict[s][o][r];
        std::printf("%-12s %-9s %-22s %6d %10d %6d %8d\n", floors[s], overlaps[o], rules[r],
                    v.accepted_right, v.accepted_imprecise, v.accepted_wrong, v.refused);
      }
    }
  }
  std::printf(
      "\nfusion at the true pose, mean over pairs (known share: cells classified / floor)\n");
  const char* names[5] = {"first map", "second map", "cautious fusion", "max of trinary",
                          "log-odds sum"};
  for (int i = 0; i < 5; ++i) {
    std::printf("%-16s known share %.4f  accuracy %.4f\n", names[i], sum_cov[i] / scored,
                sum_acc[i] / scored);
  }
  std::printf("pairs where the fusion knows at least as much as the better map: %d of %d\n",
              fused_knows_more, scored);
  std::printf(
      "... the second map sampled at the fused map's cells: %d of %d; cells a map knows and the "
      "fusion does not: %zu where the maps contradict each other (conflict >= 0.01), %zu "
      "elsewhere\n",
      fused_knows_more_sampled, scored, lost_contradicted, lost_uncontradicted);
  std::printf(
      "pairs with accuracy >= the better map's - 0.001: cautious %d, max %d, log-odds %d "
      "of %d\n",
      fused_accurate, max_accurate, logodds_accurate, scored);
  std::printf(
      "on the same cells: cautious accuracy >= the better map's - 0.001 where that map classifies "
      "a cell: %d of %d; where both maps do (against the better there): %d of %d\n",
      fused_accurate_same_cells, scored, fused_accurate_on_both, scored);
  return 0;
}
