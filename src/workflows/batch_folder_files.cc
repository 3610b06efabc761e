// The file checks of a batch written to a folder (batch_folder_files.h),
// and the merge of its shards' summaries (MergeBatchSummaries).
#include "workflows/batch_folder_files.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <system_error>
#include <utility>

#include "gravcal/io/files.h"
#include "gravcal/workflows/batch_folder.h"
#include "util/error.h"

namespace gravcal {
namespace internal {

namespace {

// True when `a` and `b` name the same existing file.
bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  return stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

}  // namespace

bool MakeFolders(const std::string& path, std::string* error) {
  for (size_t pos = 1; pos <= path.size(); ++pos) {
    if (pos != path.size() && path[pos] != '/') continue;
    const std::string prefix = path.substr(0, pos);
    if (mkdir(prefix.c_str(), 0755) != 0 && errno != EEXIST) {
      return SetError(
          error, prefix + ": cannot create the folder: " + std::generic_category().message(errno));
    }
  }
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    return SetError(error, path + ": is not a folder");
  }
  return true;
}

bool FileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

bool OwnFilesInInput(const std::string& input_dir, const std::string& output_dir,
                     const std::string& report, std::vector<std::string>* own, std::string* error) {
  std::vector<std::pair<std::string, std::function<bool(const std::string&)>>> outputs = {
      {output_dir + "/summary.csv",
       [&](const std::string& text) {
         std::vector<SummaryRow> rows;
         std::string why;
         return ParseSummaryCsv(text, "", &rows, &why);
       }},
      {output_dir + "/summary.json",
       [&](const std::string& text) {
         FleetInfo info;
         std::string why;
         return ParseFleetInfo(text, "", &info, &why);
       }},
      // Written by AcceptBatchFolder (workflows/acceptance.h) with --limits.
      {output_dir + "/limits.csv",
       [](const std::string& text) { return text.compare(0, 20, "unit,verdict,failed\n") == 0; }},
      {report, [](const std::string& text) {
         return text.compare(0, 15, "<!DOCTYPE html>") == 0 || text.compare(0, 5, "<html") == 0;
       }}};
  DIR* dir = opendir(input_dir.c_str());
  if (dir == nullptr) return true;  // UnitsFromDirectory says why.
  std::vector<std::string> names;
  while (const dirent* entry = readdir(dir)) names.push_back(entry->d_name);
  closedir(dir);
  for (const auto& [path, ours] : outputs) {
    if (path.empty()) continue;
    for (const std::string& name : names) {
      const std::string input = input_dir + "/" + name;
      if (name[0] == '.' || !SameFile(path, input)) continue;
      std::string text;
      if (!ReadFileBytes(input, &text, error)) return false;
      if (!ours(text)) {
        return SetError(error, path + ": the batch would overwrite " + input +
                                   ", a file of --input-dir that it did not write; choose "
                                   "another --output-dir or --report");
      }
      own->push_back(name);
    }
  }
  return true;
}

bool CheckUnitsAgainstOutputs(const std::vector<BatchUnit>& units, const std::string& output_dir,
                              const std::string& report, std::string* error) {
  std::map<std::pair<dev_t, ino_t>, std::pair<const BatchUnit*, std::string>> inputs;
  for (const BatchUnit& u : units) {
    std::vector<std::string> paths = {u.path, u.attitudes_path};
    for (const auto& [key, value] : u.overrides) {
      if (key == "gyro_path") paths.push_back(value);
    }
    for (const std::string& path : paths) {
      struct stat st;
      if (!path.empty() && stat(path.c_str(), &st) == 0) {
        inputs.emplace(std::make_pair(st.st_dev, st.st_ino), std::make_pair(&u, path));
      }
    }
  }
  if (inputs.empty()) return true;
  const std::string& out = output_dir;
  std::vector<std::string> outputs = {out + "/summary.csv", out + "/summary.json", report};
  for (const BatchUnit& u : units) {
    outputs.push_back(out + "/" + u.id + ".json");
    outputs.push_back(out + "/" + kBatchStateFolder + "/" + u.id + ".json");
  }
  for (const std::string& path : outputs) {
    struct stat st;
    if (path.empty() || stat(path.c_str(), &st) != 0) continue;
    const auto it = inputs.find(std::make_pair(st.st_dev, st.st_ino));
    if (it != inputs.end()) {
      return SetError(error, path + ": the batch would overwrite " + it->second.second +
                                 ", an input of unit " + it->second.first->id +
                                 ": gravcal never overwrites its input");
    }
  }
  return true;
}

bool WriteSummaryFiles(const std::string& folder, const std::vector<SummaryRow>& rows,
                       const FleetInfo& info, const FleetOptions& fleet,
                       FleetStatistics* statistics, std::string* error) {
  if (!ComputeFleetStatistics(rows, info, fleet, statistics, error)) return false;
  return WriteFileAtomically(folder + "/summary.csv", SummaryToCsv(rows), error) &&
         WriteFileAtomically(folder + "/summary.json", FleetStatisticsToJson(*statistics), error);
}

}  // namespace internal

namespace {

// The acceptance sections of the shards (AcceptBatchFolder: summary.json's
// "acceptance" and limits.csv), merged: the counts summed, the failed
// units and the limits.csv rows in fleet order.
struct MergedAcceptance {
  // Shards with a section, and the first folder with and without one.
  size_t shards = 0;
  std::string with, without;
  std::string limits;
  size_t checked = 0, pass = 0;
  // (unit index in the fleet, entry) of each failed unit and limits row.
  std::vector<std::pair<size_t, nlohmann::ordered_json>> failed;
  std::vector<std::pair<size_t, std::string>> csv_rows;
};

// Takes shard `folder`'s section (its summary.json text parsed) into *m;
// `index_of` maps unit names to fleet indices. False when the section is
// malformed or its limits differ from the other shards'.
bool TakeAcceptance(const std::string& folder, const std::string& summary_text,
                    const std::map<std::string, size_t>& index_of, MergedAcceptance* m,
                    std::string* error) {
  using internal::SetError;
  const std::string json_path = folder + "/summary.json";
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(summary_text, nullptr, false);
  if (!j.is_object() || !j.contains("acceptance")) {
    if (m->without.empty()) m->without = folder;
    return true;
  }
  if (m->with.empty()) m->with = folder;
  const nlohmann::ordered_json& a = j["acceptance"];
  if (!a.is_object() || !a.value("limits", nlohmann::ordered_json()).is_string() ||
      !a.value("checked", nlohmann::ordered_json()).is_number_unsigned() ||
      !a.value("pass", nlohmann::ordered_json()).is_number_unsigned() ||
      !a.value("failed", nlohmann::ordered_json()).is_array()) {
    return SetError(error, json_path +
                               ": its 'acceptance' section lacks limits, checked, pass or "
                               "failed");
  }
  const std::string limits = a["limits"].get<std::string>();
  if (m->shards > 0 && limits != m->limits) {
    return SetError(error, json_path + ": checked against limits " + limits + ", " + m->with +
                               " against " + m->limits);
  }
  ++m->shards;
  m->limits = limits;
  m->checked += a["checked"].get<size_t>();
  m->pass += a["pass"].get<size_t>();
  for (const nlohmann::ordered_json& f : a["failed"]) {
    const std::string unit = f.is_object() ? f.value("unit", "") : "";
    const auto at = index_of.find(unit);
    if (at == index_of.end()) {
      return SetError(error, json_path + ": failed unit '" + unit + "' is not in its summary.csv");
    }
    m->failed.emplace_back(at->second, f);
  }
  // limits.csv: "unit,verdict,failed" then one row per checked unit.
  std::string csv;
  const std::string csv_path = folder + "/limits.csv";
  if (!ReadFileBytes(csv_path, &csv, error)) return false;
  size_t begin = csv.find('\n');
  if (csv.compare(0, 20, "unit,verdict,failed\n") != 0) {
    return SetError(error, csv_path + ":1: not a limits.csv (unit,verdict,failed)");
  }
  for (begin = begin + 1; begin < csv.size();) {
    size_t end = csv.find('\n', begin);
    if (end == std::string::npos) end = csv.size();
    const std::string line = csv.substr(begin, end - begin);
    const auto at = index_of.find(line.substr(0, line.find(',')));
    if (at == index_of.end()) {
      return SetError(error, csv_path + ": unit '" + line.substr(0, line.find(',')) +
                                 "' is not in its summary.csv");
    }
    m->csv_rows.emplace_back(at->second, line);
    begin = end + 1;
  }
  return true;
}

// Writes the merged section into output_dir's summary.json and limits.csv.
bool WriteMergedAcceptance(const std::string& output_dir, MergedAcceptance m, std::string* error) {
  auto by_index = [](const auto& a, const auto& b) { return a.first < b.first; };
  std::stable_sort(m.failed.begin(), m.failed.end(), by_index);
  std::stable_sort(m.csv_rows.begin(), m.csv_rows.end(), by_index);
  const std::string summary_path = output_dir + "/summary.json";
  std::string text;
  if (!ReadFileBytes(summary_path, &text, error)) return false;
  nlohmann::ordered_json summary = nlohmann::ordered_json::parse(text, nullptr, false);
  nlohmann::ordered_json failed = nlohmann::ordered_json::array();
  for (const auto& f : m.failed) failed.push_back(f.second);
  summary["acceptance"] = {{"limits", m.limits},
                           {"checked", m.checked},
                           {"pass", m.pass},
                           {"fail", m.failed.size()},
                           {"failed", failed}};
  std::string csv = "unit,verdict,failed\n";
  for (const auto& row : m.csv_rows) csv += row.second + "\n";
  return WriteFilesAtomically(
      {{summary_path, summary.dump(2) + "\n"}, {output_dir + "/limits.csv", csv}}, error);
}

}  // namespace

bool MergeBatchSummaries(const std::vector<std::string>& shard_folders,
                         const std::string& output_dir, const FleetOptions& fleet,
                         FleetStatistics* statistics, std::string* error) {
  using internal::SetError;
  if (!fleet.IsValid(error)) return false;
  FleetInfo merged;
  std::vector<std::string> shard_folder;
  std::vector<SummaryRow> rows;
  MergedAcceptance acceptance;
  for (size_t d = 0; d < shard_folders.size(); ++d) {
    const std::string& folder = shard_folders[d];
    const std::string json_path = folder + "/summary.json";
    const std::string csv_path = folder + "/summary.csv";
    std::string text;
    FleetInfo info;
    if (!ReadFileBytes(json_path, &text, error) || !ParseFleetInfo(text, json_path, &info, error)) {
      return false;
    }
    const std::string text_json = text;
    std::vector<SummaryRow> shard_rows;
    if (!ReadFileBytes(csv_path, &text, error) ||
        !ParseSummaryCsv(text, csv_path, &shard_rows, error)) {
      return false;
    }
    if (d == 0) {
      merged = info;
      shard_folder.assign(info.shard_count, "");
    } else if (info.fleet != merged.fleet || info.units_in_fleet != merged.units_in_fleet ||
               info.shard_count != merged.shard_count) {
      return SetError(error, json_path + ": not a shard of the same fleet as " + shard_folders[0] +
                                 " (the unit list or the shard count differs)");
    } else if (info.config != merged.config) {
      return SetError(error, json_path +
                                 ": computed with another config (or gravcal version) than " +
                                 shard_folders[0]);
    }
    std::string& seen = shard_folder[info.shard_index - 1];
    if (!seen.empty()) {
      return SetError(error, json_path + ": shard " + std::to_string(info.shard_index) + "/" +
                                 std::to_string(info.shard_count) + " is also in " + seen);
    }
    seen = folder;
    std::map<std::string, size_t> index_of;
    for (const SummaryRow& row : shard_rows) index_of[row.unit] = row.index;
    if (!TakeAcceptance(folder, text_json, index_of, &acceptance, error)) return false;
    rows.insert(rows.end(), shard_rows.begin(), shard_rows.end());
  }
  if (acceptance.shards > 0 && !acceptance.without.empty()) {
    return SetError(error, acceptance.with + " was checked against limits (" + acceptance.limits +
                               ") and " + acceptance.without +
                               " was not: run every shard with the same --limits");
  }
  std::string missing;
  for (size_t k = 0; k < shard_folder.size(); ++k) {
    if (shard_folder[k].empty()) missing += (missing.empty() ? "" : ", ") + std::to_string(k + 1);
  }
  if (!missing.empty()) {
    return SetError(error, "shards " + missing + " of " + std::to_string(merged.shard_count) +
                               " are missing: merge-summaries needs every shard of the fleet");
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const SummaryRow& a, const SummaryRow& b) { return a.index < b.index; });
  for (size_t i = 0; i < std::max(rows.size(), merged.units_in_fleet); ++i) {
    if (i >= rows.size() || rows[i].index != i) {
      return SetError(error, "the shards' summaries hold " + std::to_string(rows.size()) +
                                 " rows for a fleet of " + std::to_string(merged.units_in_fleet) +
                                 " units: the row of unit index " + std::to_string(i) +
                                 " is missing or appears twice");
    }
  }
  merged.shard_index = 1;
  merged.shard_count = 1;
  if (!internal::MakeFolders(output_dir, error) ||
      !internal::WriteSummaryFiles(output_dir, rows, merged, fleet, statistics, error)) {
    return false;
  }
  return acceptance.shards == 0 || WriteMergedAcceptance(output_dir, acceptance, error);
}

}  // namespace gravcal
