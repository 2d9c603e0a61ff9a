// What the tests that run the `tickfx` binary share: a scratch directory of each test's own, and a
// way to run a program from the source tree with its exit code and output captured.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace tickfx::cli_test {

struct Result {
  int exit = -1;
  std::string out;
  std::string err;
};

inline std::string readAll(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Each test gets dir_ = <temp>/<prefix>_<test name>_<pid> (the pid: ctest runs the cases of one
/// executable as parallel processes), created empty and removed afterwards.
class CliFixture : public ::testing::Test {
 protected:
  explicit CliFixture(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + "_" + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// dir_/name as a string, for command lines.
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `text` to dir_/name; its path.
  std::string writeFile(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return path(name);
  }

  /// Runs `program args` from the source tree (so samples/... resolve), stdin closed; stdout and
  /// stderr go through files in dir_.
  Result runProgram(const std::string& program, const std::string& args) const {
    const std::filesystem::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command = "cd '" TICKFX_SOURCE_DIR "' && '" + program + "' " + args +
                                " </dev/null >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    Result r;
    r.exit = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readAll(out);
    r.err = readAll(err);
    return r;
  }

  /// A program started by startProgram(), running beside the test.
  struct Running {
    pid_t pid = -1;
  };

  /// Starts `program` with `args` (one string each, no shell) from the source tree, stdin
  /// closed, stdout and stderr into files in dir_; finish() waits for it.
  Running startProgram(const std::string& program, const std::vector<std::string>& args) const {
    const std::string out = (dir_ / "stdout.txt").string(), err = (dir_ / "stderr.txt").string();
    std::vector<std::string> argv = {program};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> raw;
    for (std::string& a : argv) raw.push_back(a.data());
    raw.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
      // Only async-signal-safe calls until exec: the test process may have threads.
      if (::chdir(TICKFX_SOURCE_DIR) != 0) ::_exit(127);
      const int in = ::open("/dev/null", O_RDONLY),
                o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644),
                e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (in < 0 || o < 0 || e < 0 || ::dup2(in, 0) < 0 || ::dup2(o, 1) < 0 || ::dup2(e, 2) < 0)
        ::_exit(127);
      ::execv(raw[0], raw.data());
      ::_exit(127);
    }
    return Running{pid};
  }

  /// Waits for `running`; exit is 128 + N when signal N ended it.
  Result finish(Running running) const {
    int status = 0;
    while (::waitpid(running.pid, &status, 0) < 0 && errno == EINTR) {
    }
    Result r;
    r.exit = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = readAll(dir_ / "stdout.txt");
    r.err = readAll(dir_ / "stderr.txt");
    return r;
  }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace tickfx::cli_test
