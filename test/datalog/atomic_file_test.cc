// write_file_atomically (datalog/atomic_file.h): the file is replaced whole or
// not at all, and no temporary file is ever left behind.
#include "datalog/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace hadynet::datalog {
namespace {

namespace fs = std::filesystem;

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() / ("hadynet_atomic_file_" + std::to_string(::getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(folder_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  static std::string bytes_of(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }

  fs::path folder_;
};

TEST_F(AtomicFile, CreatesAndReplacesWholeFiles) {
  const fs::path path = folder_ / "model.bin";
  write_file_atomically(path, std::string(100000, 'a'));
  write_file_atomically(path, std::string("\0short", 6));  // a shorter file leaves no tail; NUL bytes kept
  EXPECT_EQ(bytes_of(path), std::string("\0short", 6));
  EXPECT_EQ(entries(), std::vector<std::string>{"model.bin"});
}

TEST_F(AtomicFile, EmptyContentGivesAnEmptyFile) {
  const fs::path path = folder_ / "empty";
  write_file_atomically(path, "");
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ(fs::file_size(path), 0u);
}

// The temporary file cannot be created: the error names the step and the
// reason, and nothing appears.
TEST_F(AtomicFile, MissingFolderNamesTheStep) {
  try {
    write_file_atomically(folder_ / "no" / "such" / "x.csv", "data");
    FAIL() << "no AtomicWriteError";
  } catch (const AtomicWriteError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("create temporary file"), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  EXPECT_TRUE(entries().empty());
}

// The rename fails (the target is a non-empty folder): what was there stays,
// and the temporary file is removed. Works as root too (no permission bits).
TEST_F(AtomicFile, FailedRenameLeavesTargetAndNoTemporary) {
  const fs::path target = folder_ / "taken";
  fs::create_directories(target / "inside");
  try {
    write_file_atomically(target, "data");
    FAIL() << "no AtomicWriteError";
  } catch (const AtomicWriteError& e) {
    EXPECT_NE(std::string(e.what()).find("rename"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(target / "inside"));
  EXPECT_EQ(entries(), std::vector<std::string>{"taken"});
}

TEST_F(AtomicFile, PathWithoutFileNameIsRejected) {
  EXPECT_THROW(write_file_atomically(folder_ / "", "data"), AtomicWriteError);
}

}  // namespace
}  // namespace hadynet::datalog
