// Saving files so that a failed save leaves the previous files as they were and nobody ever reads a
// half-written one. Each file is written to a temporary name in its own directory, flushed to disk
// (fsync) and renamed over the old one only once every file of the set is complete: a map's layers,
// trajectory and summary are replaced together or not at all. A write that fails (a full disk, an
// unwritable directory, a file size limit) gives a one-line reason and removes the temporary files.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace evidential_slam {
namespace io {

class AtomicFiles {
 public:
  AtomicFiles();
  ~AtomicFiles();  // removes the temporary files of a set that was not committed
  AtomicFiles(const AtomicFiles&) = delete;
  AtomicFiles& operator=(const AtomicFiles&) = delete;

  // Writes the content of `path` through `write` into a temporary file beside it (`bytes`, if
  // set, gets its size). False (and `error`: "cannot write '<path>': <reason>") when `write`
  // returns false or the data cannot be written; the set is then abandoned (every temporary file
  // removed).
  bool add(const std::string& path, const std::function<bool(std::ostream&)>& write,
           std::string* error, uint64_t* bytes = nullptr);
  // For writers that take a file name (MRPT's image saver picks the format by the extension):
  // `write` gets a temporary path with the extension of `path`; `verify`, if set, checks what it
  // wrote (for a writer that does not report every failed write).
  bool addByPath(const std::string& path,
                 const std::function<bool(const std::string& temp_path)>& write,
                 const std::function<bool(const std::string& temp_path)>& verify,
                 std::string* error);
  // Creates the temporary file of `path` for a writer that fills it over time (a recording);
  // its name goes to `temp_path`.
  bool reserve(const std::string& path, std::string* temp_path, std::string* error);
  // Syncs every temporary file to disk, then renames each over its target and syncs their
  // directories. False (and `error`) when a sync or a rename fails, the files not yet renamed
  // being removed (a failed sync renames none), and when an earlier add failed.
  bool commit(std::string* error);
  // Removes the temporary files; the set can be used again.
  void abandon();

  bool empty() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One file, written and renamed into place as above.
bool writeFileAtomically(const std::string& path, const std::function<bool(std::ostream&)>& write,
                         std::string* error);

}  // namespace io
}  // namespace evidential_slam
