// The bag and MCAP readers live in libgravcal_formats.so, loaded only when
// such a file is read (io/formats/reader_module.h, issue 39 part 5): a CSV
// loads none of their libraries, a bag loads the module, and a missing
// module is one line naming the file and what is missing.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <string>

#include "cli_runner.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::RunCli;
using testing_util::ScratchDir;

std::string SmallCsv() {
  std::string text = "t,ax,ay,az\n";
  for (int i = 0; i < 50; ++i) {
    text +=
        std::to_string(0.01 * i) + ",0.01,-0.02," + std::to_string(9.81 + 1e-3 * (i % 3)) + "\n";
  }
  return text;
}

// A file that starts as an SQLite database (a rosbag2 .db3 to the format
// detection) and is not one.
std::string FakeDb3() { return std::string("SQLite format 3\0", 16) + std::string(200, '\x01'); }

// The CLI run with LD_DEBUG=files (the loader lists every library it opens
// on standard error) and, when given, GRAVCAL_MODULE_DIR.
CliResult RunTraced(const std::string& args, const ScratchDir& scratch,
                    const char* module_dir = nullptr) {
  setenv("LD_DEBUG", "files", 1);
  if (module_dir != nullptr) setenv("GRAVCAL_MODULE_DIR", module_dir, 1);
  CliResult r = RunCli(args, scratch);
  unsetenv("LD_DEBUG");
  unsetenv("GRAVCAL_MODULE_DIR");
  return r;
}

TEST(ReaderModule, CsvLoadsNoReaderLibrary) {
  ScratchDir scratch;
  const std::string csv = scratch.Write("log.csv", SmallCsv());
  const CliResult r = RunTraced("inspect --input " + csv, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("calling init"), std::string::npos) << "LD_DEBUG=files said nothing";
  for (const char* lib : {"libgravcal_formats", "libsqlite3", "libzstd", "liblz4", "librosbag"}) {
    EXPECT_EQ(r.err.find(lib), std::string::npos) << lib << " was loaded for a CSV";
  }
}

TEST(ReaderModule, Db3LoadsTheModule) {
  ScratchDir scratch;
  const std::string db3 = scratch.Write("bag.db3", FakeDb3());
  const CliResult r = RunTraced("inspect --input " + db3, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("libgravcal_formats.so"), std::string::npos);
  EXPECT_NE(r.err.find("libsqlite3"), std::string::npos);
  EXPECT_EQ(r.err.find("reader module"), std::string::npos)
      << r.err.substr(r.err.rfind("gravcal:"));
}

TEST(ReaderModule, MissingModuleIsOneLine) {
  ScratchDir scratch;
  const std::string db3 = scratch.Write("bag.db3", FakeDb3());
  setenv("GRAVCAL_MODULE_DIR", (scratch / "nothing_here").c_str(), 1);
  const CliResult r = RunCli("inspect --input " + db3, scratch);
  unsetenv("GRAVCAL_MODULE_DIR");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(testing_util::Count(r.err, "\n"), 1u) << r.err;
  EXPECT_NE(r.err.find(db3 +
                       ": cannot read a rosbag2 SQLite bag: its reader module "
                       "libgravcal_formats.so was not found (looked in " +
                       scratch / "nothing_here"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(r.out.empty());
}

}  // namespace
}  // namespace gravcal
