// evidential_slam_offline: evidential FastSLAM on an MRPT rawlog. Thin: parses the command line
// and hands over to io::runOffline (session/offline_runner.h), which documents outputs and exit
// codes.
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "evidential_slam/session/offline_runner.h"

int main(int argc, char** argv) {
  namespace io = evidential_slam::io;
  const std::string program = argc > 0 ? argv[0] : "evidential_slam_offline";
  const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
  io::OfflineOptions options;
  bool help = false;
  std::string error;
  if (!io::parseOfflineArgs(args, &options, &help, &error)) {
    std::fprintf(stderr, "error: %s (see --help)\n", error.c_str());
    return io::kExitUsage;
  }
  if (help) {
    std::fputs(io::offlineUsage(program).c_str(), stdout);
    return io::kExitOk;
  }
  return io::runOffline(options, stdout, stderr, isatty(fileno(stderr)) != 0);
}
