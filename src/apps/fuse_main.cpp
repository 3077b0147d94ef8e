// evidential_slam_fuse: evidential map fusion. Thin: parses the command line and hands over to
// io::runFuse (session/fuse_command.h), which documents outputs and exit codes.
#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/session/fuse_command.h"
#include "evidential_slam/session/offline_runner.h"

int main(int argc, char** argv) {
  namespace io = evidential_slam::io;
  const std::string program = argc > 0 ? argv[0] : "evidential_slam_fuse";
  const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
  io::FuseOptions options;
  bool help = false;
  std::string error;
  if (!io::parseFuseArgs(args, &options, &help, &error)) {
    std::fprintf(stderr, "error: %s (see --help)\n", error.c_str());
    return io::kExitUsage;
  }
  if (help) {
    std::fputs(io::fuseUsage(program).c_str(), stdout);
    return io::kExitOk;
  }
  return io::runFuse(options, stdout, stderr);
}
