// Where the filter's update spends its time (the offline runner's --profile): CPU time per section
// of the update summed over the worker threads (each thread's own CPU clock, so a busy machine
// does not inflate it), exclusive of the sections nested in it, and what the sections did (cells
// visited, tiles cloned, ...). Off unless a Profiler is made active; then each timed section costs
// two clock reads (the sections are per particle, group or tile clone, not per cell).
// Optionally it also measures the compute floor of the map work: the cells every group's beams
// visit, one read, one multiply and one write each on a map of its own (ProfileFloor).
#pragma once

#include <array>
#include <atomic>
#include <ctime>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace evidential_slam {

enum class ProfileSection : int {
  kWideMatchForward,  // the wide-basin match weighing its candidates (forward model)
  kIcp,               // ICP and its correspondence search (wide match and refinement)
  kHillClimb,         // the refinement's hill climb (the scan matcher's score, ~46 calls)
  kConstraint,        // the constrained merge's translation constraint
  kWeighAccumulate,   // the fused traversal: forward model and the scan's evidence
  kOpenSpace,         // the open-space conflict pass
  kApplyScan,         // applying the accumulated scan to a map
  kTileClone,         // copy-on-write tile clones and new tiles
  kResample,          // resampling and the particle copies it makes
  kCount
};
const char* profileSectionName(ProfileSection s);

enum class ProfileCounter : int {
  kUpdates,          // filter updates (processed scans after the first)
  kGroupsWeighed,    // groups whose scan was traversed and weighed
  kGroupsApplied,    // groups whose map the scan was applied to
  kVisitedCells,     // cells the weighing traversals visited (with repeats)
  kAppliedCells,     // distinct cells the scans were applied to
  kTileClones,       // tiles cloned or created for a write
  kFloorCells,       // cells the floor replay visited
  kCount
};
const char* profileCounterName(ProfileCounter c);

class Profiler {
 public:
  // The profiler the filter reports to, or null (the default: nothing is timed).
  static Profiler* active() { return active_.load(std::memory_order_relaxed); }
  // Makes `profiler` (may be null) the active one; it must outlive its use.
  static void setActive(Profiler* profiler) { active_.store(profiler, std::memory_order_relaxed); }

  void addTime(ProfileSection s, int64_t ns) {
    ns_[static_cast<size_t>(s)].fetch_add(ns, std::memory_order_relaxed);
  }
  void count(ProfileCounter c, uint64_t n = 1) {
    counts_[static_cast<size_t>(c)].fetch_add(n, std::memory_order_relaxed);
  }
  int64_t nanoseconds(ProfileSection s) const {
    return ns_[static_cast<size_t>(s)].load(std::memory_order_relaxed);
  }
  uint64_t counter(ProfileCounter c) const {
    return counts_[static_cast<size_t>(c)].load(std::memory_order_relaxed);
  }

  // The floor replay (see the header comment): on when true. The filter calls floorReplay.
  bool floor_enabled = false;
  int64_t floorNanoseconds() const { return floor_ns_; }
  // Replays the cells of one group's beams, `cells` as (x, y) pairs, on the floor map of slot
  // `slot` (one per group index); timed, single-threaded.
  void floorReplay(size_t slot, const std::vector<std::pair<int, int>>& cells);

  // A text report: per section ms per update and share, ns per visited cell, the counters.
  std::string report() const;

  Profiler();
  ~Profiler();

 private:
  static std::atomic<Profiler*> active_;
  std::array<std::atomic<int64_t>, static_cast<size_t>(ProfileSection::kCount)> ns_{};
  std::array<std::atomic<uint64_t>, static_cast<size_t>(ProfileCounter::kCount)> counts_{};
  struct FloorMap;
  std::vector<std::unique_ptr<FloorMap>> floor_maps_;
  int64_t floor_ns_ = 0;
};

// Times a section of the calling thread, exclusive of the timers started inside it, when a
// profiler is active.
class ProfileTimer {
 public:
  // This thread's CPU time, ns.
  static int64_t threadCpuNs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
  }
  explicit ProfileTimer(ProfileSection s) : profiler_(Profiler::active()), section_(s) {
    if (profiler_ == nullptr) return;
    parent_ = current_;
    current_ = this;
    start_ = threadCpuNs();
  }
  ~ProfileTimer() {
    if (profiler_ == nullptr) return;
    const int64_t ns = threadCpuNs() - start_;
    profiler_->addTime(section_, ns - nested_ns_);
    current_ = parent_;
    if (parent_ != nullptr) parent_->nested_ns_ += ns;
  }
  ProfileTimer(const ProfileTimer&) = delete;
  ProfileTimer& operator=(const ProfileTimer&) = delete;

 private:
  static thread_local ProfileTimer* current_;
  Profiler* profiler_;
  ProfileSection section_;
  ProfileTimer* parent_ = nullptr;
  int64_t nested_ns_ = 0;
  int64_t start_ = 0;
};

}  // namespace evidential_slam
