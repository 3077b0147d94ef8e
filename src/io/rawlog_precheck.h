// Internal to io/ (it names MRPT types): the bounded pre-check that rawlog_reader.cpp runs over the
// bytes of each serialised MRPT object before MRPT deserialises it. MRPT allocates what a length
// field asks for before it reads the data (a beam count of 2^30 goes straight into resizeScan, an
// action count into a vector), so each length field of the classes a 2-D laser rawlog holds is
// checked against RawlogLimits and against the bytes the stream still has, and a class that
// cannot appear where it is found (or is not registered) is refused. Only the layout of those
// classes is walked (MRPT 2.5's serializeFrom, every version it reads); nothing is built here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <mrpt/io/CStream.h>
#include <mrpt/rtti/CObject.h>

#include "evidential_slam/io/rawlog_reader.h"

namespace evidential_slam {
namespace io {
namespace detail {

// A CStream over bytes in memory (RawlogReader::openBytes, the fuzzer).
class BytesStream : public mrpt::io::CStream {
 public:
  explicit BytesStream(std::string bytes) : bytes_(std::move(bytes)) {}
  size_t Read(void* buffer, size_t count) override;
  size_t Write(const void*, size_t) override { return 0; }
  uint64_t Seek(int64_t, TSeekOrigin) override { return position_; }
  uint64_t getTotalBytesCount() const override { return bytes_.size(); }
  uint64_t getPosition() const override { return position_; }

 private:
  std::string bytes_;
  size_t position_ = 0;
};

// Reads ahead of a source stream so the next object's bytes can be checked before MRPT reads them,
// and caps how many bytes MRPT may read for one object. MRPT's archive reads through Read().
class LookaheadStream : public mrpt::io::CStream {
 public:
  explicit LookaheadStream(mrpt::io::CStream& source) : source_(source) {}

  // Makes `n` bytes past the read position available; false when the source ends (or fails)
  // before that.
  bool fill(uint64_t n);
  // Byte `offset` past the read position; fill(offset + 1) must have returned true.
  const uint8_t* peek(uint64_t offset) const { return buffer_.data() + head_ + offset; }
  // From now on Read() hands out at most `bytes` more (a short read: MRPT then throws).
  void capReads(uint64_t bytes) { cap_left_ = bytes; }
  uint64_t consumed() const { return consumed_; }
  bool sourceFailed() const { return failed_; }  // e.g. broken or cut gzip data
  bool capHit() const { return cap_hit_; }

  size_t Read(void* buffer, size_t count) override;
  size_t Write(const void*, size_t) override { return 0; }
  uint64_t Seek(int64_t, TSeekOrigin) override { return consumed_; }
  uint64_t getTotalBytesCount() const override { return source_.getTotalBytesCount(); }
  uint64_t getPosition() const override { return consumed_; }

 private:
  mrpt::io::CStream& source_;
  std::vector<uint8_t> buffer_;
  size_t head_ = 0;  // read position in buffer_
  uint64_t consumed_ = 0;
  uint64_t cap_left_ = UINT64_MAX;
  bool cap_hit_ = false;
  bool ended_ = false;
  bool failed_ = false;
};

enum class Precheck {
  kOk,         // every field checked; the object is `bytes` long
  kUnchecked,  // a registered class the check does not know (e.g. a camera image); MRPT reads it
  kTruncated,  // the stream ends inside the object
  kCorrupt,    // a length beyond the limits, an impossible class, version or flag (`why`)
};

struct PrecheckResult {
  Precheck verdict = Precheck::kOk;
  uint64_t bytes = 0;  // kOk: the object's length in the stream
  std::string why;     // kCorrupt: one line, no raw bytes; kUnchecked: the class not walked
};

// Checks the top-level rawlog object at the read position of `in` (an action collection, a
// sensory frame or an observation) without consuming it.
PrecheckResult precheckRawlogObject(LookaheadStream& in, const RawlogLimits& limits);

}  // namespace detail
}  // namespace io
}  // namespace evidential_slam
