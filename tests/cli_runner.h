// Scratch folders and the command-line tool for the tests that need them
// (not for the benchmarks, which share test_util.h).
#ifndef GRAVCAL_TESTS_CLI_RUNNER_H_
#define GRAVCAL_TESTS_CLI_RUNNER_H_

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace gravcal {
namespace testing_util {

// A file's whole content ("" when it cannot be read).
inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A scratch folder for one test, under ::testing::TempDir() and named for the
// test and the process (two runs of the suite never share one); removed with
// everything in it when the object goes.
class ScratchDir {
 public:
  ScratchDir() {
    const ::testing::UnitTest* unit = ::testing::UnitTest::GetInstance();
    std::string name = "suite";
    if (const ::testing::TestInfo* info = unit->current_test_info()) {
      name = std::string(info->test_suite_name()) + "_" + info->name();
    } else if (const ::testing::TestSuite* suite = unit->current_test_suite()) {
      name = suite->name();
    }
    for (char& c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    path_ = ::testing::TempDir() + "gravcal_" + name + "_" + std::to_string(getpid());
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
    std::filesystem::create_directories(path_, ec);
    EXPECT_FALSE(ec) << path_ << ": " << ec.message();
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::string& path() const { return path_; }
  // <path>/<name>.
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  // Writes `text` to <path>/<name> and returns that path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string file = *this / name;
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }

 private:
  std::string path_;
};

// How many times `needle` occurs in `text` (overlapping ones counted).
inline size_t Count(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

inline bool FileExists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}

// --- The command-line tool -------------------------------------------------

struct CliResult {
  int exit_code = -1;  // -1 when killed by a signal
  std::string out;
  std::string err;
};

// Starts the CLI with `args` (no shell), stdin from /dev/null (or the
// descriptor stdin_fd), stdout and stderr into the given files; returns the
// child's pid.
inline pid_t SpawnCli(const std::vector<std::string>& args, const std::string& out_path,
                      const std::string& err_path, int stdin_fd = -1) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = stdin_fd >= 0 ? stdin_fd : open("/dev/null", O_RDWR);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(null, 0);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<std::string> copy = args;
    std::string program = GRAVCAL_CLI_PATH;
    std::vector<char*> argv = {program.data()};
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(program.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

// Waits for a child; its exit code, or -1 when a signal ended it.
inline int WaitForExit(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Runs the CLI to the end; stdout and stderr go through files in `scratch`.
inline CliResult RunCli(const std::vector<std::string>& args, const ScratchDir& scratch) {
  const std::string out = scratch / "cli_stdout.txt";
  const std::string err = scratch / "cli_stderr.txt";
  CliResult r;
  r.exit_code = WaitForExit(SpawnCli(args, out, err));
  r.out = Slurp(out);
  r.err = Slurp(err);
  return r;
}

// The same with the arguments in one string, split at white space (no
// argument of the tests contains any).
inline CliResult RunCli(const std::string& args, const ScratchDir& scratch) {
  std::istringstream in(args);
  std::vector<std::string> split;
  for (std::string a; in >> a;) split.push_back(a);
  return RunCli(split, scratch);
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_CLI_RUNNER_H_
