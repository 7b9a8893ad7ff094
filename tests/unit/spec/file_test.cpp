// read_regular_file(): the one reader of files a person names (systems, scenarios, sample files,
// scripts, histories). Regular files only, a size limit, and never a hang.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "safecass/spec/file.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/scenario.hpp"

namespace safecass::spec {
namespace {

namespace fs = std::filesystem;

class ReadRegularFile : public ::testing::Test {
protected:
  ReadRegularFile() {
    std::string pattern = ::testing::TempDir() + "/safecass-file-test-XXXXXX";
    dir_ = ::mkdtemp(pattern.data()) != nullptr ? pattern : std::string();
  }
  ~ReadRegularFile() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string at(const std::string& name) const { return dir_ + "/" + name; }
  /// A sparse file of `bytes` bytes (nothing is written to the disk).
  std::string sparse(const std::string& name, off_t bytes) const {
    const std::string path = at(name);
    std::ofstream(path).close();
    EXPECT_EQ(::truncate(path.c_str(), bytes), 0);
    return path;
  }
  std::string fifo(const std::string& name) const {
    const std::string path = at(name);
    EXPECT_EQ(::mkfifo(path.c_str(), 0600), 0);
    return path;
  }
  std::string dir_;
};

std::string error_of(const Expected<std::string>& r) { return r ? std::string("(read)") : r.error().message; }

TEST_F(ReadRegularFile, ReadsARegularFileWhole) {
  std::ofstream(at("a.txt"), std::ios::binary) << "1 2 3\n4 5 6\n";
  auto r = read_regular_file(at("a.txt"));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(*r, "1 2 3\n4 5 6\n");
  EXPECT_EQ(kMaxInputFileBytes, std::size_t{64} << 20);
}

TEST_F(ReadRegularFile, RefusesDevicesFifosDirectoriesAndMissingFilesSayingWhatAndWhere) {
  const auto started = std::chrono::steady_clock::now();
  EXPECT_EQ(error_of(read_regular_file("/dev/zero")),
            "cannot read file '/dev/zero': not a regular file (a character device)");
  const std::string f = fifo("samples.fifo");
  EXPECT_EQ(error_of(read_regular_file(f)), "cannot read file '" + f + "': not a regular file (a FIFO)");
  EXPECT_EQ(error_of(read_regular_file(dir_)), "cannot read file '" + dir_ + "': not a regular file (a directory)");
  EXPECT_EQ(error_of(read_regular_file(at("none"))), "cannot read file '" + at("none") + "': no such file");
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(5)) << "nothing waited or read forever";
  auto r = read_regular_file("/dev/zero");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Io);
}

TEST_F(ReadRegularFile, RefusesAFileLargerThanTheLimitFromItsSize) {
  const std::string big = sparse("big.txt", static_cast<off_t>(kMaxInputFileBytes) + 1);
  EXPECT_EQ(error_of(read_regular_file(big)), "cannot read file '" + big + "': larger than 64 MiB (" +
                                                  std::to_string(kMaxInputFileBytes + 1) + " bytes)");
  const std::string exact = sparse("exact.txt", 1000);
  EXPECT_TRUE(read_regular_file(exact, 1000));
  EXPECT_EQ(error_of(read_regular_file(exact, 999)),
            "cannot read file '" + exact + "': larger than 999 bytes (1000 bytes)");
}

TEST_F(ReadRegularFile, ScenarioLoaderRefusesDevicesFifosDirectoriesAndHugeFilesWithTheirPosition) {
  const std::string f = fifo("scenario.fifo");
  const std::string big = sparse("scenario.json", static_cast<off_t>(kMaxInputFileBytes) + 1);
  for (const auto& [path, why] :
       {std::pair<std::string, std::string>{"/dev/zero", "not a regular file (a character device)"},
        {f, "not a regular file (a FIFO)"},
        {dir_, "not a regular file (a directory)"},
        {big, "larger than 64 MiB"}}) {
    const ScenarioLoad load = load_scenario(path);
    EXPECT_FALSE(load.scenario) << path;
    ASSERT_EQ(load.diagnostics.size(), 1u) << path;
    EXPECT_THAT(format(load.diagnostics[0]),
                ::testing::StartsWith(path + ":1:1: error: cannot read file '" + path + "': " + why));
  }
}

TEST_F(ReadRegularFile, SystemLoaderRefusesAFifoOrADeviceWithoutHanging) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  const std::string f = fifo("system.json");
  for (const std::string& path : {f, std::string("/dev/zero")}) {
    const LoadResult r = load_system(path, registry);
    EXPECT_FALSE(r.ok()) << path;
    ASSERT_FALSE(r.diagnostics.empty()) << path;
    EXPECT_THAT(r.diagnostics[0].message, ::testing::HasSubstr("not a regular file")) << path;
  }
  const std::string big = sparse("huge.json", (std::size_t{16} << 20) + 1);
  const LoadResult r = load_system(big, registry);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_THAT(r.diagnostics[0].message, ::testing::HasSubstr("larger than 16 MiB"))
      << "a system file keeps its 16 MiB limit";
}

}  // namespace
}  // namespace safecass::spec
