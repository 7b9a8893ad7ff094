// The write token and its files (middleware/token.hpp): created private and locked, never written
// over a file that is not ours, never shared by two live processes, at a private default place.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "safecass/middleware/token.hpp"

namespace safecass::middleware {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh directory for one test, removed afterwards.
class TokenFileTest : public ::testing::Test {
protected:
  TokenFileTest() {
    std::string pattern = ::testing::TempDir() + "/safecass-token-test-XXXXXX";
    dir_ = ::mkdtemp(pattern.data()) != nullptr ? pattern : std::string();
  }
  ~TokenFileTest() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string at(const std::string& name) const { return dir_ + "/" + name; }
  static mode_t mode_of(const std::string& path) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 ? st.st_mode & 07777 : 0;
  }
  /// Writes `text` to a new file with `mode`.
  static void write_file(const std::string& path, const std::string& text, mode_t mode) {
    std::ofstream(path, std::ios::binary) << text;
    ::chmod(path.c_str(), mode);
  }

  std::string dir_;
};

/// Restores an environment variable when it goes out of scope.
class EnvGuard {
public:
  explicit EnvGuard(const char* name) : name_(name) {
    if (const char* v = std::getenv(name)) value_ = v;
  }
  ~EnvGuard() {
    if (value_)
      ::setenv(name_, value_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

private:
  const char* name_;
  std::optional<std::string> value_;
};

TEST(Token, IsSixtyFourRandomHexDigits) {
  const auto a = make_token();
  const auto b = make_token();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->size(), 64u);
  EXPECT_EQ(a->find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_NE(*a, *b);
}

TEST(Token, OnlyTheExactTokenMatches) {
  const std::string t(64, 'a');
  EXPECT_TRUE(token_matches(t, t));
  EXPECT_FALSE(token_matches(t, std::string(64, 'b')));
  EXPECT_FALSE(token_matches(t, t.substr(1)));
  EXPECT_FALSE(token_matches("", "")) << "no token configured: nothing matches";
}

TEST_F(TokenFileTest, ANewTokenFileIsPrivateHeldWhileItLivesAndRemovedAfterwards) {
  const std::string path = at("robot.token");
  auto file = TokenFile::create(path);
  ASSERT_TRUE(file) << file.error().message;
  EXPECT_EQ((*file)->path(), path);
  EXPECT_EQ(mode_of(path), 0600u);
  EXPECT_EQ(read_text(path), (*file)->secret() + "\n");
  auto read = read_token_file(path);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(*read, (*file)->secret());
  // Held: another open file description cannot take the lock.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  EXPECT_NE(::flock(fd, LOCK_EX | LOCK_NB), 0);
  (*file)->remove();
  EXPECT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0) << "released when removed";
  ::close(fd);
  EXPECT_FALSE(fs::exists(path));
}

TEST_F(TokenFileTest, AnExistingFileThatIsNotATokenFileOfOursIsNeitherOverwrittenNorRemoved) {
  const std::string token_text = std::string(64, 'c') + "\n";
  struct Case {
    std::string name;
    std::string text;
    mode_t mode;
    std::string why;
  };
  const Case cases[] = {
      {"important.json", "{\"budget\": 12}\n", 0644, "mode 0644, not 0600"},
      {"private.json", "{\"budget\": 12}\n", 0600, "not a token (15 bytes)"},
      {"readable.token", token_text, 0644, "mode 0644, not 0600"},
      {"empty.token", "", 0600, "not a token (0 bytes)"},
      {"almost.token", std::string(64, 'G') + "\n", 0600, "not a token"},
  };
  for (const Case& c : cases) {
    const std::string path = at(c.name);
    write_file(path, c.text, c.mode);
    auto file = TokenFile::create(path);
    ASSERT_FALSE(file) << c.name;
    EXPECT_EQ(file.error().code, ErrorCode::Io);
    EXPECT_EQ(file.error().message, "token file " + path + ": exists and is not a SAFECASS token file of yours (" +
                                        c.why + "): refusing to overwrite it; remove it or choose another path");
    EXPECT_EQ(read_text(path), c.text) << c.name << " is unchanged";
    EXPECT_EQ(mode_of(path), c.mode) << c.name;
  }
  ASSERT_EQ(::mkdir(at("dir").c_str(), 0700), 0);
  auto d = TokenFile::create(at("dir"));
  ASSERT_FALSE(d);
  EXPECT_THAT(d.error().message, HasSubstr("(a directory)"));
  EXPECT_TRUE(fs::is_directory(at("dir")));
}

TEST_F(TokenFileTest, ASymbolicLinkIsNeverWrittenThrough) {
  const std::string target = at("important.json");
  write_file(target, "{}\n", 0600);
  ASSERT_EQ(::symlink(target.c_str(), at("link.token").c_str()), 0);
  auto file = TokenFile::create(at("link.token"));
  ASSERT_FALSE(file);
  EXPECT_THAT(file.error().message, HasSubstr("is a symbolic link"));
  EXPECT_EQ(read_text(target), "{}\n");
  // A dangling link, too: O_NOFOLLOW, so nothing is created where it points.
  ASSERT_EQ(::symlink(at("nowhere").c_str(), at("dangling.token").c_str()), 0);
  EXPECT_FALSE(TokenFile::create(at("dangling.token")));
  EXPECT_FALSE(fs::exists(at("nowhere")));
}

TEST_F(TokenFileTest, AFifoAtThePathIsRefusedWithoutWaitingForAWriter) {
  ASSERT_EQ(::mkfifo(at("fifo.token").c_str(), 0600), 0);
  auto file = TokenFile::create(at("fifo.token"));
  ASSERT_FALSE(file);
  EXPECT_THAT(file.error().message, HasSubstr("(a FIFO)"));
  auto read = read_token_file(at("fifo.token"));
  ASSERT_FALSE(read);
  EXPECT_THAT(read.error().message, HasSubstr("a FIFO, not a regular file"));
}

TEST_F(TokenFileTest, TwoProcessesGivenOnePathDoNotOverwriteEachOther) {
  const std::string path = at("shared.token");
  // The first holder is another process, alive until told to stop.
  int ready[2];
  int stop[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(stop), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto mine = TokenFile::create(path);
    const char ok = mine ? '1' : '0';
    (void)!::write(ready[1], &ok, 1);
    char c;
    (void)!::read(stop[0], &c, 1);
    ::_exit(0);  // the destructor does not run: as if killed
  }
  char ok = 0;
  ASSERT_EQ(::read(ready[0], &ok, 1), 1);
  ASSERT_EQ(ok, '1');
  const std::string first = read_text(path);
  auto second = TokenFile::create(path);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().message,
            "token file " + path +
                ": is the token file of a running process (it holds the file's lock): two processes "
                "cannot share a token file; choose another path");
  EXPECT_EQ(read_text(path), first) << "the running process's token is intact";
  (void)!::write(stop[1], "x", 1);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  // The holder is gone and left its file behind: it is replaced by a new token.
  auto third = TokenFile::create(path);
  ASSERT_TRUE(third) << third.error().message;
  EXPECT_NE(read_text(path), first);
  EXPECT_EQ(read_text(path), (*third)->secret() + "\n");
  // In this process as well: a second TokenFile at the path of a live one is refused.
  auto fourth = TokenFile::create(path);
  ASSERT_FALSE(fourth) << "held by this process now";
  EXPECT_THAT(fourth.error().message, HasSubstr("is the token file of a running process"));
  for (int fd : {ready[0], ready[1], stop[0], stop[1]}) ::close(fd);
}

TEST_F(TokenFileTest, ATokenFileLeftByAKilledProcessIsReplaced) {
  const std::string path = at("killed.token");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto mine = TokenFile::create(path);
    ::raise(SIGKILL);
    ::_exit(1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::string old = read_text(path);
  ASSERT_EQ(old.size(), 65u);
  auto file = TokenFile::create(path);
  ASSERT_TRUE(file) << file.error().message;
  EXPECT_NE((*file)->secret() + "\n", old);
}

TEST_F(TokenFileTest, RemoveLeavesAFileThatReplacedOursAlone) {
  const std::string path = at("replaced.token");
  auto file = TokenFile::create(path);
  ASSERT_TRUE(file);
  ASSERT_EQ(::unlink(path.c_str()), 0);
  write_file(path, "someone else's\n", 0600);
  (*file)->remove();
  EXPECT_EQ(read_text(path), "someone else's\n");
}

TEST_F(TokenFileTest, TheDefaultPlaceIsThePrivateSafecassDirectoryOfXdgRuntimeDir) {
  EnvGuard xdg("XDG_RUNTIME_DIR");
  ::setenv("XDG_RUNTIME_DIR", dir_.c_str(), 1);
  auto file = TokenFile::create_default("robot");
  ASSERT_TRUE(file) << file.error().message;
  EXPECT_EQ((*file)->path(), dir_ + "/safecass/robot-" + std::to_string(::getpid()) + ".token");
  EXPECT_EQ(mode_of(dir_ + "/safecass"), 0700u);
  EXPECT_EQ(mode_of((*file)->path()), 0600u);
  const std::string path = (*file)->path();
  (*file)->remove();
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::exists(dir_ + "/safecass")) << "the shared runtime directory stays";
  // A name cannot leave the directory.
  auto odd = TokenFile::create_default("../../etc/x");
  ASSERT_TRUE(odd) << odd.error().message;
  EXPECT_EQ(fs::path((*odd)->path()).parent_path(), fs::path(dir_ + "/safecass"));
}

TEST_F(TokenFileTest, ADefaultDirectoryOthersCanEnterIsRefused) {
  EnvGuard xdg("XDG_RUNTIME_DIR");
  ::setenv("XDG_RUNTIME_DIR", dir_.c_str(), 1);
  ASSERT_EQ(::mkdir((dir_ + "/safecass").c_str(), 0700), 0);
  ::chmod((dir_ + "/safecass").c_str(), 0755);
  auto file = TokenFile::create_default("robot");
  ASSERT_FALSE(file);
  EXPECT_THAT(file.error().message, HasSubstr("has mode 0755: others may enter it (it must be 0700)"));
  ::rmdir((dir_ + "/safecass").c_str());
  ASSERT_EQ(::symlink(dir_.c_str(), (dir_ + "/safecass").c_str()), 0);
  auto linked = TokenFile::create_default("robot");
  ASSERT_FALSE(linked);
  EXPECT_THAT(linked.error().message, HasSubstr("is a symbolic link, not a directory"));
  ::unlink((dir_ + "/safecass").c_str());
  if (::geteuid() == 0) {  // as root, a directory of another user can be made
    ASSERT_EQ(::mkdir((dir_ + "/safecass").c_str(), 0700), 0);
    ASSERT_EQ(::chown((dir_ + "/safecass").c_str(), 1, 1), 0);
    auto theirs = TokenFile::create_default("robot");
    ASSERT_FALSE(theirs);
    EXPECT_THAT(theirs.error().message, HasSubstr("is owned by another user (uid 1)"));
  }
}

TEST_F(TokenFileTest, WithoutXdgRuntimeDirTheDefaultIsANewPrivateDirectoryRemovedWithTheFile) {
  EnvGuard xdg("XDG_RUNTIME_DIR");
  EnvGuard tmp("TMPDIR");
  ::unsetenv("XDG_RUNTIME_DIR");
  ::setenv("TMPDIR", dir_.c_str(), 1);
  auto a = TokenFile::create_default("robot");
  auto b = TokenFile::create_default("robot");
  ASSERT_TRUE(a && b);
  const fs::path parent = fs::path((*a)->path()).parent_path();
  EXPECT_EQ(parent.parent_path(), fs::path(dir_));
  EXPECT_THAT(parent.filename().string(), HasSubstr("safecass-"));
  EXPECT_NE(parent, fs::path((*b)->path()).parent_path()) << "each process (each file) gets its own directory";
  EXPECT_EQ(mode_of(parent.string()), 0700u);
  EXPECT_EQ(fs::path((*a)->path()).filename().string(), "robot-" + std::to_string(::getpid()) + ".token");
  (*a)->remove();
  EXPECT_FALSE(fs::exists(parent));
}

TEST_F(TokenFileTest, ReadingRefusesWhatIsNotATokenFile) {
  write_file(at("hello"), "hello\n", 0600);
  auto r = read_token_file(at("hello"));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Parse);
  EXPECT_EQ(read_token_file(at("missing")).error().code, ErrorCode::Io);
  auto dev = read_token_file("/dev/zero");
  ASSERT_FALSE(dev);
  EXPECT_THAT(dev.error().message, HasSubstr("/dev/zero: a device, not a regular file"));
  EXPECT_FALSE(TokenFile::create("/nonexistent-dir/x.token"));
}

}  // namespace
}  // namespace safecass::middleware
