// Runs a piece of a test in a forked child under conditions the test process itself must not
// take on: a file size limit (a full disk, portably: with SIGXFSZ ignored, a write past the limit
// fails with EFBIG, "File too large") and the rights of user nobody (an unwritable directory even
// when the tests run as root).
#pragma once

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <functional>

namespace evidential_slam {
namespace test {

constexpr uid_t kNobody = 65534;

// `fn`'s return value as the child's exit status (0..255), or -1 when the child did not exit.
inline int runInChild(const std::function<int()>& fn, uint64_t max_file_bytes = 0,
                      bool as_nobody = false) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (max_file_bytes > 0) {
      signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{max_file_bytes, max_file_bytes};
      if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(100);
    }
    if (as_nobody && geteuid() == 0 && (setgid(kNobody) != 0 || setuid(kNobody) != 0)) _exit(101);
    _exit(fn());
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

}  // namespace test
}  // namespace evidential_slam
