// The pre-check of serialised rawlog objects. See rawlog_precheck.h.
//
// The layouts walked here are those of MRPT 2.5's serializeFrom for every version it reads:
// CActionCollection, CSensoryFrame, CActionRobotMovement2D, CObservation2DRangeScan,
// CObservationOdometry, CPose2D, CPose3D, CPosePDFGaussian, CMatrixF and CMatrixD. Each object is
// `<name length | 0x80> <class name> <version byte> <payload> <0x88>` (or, in the format before
// MRPT 0.5.5, `<name length> 00 00 00 <class name> <int32 version> <payload>`).
#include "rawlog_precheck.h"

#include <algorithm>
#include <cstring>

#include <mrpt/math/CMatrixD.h>
#include <mrpt/math/CMatrixF.h>
#include <mrpt/obs/CAction.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/poses/CPosePDFGaussian.h>

#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace detail {

size_t BytesStream::Read(void* buffer, size_t count) {
  const size_t n = std::min(count, bytes_.size() - position_);
  if (n > 0) std::memcpy(buffer, bytes_.data() + position_, n);
  position_ += n;
  return n;
}

bool LookaheadStream::fill(uint64_t n) {
  constexpr size_t kChunk = 64 * 1024;
  while (buffer_.size() - head_ < n) {
    if (ended_) return false;
    if (head_ > 0) {  // drop what was handed out before growing
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
    const size_t have = buffer_.size();
    const size_t want = std::max<size_t>(kChunk, n - have);
    buffer_.resize(have + want);
    size_t got = source_.Read(buffer_.data() + have, want);
    if (got > want) {  // a zlib error (-1) seen through size_t
      failed_ = true;
      got = 0;
    }
    if (got < want) ended_ = true;  // gzread and plain reads come back short only at the end
    buffer_.resize(have + got);
  }
  return true;
}

size_t LookaheadStream::Read(void* buffer, size_t count) {
  size_t allowed = count;
  if (cap_left_ < allowed) {
    allowed = static_cast<size_t>(cap_left_);
    cap_hit_ = true;
  }
  fill(allowed);
  const size_t n = std::min<size_t>(allowed, buffer_.size() - head_);
  if (n > 0) std::memcpy(buffer, buffer_.data() + head_, n);
  head_ += n;
  consumed_ += n;
  if (cap_left_ != UINT64_MAX) cap_left_ -= n;
  return n;
}

namespace {

using mrpt::rtti::TRuntimeClassId;

constexpr uint8_t kEndFlag = 0x88;  // MRPT's SERIALIZATION_END_FLAG

struct Stop {
  Precheck verdict;
  std::string why;
};

// Where an object is found, and what may be there.
struct Slot {
  const TRuntimeClassId* base;  // nullptr: a top-level rawlog entry
  bool exact;                   // the class itself (MRPT reads into an existing object)
  const char* role;             // for messages: "an observation", ...
  uint32_t rows = 0, cols = 0;  // a matrix slot of a fixed shape (0: any)
};

class Walker {
 public:
  Walker(LookaheadStream& in, const RawlogLimits& limits) : in_(in), limits_(limits) {}

  uint64_t offset() const { return at_; }

  void topLevel() { object({nullptr, false, "a rawlog entry"}); }

 private:
  [[noreturn]] void corrupt(const std::string& why) { throw Stop{Precheck::kCorrupt, why}; }

  const uint8_t* take(uint64_t n) {
    if (at_ + n > limits_.max_object_bytes) {
      corrupt("an object longer than " + std::to_string(limits_.max_object_bytes) + " bytes");
    }
    if (!in_.fill(at_ + n)) throw Stop{Precheck::kTruncated, ""};
    const uint8_t* p = in_.peek(at_);
    at_ += n;
    return p;
  }
  void skip(uint64_t n) { take(n); }
  uint8_t u8() { return *take(1); }
  uint32_t u32() {
    uint32_t v;
    std::memcpy(&v, take(4), 4);  // little-endian, as MRPT writes on every platform it builds on
    return v;
  }
  int32_t i32() { return static_cast<int32_t>(u32()); }
  // A serialised bool. Old MRPT versions wrote some flags uninitialised (any byte), so a byte
  // other than 0 and 1 is accepted where nothing depends on it; where the layout that follows
  // depends on it (`decides_layout`), how MRPT's build reads such a bool is not defined.
  bool flag(const char* what, bool decides_layout) {
    const uint8_t b = u8();
    if (decides_layout && b > 1)
      corrupt(std::string("a ") + what + " flag of " + std::to_string(b));
    return b != 0;
  }
  void string(const char* what) {
    const uint32_t n = u32();
    if (n > limits_.max_string_bytes) {
      corrupt(std::string("a ") + what + " of " + std::to_string(n) + " bytes (more than the " +
              std::to_string(limits_.max_string_bytes) + " allowed)");
    }
    skip(n);
  }
  // A count of `what` (elements of `bytes_each` bytes, skipped here unless 0) within `limit`.
  uint32_t count(const char* what, uint32_t limit, uint64_t bytes_each) {
    const uint32_t n = u32();
    if (n > limit) {
      corrupt(std::to_string(n) + " " + what + " (more than the " + std::to_string(limit) +
              " allowed)");
    }
    if (bytes_each > 0) skip(bytes_each * n);
    return n;
  }
  int32_t choice(const char* what, int32_t max) {
    const int32_t v = i32();
    if (v < 0 || v > max) corrupt(std::string("an unknown ") + what + " " + std::to_string(v));
    return v;
  }
  [[noreturn]] void badVersion(const TRuntimeClassId* id, int version) {
    corrupt(std::string("a ") + id->className + " of unknown version " + std::to_string(version));
  }

  bool fits(const TRuntimeClassId* id, const Slot& slot) const {
    if (slot.exact) return id == slot.base;
    if (slot.base) return id->derivedFrom(slot.base);
    return id == CLASS_ID(mrpt::obs::CActionCollection) ||
           id == CLASS_ID(mrpt::obs::CSensoryFrame) ||
           id->derivedFrom(CLASS_ID(mrpt::obs::CObservation));
  }

  void object(const Slot& slot) {
    const uint8_t first = u8();
    const bool old_format = (first & 0x80) == 0;
    if (old_format && (u8() != 0 || u8() != 0 || u8() != 0)) {
      corrupt(std::string("no valid object header where ") + slot.role + " was expected");
    }
    const size_t name_length = first & 0x7f;
    if (name_length == 0 || name_length > 120) {
      corrupt(std::string("no valid object header where ") + slot.role + " was expected");
    }
    const auto* name_bytes = reinterpret_cast<const char*>(take(name_length));
    const std::string name(name_bytes, name_length);
    if (name == "nullptr")
      corrupt(std::string("a null object where ") + slot.role + " was expected");
    int version = 0;
    if (old_format) {
      version = i32();
      if (version < 0 || version >= 255)
        corrupt("an object header of version " + std::to_string(version));
    } else {
      version = u8();
    }
    const TRuntimeClassId* id = mrpt::rtti::findRegisteredClass(name);
    if (!id) corrupt("an object of unknown class " + quotedForMessage(name));
    if (!fits(id, slot)) {
      corrupt(std::string("a ") + id->className + " where " + slot.role + " was expected");
    }
    payload(id, version, slot);
    if (!old_format && u8() != kEndFlag) {
      corrupt(std::string("a ") + id->className + " not followed by MRPT's end-of-object flag");
    }
  }

  void payload(const TRuntimeClassId* id, int v, const Slot& slot) {
    using namespace mrpt::obs;
    using namespace mrpt::poses;
    if (id == CLASS_ID(CActionCollection)) {
      if (v != 0) badVersion(id, v);
      const uint32_t n = count("actions in a collection", limits_.max_objects, 0);
      for (uint32_t i = 0; i < n; ++i) object({CLASS_ID(CAction), false, "an action"});
    } else if (id == CLASS_ID(CSensoryFrame)) {
      if (v > 2) badVersion(id, v);
      if (v < 2) skip(4);   // frame ID
      if (v == 0) skip(8);  // time stamp
      const uint32_t n = count("observations in a sensory frame", limits_.max_objects, 0);
      for (uint32_t i = 0; i < n; ++i) object({CLASS_ID(CObservation), false, "an observation"});
    } else if (id == CLASS_ID(CActionRobotMovement2D)) {
      robotMovement2D(id, v);
    } else if (id == CLASS_ID(CObservation2DRangeScan)) {
      rangeScan(id, v);
    } else if (id == CLASS_ID(CObservationOdometry)) {
      if (v > 2) badVersion(id, v);
      object({CLASS_ID(CPose2D), true, "an odometry pose"});
      string("sensor label");
      skip(8);  // time stamp
      if (v >= 1) {
        const bool encoders = flag("has-encoders", v >= 2);
        if (encoders || v < 2) skip(8);
        const bool velocities = flag("has-velocities", v >= 2);
        if (v < 2) {
          skip(8);
        } else if (velocities) {
          skip(24);
        }
      }
    } else if (id == CLASS_ID(CPose2D)) {
      if (v > 1) badVersion(id, v);
      skip(v == 0 ? 12 : 24);
    } else if (id == CLASS_ID(CPose3D)) {
      if (v == 0) {
        object({CLASS_ID(mrpt::math::CMatrixF), true, "a 4x4 pose matrix", 4, 4});
      } else if (v == 1) {
        object({CLASS_ID(mrpt::math::CMatrixD), true, "a 4x4 pose matrix", 4, 4});
      } else if (v == 2) {
        skip(7 * 8);
      } else if (v == 3) {
        skip(12 * 8);
      } else {
        badVersion(id, v);
      }
    } else if (id == CLASS_ID(CPosePDFGaussian)) {
      if (v > 2) badVersion(id, v);
      object({CLASS_ID(CPose2D), true, "a mean pose"});
      if (v == 0) {
        object({CLASS_ID(mrpt::math::CMatrixF), true, "a 3x3 covariance", 3, 3});
      } else {
        skip(6 * (v == 1 ? 4 : 8));  // the upper triangle of a 3x3 covariance
      }
    } else if (id == CLASS_ID(mrpt::math::CMatrixF) || id == CLASS_ID(mrpt::math::CMatrixD)) {
      if (v != 0) badVersion(id, v);
      const uint32_t rows = u32(), cols = u32();
      const uint64_t cells = static_cast<uint64_t>(rows) * cols;
      if (rows > limits_.max_matrix_elements || cols > limits_.max_matrix_elements ||
          cells > limits_.max_matrix_elements) {
        corrupt("a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix (more than " +
                std::to_string(limits_.max_matrix_elements) + " elements allowed)");
      }
      if (slot.rows > 0 && (rows != slot.rows || cols != slot.cols)) {
        corrupt("a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix where " +
                slot.role + " was expected");
      }
      skip(cells * (id == CLASS_ID(mrpt::math::CMatrixF) ? 4 : 8));
    } else {
      throw Stop{Precheck::kUnchecked, id->className};
    }
  }

  // The odometry increment's motion model: MRPT draws `samples` particles for the Thrun model.
  void motionModel(int32_t model, int32_t samples) {
    if (model != 0 &&
        (samples < 0 || static_cast<uint32_t>(samples) > limits_.max_motion_samples)) {
      corrupt("a motion model of " + std::to_string(samples) + " samples (at most " +
              std::to_string(limits_.max_motion_samples) + " allowed)");
    }
  }

  void robotMovement2D(const TRuntimeClassId* id, int v) {
    using mrpt::poses::CPose2D;
    using mrpt::poses::CPosePDF;
    const Slot increment{CLASS_ID(CPose2D), true, "an odometry increment"};
    const Slot pdf{CLASS_ID(CPosePDF), false, "a pose PDF"};
    if (v > 7) badVersion(id, v);
    if (v <= 1) {
      object(pdf);
      choice("estimation method", 1);
      if (v == 1) {
        flag("has-velocities", false);
        skip(8);
        flag("has-encoders", false);
        skip(8);
      }
      return;
    }
    const int32_t method = choice("estimation method", 1);
    if (method == 0) {  // odometry: the raw increment and the motion model's options
      object(increment);
      if (v == 2) {
        skip(44);
      } else {
        const int32_t model = choice("motion model", 1);
        // Gaussian model: version 3 has three unused floats and two doubles, later six floats.
        skip(v == 3 ? 3 * 4 + 2 * 8 : 6 * 4);
        const int32_t samples = i32();
        skip(4 * 4);
        if (v >= 5) skip(2 * 4);
        motionModel(model, samples);
      }
    } else {
      object(pdf);
    }
    const bool velocities = flag("has-velocities", v >= 7);
    if (v < 7) {
      skip(8);
    } else if (velocities) {
      skip(24);
    }
    const bool encoders = flag("has-encoders", v >= 7);
    if (v < 7 || encoders) skip(8);
    if (v >= 6) skip(8);  // time stamp
  }

  void rangeScan(const TRuntimeClassId* id, int v) {
    using mrpt::math::CMatrixF;
    using mrpt::poses::CPose3D;
    if (v > 7) badVersion(id, v);
    skip(4);  // aperture
    flag("right-to-left", false);
    skip(4);  // maximum range
    object({CLASS_ID(CPose3D), true, "a sensor pose"});
    if (v < 6) object({CLASS_ID(CMatrixF), true, "a sensor pose covariance"});
    const uint32_t beams = count("beams in a scan", limits_.max_beams, 4);  // the ranges
    if (v >= 1) skip(beams);  // a validity byte per beam (version 0 derives it from the ranges)
    if (v <= 3) {
      if (v >= 2) skip(4);  // range noise
      if (v >= 3) skip(8);  // time stamp
      return;
    }
    skip(4 + 8 + 4);  // range noise, time stamp, beam aperture
    if (v >= 5) {
      string("sensor label");
      skip(8);  // pitch step (a double)
    }
    if (v >= 7 && flag("has-intensity", true)) skip(4ull * beams);
  }

  LookaheadStream& in_;
  const RawlogLimits& limits_;
  uint64_t at_ = 0;
};

}  // namespace

PrecheckResult precheckRawlogObject(LookaheadStream& in, const RawlogLimits& limits) {
  PrecheckResult result;
  Walker walker(in, limits);
  try {
    walker.topLevel();
    result.bytes = walker.offset();
  } catch (const Stop& stop) {
    result.verdict = stop.verdict;
    result.why = stop.why;
  }
  return result;
}

}  // namespace detail
}  // namespace io
}  // namespace evidential_slam
