// AtomicFiles: a set of files replaces the old ones together or not at all. Checked on the bytes
// of the old files and the directory listing (no temporary file left) after a writer that fails,
// a full disk (a file size limit in a child process) and an unwritable or missing directory.
#include "evidential_slam/io/atomic_files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include "child_process.h"
#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::function<bool(std::ostream&)> text(const std::string& content) {
  return [content](std::ostream& out) { return static_cast<bool>(out << content); };
}

// Two files written as version 1.
fs::path twoFiles() {
  const fs::path dir = test::scratchDir();
  AtomicFiles files;
  std::string error;
  EXPECT_TRUE(files.add((dir / "a.txt").string(), text("a1"), &error)) << error;
  EXPECT_TRUE(files.add((dir / "b.npy").string(), text("b1"), &error)) << error;
  EXPECT_TRUE(files.commit(&error)) << error;
  return dir;
}

void expectVersion1(const fs::path& dir) {
  EXPECT_EQ(test::readText(dir / "a.txt"), "a1");
  EXPECT_EQ(test::readText(dir / "b.npy"), "b1");
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"a.txt", "b.npy"}));
}

TEST(AtomicFiles, FilesAppearOnlyAtCommit) {
  const fs::path dir = twoFiles();
  AtomicFiles files;
  std::string error;
  uint64_t bytes = 0;
  ASSERT_TRUE(files.add((dir / "a.txt").string(), text("a2"), &error, &bytes)) << error;
  EXPECT_EQ(bytes, 2u);
  ASSERT_TRUE(files.add((dir / "c.txt").string(), text("c2"), &error)) << error;
  // Staged: the old content is still there, the new one sits beside it under a hidden name with
  // the same extension (MRPT's image saver picks the format by it).
  EXPECT_EQ(test::readText(dir / "a.txt"), "a1");
  EXPECT_FALSE(fs::exists(dir / "c.txt"));
  const auto staged = listing(dir);
  ASSERT_EQ(staged.size(), 4u);
  EXPECT_EQ(staged[0].rfind(".a.txt.tmp", 0), 0u) << staged[0];
  EXPECT_EQ(fs::path(staged[0]).extension(), ".txt");
  ASSERT_TRUE(files.commit(&error)) << error;
  EXPECT_EQ(test::readText(dir / "a.txt"), "a2");
  EXPECT_EQ(test::readText(dir / "c.txt"), "c2");
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"a.txt", "b.npy", "c.txt"}));
  // A new file gets the usual permissions (0666 less the umask), not a temporary file's 0600.
  const mode_t mask = umask(0);
  umask(mask);
  struct stat st {};
  ASSERT_EQ(stat((dir / "c.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
}

TEST(AtomicFiles, AFailedWriterLeavesTheOldSet) {
  const fs::path dir = twoFiles();
  std::string error;
  {
    AtomicFiles files;
    ASSERT_TRUE(files.add((dir / "a.txt").string(), text("a2"), &error));
    EXPECT_FALSE(files.add((dir / "b.npy").string(),
                           [](std::ostream& out) { return !(out << "b2").fail() && false; },
                           &error));
    EXPECT_NE(error.find("cannot write '" + (dir / "b.npy").string() + "'"), std::string::npos)
        << error;
    EXPECT_FALSE(files.commit(&error)) << "an abandoned set commits nothing";
  }
  expectVersion1(dir);
  {  // Never committed: the destructor removes the staged file.
    AtomicFiles files;
    ASSERT_TRUE(files.add((dir / "a.txt").string(), text("a3"), &error));
  }
  expectVersion1(dir);
  {  // A writer that throws.
    AtomicFiles files;
    EXPECT_FALSE(files.add((dir / "a.txt").string(),
                           [](std::ostream&) -> bool { throw std::runtime_error("boom"); },
                           &error));
    EXPECT_NE(error.find("boom"), std::string::npos) << error;
  }
  expectVersion1(dir);
}

TEST(AtomicFiles, AFullDiskLeavesTheOldSet) {
  const fs::path dir = twoFiles();
  // In a child whose files may not grow past 4 KiB: the first file fits, the second does not.
  const int status = test::runInChild(
      [&] {
        AtomicFiles files;
        std::string error;
        if (!files.add((dir / "a.txt").string(), text("a2"), &error)) return 1;
        if (files.add((dir / "b.npy").string(), text(std::string(64 * 1024, 'x')), &error)) {
          return 2;
        }
        if (error != "cannot write '" + (dir / "b.npy").string() + "': File too large") return 3;
        return files.commit(&error) ? 4 : 0;
      },
      4096);
  EXPECT_EQ(status, 0);
  expectVersion1(dir);
}

TEST(AtomicFiles, UnwritableOrMissingDirectory) {
  const fs::path dir = twoFiles();
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  // As nobody when the tests run as root (root writes anywhere).
  const int status = test::runInChild(
      [&] {
        std::string error;
        if (writeFileAtomically((dir / "a.txt").string(), text("a2"), &error)) return 1;
        return error == "cannot write '" + (dir / "a.txt").string() + "': Permission denied" ? 0
                                                                                             : 2;
      },
      0, true);
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add);
  EXPECT_EQ(status, 0);
  expectVersion1(dir);

  std::string error;
  EXPECT_FALSE(writeFileAtomically((dir / "no" / "x.txt").string(), text("x"), &error));
  EXPECT_EQ(error,
            "cannot write '" + (dir / "no" / "x.txt").string() + "': No such file or directory");
}

TEST(AtomicFiles, ByPathWithVerification) {
  const fs::path dir = twoFiles();
  std::string error;
  auto write = [](const std::string& temp) {
    return static_cast<bool>(std::ofstream(temp) << "b2");
  };
  {
    AtomicFiles files;
    // A writer that reports success over a file that is not what it should be.
    EXPECT_FALSE(files.addByPath((dir / "b.npy").string(), write,
                                 [](const std::string&) { return false; }, &error));
    EXPECT_NE(error.find("came out incomplete"), std::string::npos) << error;
  }
  expectVersion1(dir);
  AtomicFiles files;
  ASSERT_TRUE(files.addByPath((dir / "b.npy").string(), write,
                              [](const std::string& temp) { return test::readText(temp) == "b2"; },
                              &error))
      << error;
  ASSERT_TRUE(files.commit(&error)) << error;
  EXPECT_EQ(test::readText(dir / "b.npy"), "b2");
  EXPECT_EQ(listing(dir).size(), 2u);
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
