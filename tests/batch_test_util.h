// Helpers of the batch tests: results compared without their times, the
// finished files of an output folder.
#ifndef GRAVCAL_TESTS_BATCH_TEST_UTIL_H_
#define GRAVCAL_TESTS_BATCH_TEST_UTIL_H_

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gravcal/workflows/fleet_summary.h"

namespace gravcal {
namespace testing_util {

// The calibration JSON without the solver's wall-clock time, the only field
// that differs between two runs of the same calibration.
inline nlohmann::json WithoutTime(const std::string& text) {
  nlohmann::json j = nlohmann::json::parse(text);
  j["solver"].erase("time_s");
  return j;
}

// summary.csv without the time columns.
inline std::string WithoutTimes(const std::string& csv) {
  std::vector<SummaryRow> rows;
  std::string error;
  EXPECT_TRUE(ParseSummaryCsv(csv, "summary.csv", &rows, &error)) << error;
  for (SummaryRow& row : rows) {
    for (const char* c : {"read_s", "detect_s", "solve_s", "total_s"}) row.values.erase(c);
  }
  return SummaryToCsv(rows);
}

struct FileId {
  ino_t inode = 0;
  int64_t mtime_ns = 0;
  bool operator==(const FileId& o) const { return inode == o.inode && mtime_ns == o.mtime_ns; }
};

// Finished files (*.json, no temporaries) in a folder, with inode and mtime.
inline std::map<std::string, FileId> JsonFiles(const std::string& folder) {
  std::map<std::string, FileId> files;
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) return files;
  while (const dirent* e = readdir(dir)) {
    const std::string name = e->d_name;
    // Hidden names: gravcal's temporaries (io/files.h).
    if (name[0] == '.' || name.size() < 5 || name.compare(name.size() - 5, 5, ".json") != 0) {
      continue;
    }
    struct stat st;
    if (stat((folder + "/" + name).c_str(), &st) != 0) continue;
    files[name] = {st.st_ino,
                   static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
  }
  closedir(dir);
  return files;
}

// Names in a folder that contain `part`.
inline size_t CountNames(const std::string& folder, const std::string& part) {
  size_t n = 0;
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr) return 0;
  while (const dirent* e = readdir(dir))
    n += std::string(e->d_name).find(part) != std::string::npos;
  closedir(dir);
  return n;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_BATCH_TEST_UTIL_H_
