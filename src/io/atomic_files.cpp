// Temporary file, fsync, rename. See atomic_files.h.
#include "evidential_slam/io/atomic_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>
#include <streambuf>

#include "evidential_slam/io/error_text.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

// A stream buffer writing to a file descriptor that keeps the errno of the first failed write.
class FdStreambuf : public std::streambuf {
 public:
  explicit FdStreambuf(int fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!flushBuffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return flushBuffer() ? 0 : -1; }

 private:
  bool flushBuffer() {
    const char* p = pbase();
    while (p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        if (error_ == 0) error_ = n < 0 ? errno : EIO;
        return false;
      }
      p += n;
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return true;
  }

  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buffer_;
};

std::string reason(int err) { return err != 0 ? std::strerror(err) : "write failed"; }

// Flushes `fd`'s data to disk, then closes it; the errno of the first failure, or 0.
int syncAndClose(int fd) {
  int err = 0;
  if (::fsync(fd) != 0 && errno != EINVAL) err = errno;  // EINVAL: a file that cannot be synced
  if (::close(fd) != 0 && err == 0) err = errno;
  return err;
}

// Creates a new, empty temporary file beside `path` (same extension, mode 0666 less the umask)
// and returns its descriptor, or -1 with errno.
int createTemp(const std::string& path, std::string* temp) {
  static thread_local std::mt19937_64 random(std::random_device{}());
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string name = target.filename().string();
  const std::string ext = target.extension().string();
  for (int attempt = 0; attempt < 100; ++attempt) {
    char tag[20];
    std::snprintf(tag, sizeof(tag), "%012llx", static_cast<unsigned long long>(random() >> 16));
    *temp = (dir / ("." + name + ".tmp" + tag + ext)).string();
    const int fd = ::open(temp->c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  return -1;
}

}  // namespace

struct AtomicFiles::Impl {
  struct Staged {
    std::string path, temp;
  };
  std::vector<Staged> staged;
  std::string failure;  // why the set was abandoned; commit() refuses it

  bool fail(const std::string& path, const std::string& why, std::string* error) {
    failure = "cannot write " + quotedPath(path) + ": " + oneLineMessage(why);
    if (error) *error = failure;
    removeTemps();
    return false;
  }
  void removeTemps() {
    for (const Staged& s : staged) ::unlink(s.temp.c_str());
    staged.clear();
  }
};

AtomicFiles::AtomicFiles() : impl_(std::make_unique<Impl>()) {}
AtomicFiles::~AtomicFiles() { abandon(); }

bool AtomicFiles::empty() const { return impl_->staged.empty(); }

void AtomicFiles::abandon() {
  impl_->removeTemps();
  impl_->failure.clear();
}

bool AtomicFiles::reserve(const std::string& path, std::string* temp_path, std::string* error) {
  std::string temp;
  const int fd = createTemp(path, &temp);
  if (fd < 0) return impl_->fail(path, reason(errno), error);
  ::close(fd);
  impl_->staged.push_back({path, temp});
  *temp_path = temp;
  return true;
}

bool AtomicFiles::add(const std::string& path, const std::function<bool(std::ostream&)>& write,
                      std::string* error, uint64_t* bytes) {
  std::string temp;
  const int fd = createTemp(path, &temp);
  if (fd < 0) return impl_->fail(path, reason(errno), error);
  impl_->staged.push_back({path, temp});
  int err = 0;
  bool wrote = false;
  {
    FdStreambuf buffer(fd);
    std::ostream out(&buffer);
    try {
      wrote = write(out);
    } catch (const std::exception& e) {
      ::close(fd);
      return impl_->fail(path, e.what(), error);
    }
    out.flush();
    err = buffer.error();
    wrote = wrote && out.good() && err == 0;
  }
  struct stat st {};
  if (bytes && ::fstat(fd, &st) == 0) *bytes = static_cast<uint64_t>(st.st_size);
  if (::close(fd) != 0 && err == 0) err = errno;
  if (!wrote || err != 0) return impl_->fail(path, reason(err), error);
  return true;
}

bool AtomicFiles::addByPath(const std::string& path,
                            const std::function<bool(const std::string&)>& write,
                            const std::function<bool(const std::string&)>& verify,
                            std::string* error) {
  std::string temp;
  if (!reserve(path, &temp, error)) return false;
  errno = 0;
  bool wrote = false;
  try {
    wrote = write(temp);
  } catch (const std::exception& e) {
    return impl_->fail(path, e.what(), error);
  }
  if (!wrote) return impl_->fail(path, reason(errno), error);
  if (verify && !verify(temp)) {
    return impl_->fail(path, "the file came out incomplete (disk full?)", error);
  }
  return true;
}

bool AtomicFiles::commit(std::string* error) {
  if (!impl_->failure.empty()) {
    if (error) *error = impl_->failure;
    return false;
  }
  auto& staged = impl_->staged;
  // Every file's data on disk before any of them replaces an old one.
  for (const auto& s : staged) {
    const int fd = ::open(s.temp.c_str(), O_RDONLY | O_CLOEXEC);
    const int err = fd < 0 ? errno : syncAndClose(fd);
    if (err != 0) return impl_->fail(s.path, reason(err), error);
  }
  std::set<std::string> dirs;
  for (size_t i = 0; i < staged.size(); ++i) {
    if (::rename(staged[i].temp.c_str(), staged[i].path.c_str()) != 0) {
      const int err = errno;
      const std::string path = staged[i].path;
      staged.erase(staged.begin(), staged.begin() + static_cast<std::ptrdiff_t>(i));
      return impl_->fail(path, reason(err), error);
    }
    const fs::path parent = fs::path(staged[i].path).parent_path();
    dirs.insert(parent.empty() ? "." : parent.string());
  }
  staged.clear();
  // The renames themselves reach the disk when the directories are synced.
  for (const std::string& dir : dirs) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
      ::fsync(fd);
      ::close(fd);
    }
  }
  return true;
}

bool writeFileAtomically(const std::string& path, const std::function<bool(std::ostream&)>& write,
                         std::string* error) {
  AtomicFiles files;
  return files.add(path, write, error) && files.commit(error);
}

}  // namespace io
}  // namespace evidential_slam
